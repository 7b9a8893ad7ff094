#include "safecass/record/recorder.hpp"

#include "segmented_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace safecass {

namespace {

void append_quoted(std::string& out, std::string_view s) {
  out += '"';
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

/// A number as JSON; a non-finite one (a NaN or infinite sample) as the string "nan", "inf" or
/// "-inf", since JSON has no such numbers and the value must not be lost.
std::string json_num(double v) {
  if (std::isnan(v)) return "\"nan\"";
  if (std::isinf(v)) return v > 0 ? "\"inf\"" : "\"-inf\"";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string secs(Time t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6f", to_seconds(t));
  return buf;
}

std::string event_name(const Coordinator& co, EventId e) {
  return e == kNoEvent || e >= co.event_count() ? std::string() : co.event(e).name;
}

/// The address of a record's root origin. A root that came from another process (a live
/// coordinator's remote provided interface) names its origin in that process, interned when it
/// arrived (RootCause::remote_origin), not the local stand-in machine it arrived through: a live
/// client's history names the same root cause as an in-process run.
std::string root_origin_text(const Record& r, const Coordinator& co) {
  if (r.root.remote_origin != kNoName) return std::string(co.name_of(r.root.remote_origin));
  return co.address_of(r.root.origin);
}

}  // namespace

std::string record_to_json(const Record& r, const Coordinator& co) {
  std::string out = "{\"seq\":" + std::to_string(r.seq) + ",\"t\":" + secs(r.time) + ",\"kind\":";
  append_quoted(out, to_string(r.kind));
  if (r.outcome != Outcome::None) {
    out += ",\"outcome\":";
    append_quoted(out, to_string(r.outcome));
  }
  if (r.component != kNoComponent && r.component < co.component_count()) {
    out += ",\"component\":";
    append_quoted(out, co.component_name(r.component));
  }
  if (r.machine != kNoMachine && r.machine < co.machine_count()) {
    out += ",\"machine\":";
    append_quoted(out, co.address_of(r.machine));
  }
  if (r.event != kNoEvent) {
    out += ",\"event\":";
    append_quoted(out, event_name(co, r.event));
  }
  if (r.kind != RecordKind::Injection) {
    out += ",\"from\":";
    append_quoted(out, to_string(r.from));
    out += ",\"to\":";
    append_quoted(out, to_string(r.to));
  }
  if (r.kind == RecordKind::Event) {
    out += ",\"level\":";
    append_quoted(out, to_string(r.level));
    out += ",\"severity\":" + std::to_string(r.severity);
  }
  if (r.mirror) out += ",\"mirror\":true";
  if (r.root.event != kNoEvent && r.root.origin != kNoMachine && r.root.origin < co.machine_count()) {
    out += ",\"root\":{\"event\":";
    append_quoted(out, event_name(co, r.root.event));
    out += ",\"origin\":";
    append_quoted(out, root_origin_text(r, co));
    out += ",\"t\":" + secs(r.root.time);
    if (r.root.sample.filter != kNoName) {
      out += ",\"filter\":";
      append_quoted(out, co.name_of(r.root.sample.filter));
    }
    if (r.root.sample.signal != kNoName) {
      out += ",\"signal\":";
      append_quoted(out, co.name_of(r.root.sample.signal));
      out += ",\"value\":" + json_num(r.root.sample.value) + ",\"sample_t\":" + secs(r.root.sample.sample_time);
    }
    if (r.root.sample.injected) out += ",\"injected\":true";
    out += "}";
  }
  if (!r.text.empty()) {
    out += ",\"text\":";
    append_quoted(out, r.text);
  }
  out += "}";
  return out;
}

std::string record_to_text(const Record& r, const Coordinator& co) {
  std::string out = "t=" + secs(r.time) + "  ";
  const std::string where = r.machine != kNoMachine && r.machine < co.machine_count()
                                ? co.address_of(r.machine)
                                : (r.component != kNoComponent ? std::string(co.component_name(r.component)) : std::string("-"));
  out += where;
  switch (r.kind) {
    case RecordKind::Transition:
    case RecordKind::ComponentTransition:
      out += "  " + std::string(to_string(r.from)) + " -> " + std::string(to_string(r.to));
      if (r.event != kNoEvent) out += "  " + event_name(co, r.event);
      break;
    case RecordKind::Event:
      out += "  " + std::string(to_string(r.outcome)) + " " + event_name(co, r.event);
      break;
    case RecordKind::Reset: out += "  reset"; break;
    case RecordKind::Injection: out += "  injection"; break;
  }
  if (r.root.event != kNoEvent && r.root.origin != kNoMachine && r.root.origin < co.machine_count() &&
      !(r.root.origin == r.machine && r.root.event == r.event)) {
    out += "  <- " + root_origin_text(r, co) + ":" + event_name(co, r.root.event);
  }
  if (r.root.sample.filter != kNoName || r.root.sample.signal != kNoName) {
    out += "  [";
    if (r.root.sample.filter != kNoName) out += "filter " + std::string(co.name_of(r.root.sample.filter));
    if (r.root.sample.signal != kNoName) {
      out += ", " + std::string(co.name_of(r.root.sample.signal)) + " = " + num(r.root.sample.value);
    }
    if (r.root.sample.injected) out += ", injected";
    out += "]";
  }
  if (!r.text.empty()) out += "  (" + std::string(r.text) + ")";
  return out;
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
    out.push_back(file + std::to_string(s.dropped) + (s.dropped == 1 ? " record" : " records") +
                  " dropped: the recorder's queue was full (an \"overflow\" line marks where; the history is incomplete)");
  }
  return out;
}

std::string record_status_json(const RecordStatus& s) {
  std::string out = "{\"kind\":\"recorder\",\"path\":";
  append_quoted(out, s.path);
  out += ",\"written\":" + std::to_string(s.written) + ",\"dropped\":" + std::to_string(s.dropped) +
         ",\"unwritten\":" + std::to_string(s.unwritten) + ",\"write_error\":" + (s.write_error.empty() ? "false" : "true");
  if (!s.write_error.empty()) {
    out += ",\"error\":";
    append_quoted(out, s.write_error);
  }
  out += std::string(",\"complete\":") + (s.complete() ? "true" : "false") + "}";
  return out;
}

Expected<std::unique_ptr<Recorder>> Recorder::open(Coordinator& coordinator, const std::string& path, std::size_t capacity,
                                                   FileLimits limits) {
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
        line = "{\"kind\":\"overflow\",\"dropped\":" + std::to_string(dropped_ - dropped_reported_) + "}";
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
