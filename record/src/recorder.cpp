#include "safecass/record/recorder.hpp"

#include "safecass/introspect/format.hpp"
#include "safecass/json/write.hpp"
#include "segmented_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace safecass {

std::string record_to_json(const Record& r, const Coordinator& co) {
  return introspect::history_json(introspect::history_entry(r, co));
}

std::string record_to_text(const Record& r, const Coordinator& co) {
  return introspect::history_text(introspect::history_entry(r, co), introspect::TimeFormat{});
}

std::vector<std::string> describe_losses(const RecordStatus& s) {
  std::vector<std::string> out;
  const std::string file = "history file '" + s.path + "': ";
  if (!s.write_error.empty()) {
    out.push_back(file + "write error after " + std::to_string(s.written) + " records: " + s.write_error + "; " +
                  std::to_string(s.unwritten) + (s.unwritten == 1 ? " record was" : " records were") +
                  " not written (the system kept running; the history is incomplete)");
  }
  if (s.dropped != 0) {
    out.push_back(
        file + std::to_string(s.dropped) + (s.dropped == 1 ? " record" : " records") +
        " dropped: the recorder's queue was full (an \"overflow\" line marks where; the history is incomplete)");
  }
  return out;
}

std::string record_status_json(const RecordStatus& s) {
  json::JsonObject j;
  j.str("kind", "recorder")
      .str("path", s.path)
      .integer("written", static_cast<long long>(s.written))
      .integer("dropped", static_cast<long long>(s.dropped))
      .integer("unwritten", static_cast<long long>(s.unwritten))
      .boolean("write_error", !s.write_error.empty());
  if (!s.write_error.empty()) j.str("error", s.write_error);
  return j.boolean("complete", s.complete()).text();
}

Expected<std::unique_ptr<Recorder>> Recorder::open(Coordinator& coordinator, const std::string& path,
                                                   std::size_t capacity, FileLimits limits) {
  auto file = detail::SegmentedFile::open(path, limits);
  if (!file) return fail(ErrorCode::Io, "cannot write history file '" + path + "': " + file.error().message);
  return std::unique_ptr<Recorder>(
      new Recorder(coordinator, std::make_unique<detail::SegmentedFile>(std::move(*file)), capacity));
}

Recorder::Recorder(Coordinator& coordinator, std::unique_ptr<detail::SegmentedFile> file, std::size_t capacity)
    : coordinator_(coordinator), file_(std::move(file)), path_(file_->path()), capacity_(capacity == 0 ? 1 : capacity) {
  thread_ = std::thread([this] { writer(); });
  subscription_ = coordinator_.subscribe([this](const Record& r) {
    std::lock_guard lock(mutex_);
    if (closing_) return;
    if (queue_.size() >= capacity_) {
      ++dropped_;
      ready_.notify_one();
      return;
    }
    queue_.push_back(r);
    ready_.notify_one();
  });
}

Recorder::~Recorder() { close(); }

void Recorder::close() {
  if (subscription_ != 0) {
    coordinator_.unsubscribe(subscription_);
    subscription_ = 0;
  }
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
    ready_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
  // close() may report what a write could not (NFS, a delayed I/O error).
  const bool closed = file_->close();
  std::lock_guard lock(mutex_);
  if (!closed && write_error_.empty()) write_error_ = file_->error();
}

void Recorder::writer() {
  std::unique_lock lock(mutex_);
  for (;;) {
    ready_.wait(lock, [this] { return closing_ || !queue_.empty() || dropped_ != dropped_reported_; });
    while (!queue_.empty() || dropped_ != dropped_reported_) {
      std::string line;
      bool record = false;
      if (dropped_ != dropped_reported_) {
        line = json::JsonObject()
                   .str("kind", "overflow")
                   .integer("dropped", static_cast<long long>(dropped_ - dropped_reported_))
                   .text();
        dropped_reported_ = dropped_;
      } else {
        const Record r = queue_.front();
        queue_.pop_front();
        record = true;
        if (!write_error_.empty()) {  // the file is broken: count what it misses, keep the system going
          ++unwritten_;
          continue;
        }
        lock.unlock();
        line = record_to_json(r, coordinator_);
        lock.lock();
      }
      if (!write_error_.empty()) continue;
      // One write() per line, newline included: a kill leaves at most the last line torn.
      line += '\n';
      lock.unlock();
      const bool ok = file_->write(line);
      lock.lock();
      rotations_ = file_->rotations();
      discarded_ = file_->discarded();
      if (ok) {
        written_ += record ? 1 : 0;
      } else {
        write_error_ = file_->error();
        unwritten_ += record ? 1 : 0;
      }
    }
    if (closing_) return;
  }
}

std::uint64_t Recorder::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

std::uint64_t Recorder::written() const {
  std::lock_guard lock(mutex_);
  return written_;
}

RecordStatus Recorder::status() const {
  std::lock_guard lock(mutex_);
  return RecordStatus{path_, written_, dropped_, unwritten_, write_error_, rotations_, discarded_};
}

}  // namespace safecass
