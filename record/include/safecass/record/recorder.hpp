#pragma once
/// @file recorder.hpp
/// Durable history: every record of a coordinator's observer stream as one JSON object per line.
///
/// The Recorder subscribes to the stream and hands records to a writer thread through a bounded
/// queue, so the monitored system never waits for the disk. When the queue is full a record is
/// dropped and counted; the count is written to the file (a `{"kind":"overflow",...}` line) and
/// reported by dropped(), never silent. Each line is flushed as it is written, so a killed
/// process leaves a readable history up to its last complete line.

#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include "safecass/core/coordinator.hpp"

namespace safecass {

/// One record as a JSON object (no trailing newline). Deterministic: same record, same bytes.
std::string record_to_json(const Record& r, const Coordinator& coordinator);

/// A human-readable line: "t=0.301000 JR3.s_A Normal -> Error EVT_FORCE_ERROR (...)".
std::string record_to_text(const Record& r, const Coordinator& coordinator);

class Recorder {
public:
  /// Opens `path` for writing (truncates). Errors: Io.
  static Expected<std::unique_ptr<Recorder>> open(Coordinator& coordinator, const std::string& path,
                                                  std::size_t capacity = 65536);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Writes everything queued and stops the writer. Called by the destructor.
  void close();
  std::uint64_t dropped() const;
  std::uint64_t written() const;

private:
  Recorder(Coordinator& coordinator, std::FILE* file, std::size_t capacity);
  void writer();

  Coordinator& coordinator_;
  std::FILE* file_;
  std::size_t capacity_;
  Coordinator::SubscriptionId subscription_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Record> queue_;
  bool closing_ = false;
  std::uint64_t dropped_ = 0;
  std::uint64_t dropped_reported_ = 0;
  std::uint64_t written_ = 0;
  std::thread thread_;
};

}  // namespace safecass
