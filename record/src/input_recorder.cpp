#include "safecass/record/input_recorder.hpp"

#include <algorithm>
#include <set>

#include "safecass/json/write.hpp"
#include "segmented_file.hpp"

namespace safecass {

namespace {
std::string plural(std::uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

constexpr std::size_t kMaxChunk = std::size_t{256} * 1024;
constexpr auto kFlushEvery = std::chrono::milliseconds(50);
}  // namespace

std::vector<std::string> describe_losses(const InputRecordStatus& s) {
  std::vector<std::string> out;
  const std::string file = "input recording '" + s.path + "': ";
  if (!s.write_error.empty()) {
    out.push_back(file + "write error: " + s.write_error + "; " + plural(s.unwritten, "sample was", "samples were") +
                  " not written (the system kept running; the recording is incomplete)");
  }
  if (s.lost != 0) {
    out.push_back(file + plural(s.lost, "sample", "samples") +
                  " lost: overwritten in their signal's history buffer before the recorder read them (a loss record "
                  "marks where)");
  }
  if (s.dropped != 0) {
    out.push_back(file + plural(s.dropped, "sample", "samples") +
                  " dropped: the queue to the disk was full (a loss record marks where; the recording is incomplete)");
  }
  return out;
}

std::string record_status_json(const InputRecordStatus& s) {
  const auto count = [](std::uint64_t n) { return static_cast<long long>(n); };
  json::JsonObject out;
  out.str("kind", "input_recorder")
      .str("path", s.path)
      .integer("samples", count(s.samples))
      .integer("actions", count(s.actions))
      .integer("lost", count(s.lost))
      .integer("dropped", count(s.dropped))
      .integer("unwritten", count(s.unwritten))
      .boolean("write_error", !s.write_error.empty());
  if (!s.write_error.empty()) out.str("error", s.write_error);
  out.integer("rotations", count(s.rotations)).boolean("complete", s.complete());
  return out.text();
}

std::string InputRecorder::path_for_history(const std::string& history) {
  const std::string ext = ".jsonl";
  if (history.size() > ext.size() && history.compare(history.size() - ext.size(), ext.size(), ext) == 0) {
    return history.substr(0, history.size() - ext.size()) + ".inputs";
  }
  return history + ".inputs";
}

Expected<std::unique_ptr<InputRecorder>> InputRecorder::open(Monitor& monitor, const std::string& path,
                                                             InputRecorderOptions options) {
  auto file = detail::SegmentedFile::open(path, options.limits);
  if (!file) return fail(ErrorCode::Io, "cannot write input recording '" + path + "': " + file.error().message);
  std::unique_ptr<InputRecorder> r(
      new InputRecorder(monitor, std::make_unique<detail::SegmentedFile>(std::move(*file)), std::move(options)));
  if (r->inputs_.size() > input_log::kMaxSignals) {
    return fail(ErrorCode::InvalidArgument, "input recording '" + path + "': " + std::to_string(r->inputs_.size()) +
                                                " input signals (a recording holds at most 65534)");
  }
  InputLogHeader header;
  header.period = r->options_.period;
  header.start = monitor.coordinator().clock().now();
  header.clock = r->options_.clock;
  header.system = monitor.coordinator().structure().name();
  std::string preamble;
  input_log::put_header(preamble, header);
  for (std::size_t i = 0; i < r->inputs_.size(); ++i) {
    const Signal& s = *r->inputs_[i].signal;
    input_log::put_signal(preamble, static_cast<std::uint16_t>(i), static_cast<std::uint16_t>(s.size()), s.name());
  }
  r->file_->set_preamble(preamble);
  // A write error (a full disk) is kept and said at the end, as for every later write: the
  // system runs either way.
  if (!r->file_->write(preamble)) r->write_error_ = r->file_->error();
  r->writer_ = std::thread([p = r.get()] { p->writer(); });
  return r;
}

InputRecorder::InputRecorder(Monitor& monitor, std::unique_ptr<detail::SegmentedFile> file,
                             InputRecorderOptions options)
    : monitor_(monitor), file_(std::move(file)), options_(std::move(options)), path_(file_->path()) {
  chunk_limit_ = kMaxChunk;
  if (options_.limits.max_bytes != 0)
    chunk_limit_ = std::max<std::size_t>(4096, std::min<std::uint64_t>(kMaxChunk, options_.limits.max_bytes / 4));
  // Inputs: the signals no filter writes. Filter outputs are computed again by a replay.
  std::set<const Signal*> outputs;
  for (const auto& f : monitor_.filters()) outputs.insert(f->outputs().begin(), f->outputs().end());
  const std::set<std::string> only(options_.signals.begin(), options_.signals.end());
  for (Signal* s : monitor_.signals().all()) {
    if (outputs.count(s) != 0 || (!only.empty() && only.count(s->name()) == 0)) continue;
    inputs_.push_back(Input{s, SignalCursor(s), 0});
  }
}

InputRecorder::~InputRecorder() { close(); }

void InputRecorder::open_chunk_locked() {
  if (!chunk_.bytes.empty()) return;
  // A chunk restates the time only where a reader would miss it, so that the same run records the
  // same bytes however its chunks fall: after dropped chunks (with their loss mark), and at the
  // start of a new segment (its `resume`, written by the file when this chunk rotates it).
  if (have_time_) {
    chunk_.resume.clear();
    input_log::put_time(chunk_.resume, last_time_);
  }
  if (pending_dropped_ != 0) {
    input_log::put_loss(chunk_.bytes, last_time_, input_log::kAnySignal, pending_dropped_);
    chunk_.carried = pending_dropped_;
    pending_dropped_ = 0;
    chunk_.bytes += chunk_.resume;
  }
}

void InputRecorder::seal_locked(bool last) {
  if (chunk_.bytes.empty()) return;
  if (!last && queued_bytes_ + chunk_.bytes.size() > options_.queue_bytes && !queue_.empty()) {
    // Dropped with the loss mark it carried: the next chunk marks both.
    dropped_ += chunk_.samples;
    pending_dropped_ += chunk_.samples + chunk_.carried;
  } else {
    queued_bytes_ += chunk_.bytes.size();
    queue_.push_back(std::move(chunk_));
    ready_.notify_one();
  }
  chunk_ = Chunk{};
}

void InputRecorder::drain_locked() {
  if (closed_) return;
  staged_.clear();
  staged_values_.clear();
  for (std::uint32_t i = 0; i < inputs_.size(); ++i) {
    Input& in = inputs_[i];
    const std::size_t width = in.signal->size();
    in.cursor.read_new([&](const SampleView& s) {
      if (s.injected) return;  // a deep injection: recorded as the action that wrote it
      staged_.push_back(Staged{s.time, i, static_cast<std::uint32_t>(staged_values_.size())});
      staged_values_.insert(staged_values_.end(), s.data, s.data + width);
    });
    if (in.cursor.missed() != in.missed) {
      const std::uint64_t n = in.cursor.missed() - in.missed;
      in.missed = in.cursor.missed();
      lost_ += n;
      open_chunk_locked();
      input_log::put_loss(chunk_.bytes, have_time_ ? last_time_ : Time{}, static_cast<std::uint16_t>(i), n);
    }
  }
  if (staged_.empty()) return;
  // Each signal's samples are in order; across signals, order by time (stable: input order).
  if (!std::is_sorted(staged_.begin(), staged_.end(),
                      [](const Staged& a, const Staged& b) { return a.time < b.time; })) {
    std::stable_sort(staged_.begin(), staged_.end(), [](const Staged& a, const Staged& b) { return a.time < b.time; });
  }
  for (const Staged& s : staged_) {
    open_chunk_locked();
    if (!have_time_ || s.time != last_time_) {
      have_time_ = true;
      last_time_ = s.time;
      input_log::put_time(chunk_.bytes, s.time);
    }
    input_log::put_sample(chunk_.bytes, static_cast<std::uint16_t>(s.input), staged_values_.data() + s.offset,
                          inputs_[s.input].signal->size());
    ++chunk_.samples;
    if (chunk_.bytes.size() >= chunk_limit_) seal_locked();
  }
}

void InputRecorder::drain() {
  std::lock_guard lock(mutex_);
  drain_locked();
}

void InputRecorder::applied(const introspect::Action& action, Time at) {
  if (std::holds_alternative<introspect::PushSample>(action)) return;  // read from its signal by drain()
  std::lock_guard lock(mutex_);
  if (closed_) return;
  drain_locked();
  open_chunk_locked();
  input_log::put_action(chunk_.bytes, action, at);
  ++actions_;
  if (chunk_.bytes.size() >= chunk_limit_) seal_locked();
}

void InputRecorder::start_polling(std::chrono::milliseconds every) {
  std::lock_guard lock(mutex_);
  if (poller_.joinable() || closed_) return;
  poller_ = std::thread([this, every] {
    std::unique_lock guard(mutex_);
    while (!polling_stop_) {
      poll_wake_.wait_for(guard, every, [this] { return polling_stop_; });
      drain_locked();
    }
  });
}

void InputRecorder::writer() {
  std::unique_lock lock(mutex_);
  for (;;) {
    ready_.wait_for(lock, kFlushEvery, [this] { return closing_ || !queue_.empty(); });
    // At least every 50 ms, what was drained goes to the disk, even a chunk that is not full.
    seal_locked();
    std::deque<Chunk> batch;
    batch.swap(queue_);
    queued_bytes_ = 0;
    const bool last = closing_;
    lock.unlock();
    std::uint64_t written = 0;
    std::uint64_t failed = 0;
    for (const Chunk& c : batch) {
      if (file_->write(c.bytes, c.resume)) {
        written += c.samples;
      } else {
        failed += c.samples;
      }
    }
    lock.lock();
    samples_ += written;
    unwritten_ += failed;
    if (write_error_.empty()) write_error_ = file_->error();
    rotations_ = file_->rotations();
    discarded_ = file_->discarded();
    if (last && queue_.empty() && chunk_.bytes.empty()) return;
  }
}

void InputRecorder::close(Time end) {
  {
    std::unique_lock lock(mutex_);
    if (closed_) return;
    polling_stop_ = true;
    poll_wake_.notify_all();
  }
  if (poller_.joinable()) poller_.join();
  {
    std::lock_guard lock(mutex_);
    drain_locked();
    seal_locked();
    open_chunk_locked();
    input_log::put_end(chunk_.bytes, end);
    seal_locked(true);  // the end, and the mark of what was dropped, are never dropped
    closed_ = true;
    closing_ = true;
    ready_.notify_one();
  }
  if (writer_.joinable()) writer_.join();
  const bool ok = file_->close();
  std::lock_guard lock(mutex_);
  if (!ok && write_error_.empty()) write_error_ = file_->error();
}

void InputRecorder::close() { close(monitor_.coordinator().clock().now()); }

InputRecordStatus InputRecorder::status() const {
  std::lock_guard lock(mutex_);
  return InputRecordStatus{path_,      samples_,     actions_,   lost_,     dropped_,
                           unwritten_, write_error_, rotations_, discarded_};
}

}  // namespace safecass
