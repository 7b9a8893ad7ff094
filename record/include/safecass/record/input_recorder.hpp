#pragma once
/// @file input_recorder.hpp
/// Records what a running system is fed: every sample of its input signals (the signals no filter
/// writes) and every operator action (generate, broadcast, reset, injections), in the format of
/// input_log.hpp (docs/record-format.md), next to the history the Recorder writes.
///
/// It reads samples with its own SignalCursor per input signal, so the component that pushes a
/// sample pays nothing: no lock, no allocation, no branch on the hot path. drain() moves every
/// sample pushed so far into the recording; a simulation driver calls it after each tick, a live
/// system lets start_polling() call it every 10 ms from a thread. A sample overwritten in its
/// signal's history buffer before drain() read it is counted as lost; samples that find the queue
/// to the disk full (more than InputRecorderOptions::queue_bytes waiting) are dropped and counted.
/// Both are written into the recording (a loss record where they happened) and reported by
/// status(), never silent.
///
/// A writer thread writes the queue at least every 50 ms, in whole records: a killed process
/// leaves a recording that every reader accepts up to its last whole record. A write error stops
/// the writing, not the system: it is kept and counted. With FileLimits::max_bytes the file
/// rotates; every segment starts with the header and the signal declarations, so each replays alone.
///
/// Actions are recorded as an introspect::ActionObserver: whatever applies them through
/// introspect::apply() (the scenario runner, a replay, a live coordinator's console and viewer
/// writes and scenario) tells the recorder, once per applied action. Each first drains the samples
/// pushed before it, so the recording keeps their order. A PushSample is not an action record: its
/// sample is read from its signal like every other.
///
/// Lifecycle: open() (configuration of the monitor finished) → drain()/actions/start_polling() →
/// close() (drained, an end record, everything written; also done by the destructor).
/// Every member function is thread-safe.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "safecass/filters/monitor.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/record/file_limits.hpp"
#include "safecass/record/input_log.hpp"

namespace safecass {

namespace detail {
class SegmentedFile;
}

/// What an input recorder has written and what it lost.
struct InputRecordStatus {
  std::string path;
  std::uint64_t samples = 0;    ///< samples written (queued to the file)
  std::uint64_t actions = 0;    ///< actions written
  std::uint64_t lost = 0;       ///< samples overwritten in a history buffer before they were read
  std::uint64_t dropped = 0;    ///< samples dropped because the queue to the disk was full
  std::uint64_t unwritten = 0;  ///< samples not written because a write had failed
  std::string write_error;      ///< the first write error; empty: none
  std::uint64_t rotations = 0;  ///< times the file was rotated (FileLimits::max_bytes)
  std::uint64_t discarded = 0;  ///< old segments deleted by rotation

  bool complete() const noexcept { return lost == 0 && dropped == 0 && write_error.empty(); }
};

/// One line per loss for a person ("input recording 'x.inputs': ..."), empty when complete.
std::vector<std::string> describe_losses(const InputRecordStatus& status);
/// {"kind":"input_recorder","path":P,"samples":N,"actions":N,"lost":N,"dropped":N,"unwritten":N,
///  "write_error":false|true,"error":TEXT (only with a write error),"rotations":N,"complete":B}
std::string record_status_json(const InputRecordStatus& status);

struct InputRecorderOptions {
  FileLimits limits;                    ///< rotation (--max-bytes)
  std::size_t queue_bytes = 64u << 20;  ///< bytes waiting for the disk before samples are dropped
  Time period{};                        ///< the run's tick period, for the header (0: unknown)
  std::string clock = "simulated";      ///< where the times come from, for the header
  /// Record only these input signals ("Component.signal"); empty: every input signal. A framework
  /// bridge that adds signals of its own (the ROS bridge's topic rates) records those of the spec.
  std::vector<std::string> signals;
};

class InputRecorder final : public introspect::ActionObserver {
public:
  /// Creates `path`, writes the header and declares the input signals of `monitor`. Errors: Io
  /// (with the path and the reason), InvalidArgument (more than 65534 input signals).
  [[nodiscard]] static Expected<std::unique_ptr<InputRecorder>> open(Monitor& monitor, const std::string& path,
                                                                     InputRecorderOptions options = {});
  ~InputRecorder() override;
  InputRecorder(const InputRecorder&) = delete;
  InputRecorder& operator=(const InputRecorder&) = delete;

  /// The inputs file that goes with a history file: "run.jsonl" → "run.inputs", "h" → "h.inputs".
  static std::string path_for_history(const std::string& history_path);

  /// Moves every sample pushed so far into the recording, in time order.
  void drain();
  /// Calls drain() every `every` from a thread until close() (live systems).
  void start_polling(std::chrono::milliseconds every = std::chrono::milliseconds(10));

  /// Records an applied action at `at` (after draining the samples pushed before it).
  void applied(const introspect::Action& action, Time at) override;

  /// Drains, writes the end record with `end` (the last tick of a simulated run; default: the
  /// clock's now), writes everything queued and closes the file. Idempotent.
  void close(Time end);
  void close();
  InputRecordStatus status() const;

private:
  struct Input {
    const Signal* signal;
    SignalCursor cursor;
    std::uint64_t missed = 0;
  };
  struct Chunk {
    std::string bytes;
    std::uint64_t samples = 0;
    std::uint64_t carried = 0;  ///< the dropped samples its loss record marks
    std::string resume;         ///< the time record a reader needs when the chunk starts a segment
  };
  InputRecorder(Monitor& monitor, std::unique_ptr<detail::SegmentedFile> file, InputRecorderOptions options);
  void drain_locked();
  /// Moves the open chunk to the queue, or drops it when the queue is full (never the `last`).
  void seal_locked(bool last = false);
  void open_chunk_locked();
  void writer();

  Monitor& monitor_;
  std::unique_ptr<detail::SegmentedFile> file_;
  InputRecorderOptions options_;
  std::string path_;
  std::size_t chunk_limit_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<Input> inputs_;
  // Staging of one drain, merged by time: (time, input, offset into staged_values_).
  struct Staged {
    Time time;
    std::uint32_t input;
    std::uint32_t offset;
  };
  std::vector<Staged> staged_;
  std::vector<double> staged_values_;
  Chunk chunk_;
  bool have_time_ = false;
  Time last_time_{};
  std::deque<Chunk> queue_;
  std::size_t queued_bytes_ = 0;
  std::uint64_t pending_dropped_ = 0;  ///< dropped, not yet marked in the file
  bool closing_ = false;
  bool closed_ = false;
  std::uint64_t samples_ = 0;
  std::uint64_t actions_ = 0;
  std::uint64_t lost_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t unwritten_ = 0;
  std::uint64_t rotations_ = 0;
  std::uint64_t discarded_ = 0;
  std::string write_error_;
  std::thread writer_;
  std::thread poller_;
  bool polling_stop_ = false;
  std::condition_variable poll_wake_;
};

}  // namespace safecass
