#pragma once
/// @file recorder.hpp
/// Durable history: every record of a coordinator's observer stream as one JSON object per line.
///
/// The Recorder subscribes to the stream and hands records to a writer thread through a bounded
/// queue, so the monitored system never waits for the disk. When the queue is full a record is
/// dropped and counted; the count is written to the file (a `{"kind":"overflow",...}` line) and
/// reported by status(), never silent. Each line is written with its newline in one write() as it
/// is taken from the queue, so a killed process leaves a readable history up to its last complete
/// line (at most the last line is torn).
///
/// With FileLimits::max_bytes the file is rotated instead of filling the disk (file_limits.hpp);
/// every segment is a readable history on its own, and the rotations are counted in status().
///
/// A write error (a full disk, /dev/full, an I/O error) does not stop the monitored system: the
/// recorder stops writing, remembers the first error and counts every record it could not write;
/// status() says so, and the tools report it on stderr and in their exit code.
///
/// Lifecycle: open() (subscribed, writer running) → close() (unsubscribed, queue written, file
/// closed; also done by the destructor). status() may be called at any time from any thread.

#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/record/file_limits.hpp"

namespace safecass {

namespace detail {
class SegmentedFile;
}

/// One record as a JSON object (no trailing newline). Deterministic: same record, same bytes.
std::string record_to_json(const Record& r, const Coordinator& coordinator);

/// A human-readable line: "t=0.301000 JR3.s_A Normal -> Error EVT_FORCE_ERROR (...)".
std::string record_to_text(const Record& r, const Coordinator& coordinator);

/// What a recorder has written and what it lost.
struct RecordStatus {
  std::string path;             ///< the history file
  std::uint64_t written = 0;    ///< records written to the file
  std::uint64_t dropped = 0;    ///< records dropped because the queue was full
  std::uint64_t unwritten = 0;  ///< records lost because a write had failed
  std::string write_error;      ///< the first write error ("No space left on device"); empty: none
  std::uint64_t rotations = 0;  ///< times the file was rotated (FileLimits::max_bytes)
  std::uint64_t discarded = 0;  ///< old segments deleted by rotation (FileLimits::keep)

  /// Nothing lost: every record of the stream is in the file.
  bool complete() const noexcept { return dropped == 0 && write_error.empty(); }
};

/// One line per loss for a person ("history file 'h.jsonl': ..."), empty when complete.
std::vector<std::string> describe_losses(const RecordStatus& status);

/// The status as one JSON object, for machine-readable output (`safecass run --json`):
/// {"kind":"recorder","path":P,"written":N,"dropped":N,"unwritten":N,"write_error":false|true,
///  "error":TEXT (only with a write error),"complete":true|false}.
std::string record_status_json(const RecordStatus& status);

class Recorder {
public:
  /// Opens `path` for writing (creates or truncates). Errors: Io, with the path and the reason.
  [[nodiscard]] static Expected<std::unique_ptr<Recorder>> open(Coordinator& coordinator, const std::string& path,
                                                                std::size_t capacity = 65536, FileLimits limits = {});
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Writes everything queued and stops the writer. Called by the destructor.
  void close();
  std::uint64_t dropped() const;
  std::uint64_t written() const;
  /// Written, dropped and lost records and the first write error. Thread-safe.
  RecordStatus status() const;

private:
  Recorder(Coordinator& coordinator, std::unique_ptr<detail::SegmentedFile> file, std::size_t capacity);
  void writer();

  Coordinator& coordinator_;
  std::unique_ptr<detail::SegmentedFile> file_;
  std::string path_;
  std::size_t capacity_;
  Coordinator::SubscriptionId subscription_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Record> queue_;
  bool closing_ = false;
  std::uint64_t dropped_ = 0;
  std::uint64_t dropped_reported_ = 0;
  std::uint64_t written_ = 0;
  std::uint64_t unwritten_ = 0;
  std::uint64_t rotations_ = 0;
  std::uint64_t discarded_ = 0;
  std::string write_error_;
  std::thread thread_;
};

}  // namespace safecass
