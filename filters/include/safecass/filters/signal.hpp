#pragma once
/// @file signal.hpp
/// Signals (DESIGN §3): named `Component.signal`, scalar or fixed-size vector of doubles, each
/// sample timestamped, with a history buffer that keeps the recent samples.
///
/// The history buffer is a ring that writers fill and any number of readers follow, without
/// locks: a writer reserves a slot with one atomic increment and publishes it with a per-slot
/// sequence number (so a deep fault injection from a tool thread may write beside the signal's
/// own writer); a reader copies a slot and checks the sequence number again (seqlock). Nothing
/// allocates after construction.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/ids.hpp"

namespace safecass {

/// A sample as read from a buffer: valid while the reader's scratch storage is not reused.
struct SampleView {
  Time time{};
  const double* data = nullptr;
  std::size_t size = 0;
  bool injected = false;  ///< written by fault injection
  double operator[](std::size_t i) const noexcept { return data[i]; }
  double scalar() const noexcept { return data[0]; }
};

class HistoryBuffer {
public:
  /// `width` doubles per sample; `capacity` is rounded up to a power of two.
  HistoryBuffer(std::size_t width, std::size_t capacity);
  HistoryBuffer(const HistoryBuffer&) = delete;
  HistoryBuffer& operator=(const HistoryBuffer&) = delete;

  std::size_t width() const noexcept { return width_; }
  std::size_t capacity() const noexcept { return mask_ + 1; }

  /// Appends a sample (`values` holds width() doubles). Lock-free, allocation-free.
  void push(Time time, const double* values, bool injected = false) noexcept;

  /// Index the next push will take; samples [end() - capacity(), end()) may be readable.
  std::uint64_t end() const noexcept { return head_.load(std::memory_order_acquire); }

  /// Copies sample `index` into `out` (width() doubles). Returns false if that sample is not
  /// (yet, or any more) in the buffer. Lock-free, allocation-free.
  bool read(std::uint64_t index, Time& time, double* out, bool& injected) const noexcept;

private:
  struct Slot {
    std::atomic<std::uint64_t> seq{0};  ///< 2*index+1 while writing, 2*index+2 when published
  };
  std::size_t width_;
  std::size_t mask_;
  std::unique_ptr<Slot[]> slots_;
  /// Per slot: time, flags, then width_ doubles, stored as bit patterns in relaxed atomics so
  /// that a reader racing a writer is well defined (the sequence check discards the copy).
  std::unique_ptr<std::atomic<std::uint64_t>[]> words_;
  std::atomic<std::uint64_t> head_{0};
};

/// A named signal with its history buffer.
class Signal {
public:
  Signal(std::string name, ComponentId component, std::size_t size, std::size_t history);

  /// "Component.signal".
  const std::string& name() const noexcept { return name_; }
  ComponentId component() const noexcept { return component_; }
  /// Number of doubles per sample: 1 for a scalar.
  std::size_t size() const noexcept { return buffer_.width(); }
  NameId name_id() const noexcept { return name_id_; }
  void set_name_id(NameId id) noexcept { name_id_ = id; }

  /// Writes a scalar sample. Lock-free, allocation-free.
  void push(Time time, double value) noexcept { buffer_.push(time, &value); }
  /// Writes a vector sample of size() doubles. Lock-free, allocation-free.
  void push(Time time, const double* values) noexcept { buffer_.push(time, values); }
  /// Deep fault injection: a sample every consumer sees, marked as injected.
  void inject(Time time, const double* values) noexcept { buffer_.push(time, values, true); }

  HistoryBuffer& buffer() noexcept { return buffer_; }
  const HistoryBuffer& buffer() const noexcept { return buffer_; }

  /// Copies the newest sample into `out`; false when the signal has no sample yet.
  bool latest(Time& time, double* out) const noexcept;

private:
  std::string name_;
  ComponentId component_;
  NameId name_id_ = kNoName;
  HistoryBuffer buffer_;
};

/// Reads the samples of one signal in order, remembering where it stopped. One cursor per reader.
class SignalCursor {
public:
  SignalCursor() = default;
  explicit SignalCursor(const Signal* signal);
  /// Reads the next unread sample into internal storage; false when there is none. Samples
  /// overwritten before they were read are skipped and counted in missed().
  bool next(SampleView& out) noexcept;
  /// Skips every sample written so far.
  void skip_to_end() noexcept;
  std::uint64_t missed() const noexcept { return missed_; }
  const Signal* signal() const noexcept { return signal_; }

private:
  const Signal* signal_ = nullptr;
  std::uint64_t next_ = 0;
  std::uint64_t missed_ = 0;
  std::vector<double> scratch_;
};

/// The signals of one coordinator, by name. Signals are created during configuration; their
/// addresses are stable for the registry's lifetime.
class SignalRegistry {
public:
  explicit SignalRegistry(std::size_t default_history = 1024) : default_history_(default_history) {}
  /// Creates `name` ("Component.signal") of `size` doubles. Errors: Duplicate (with a different
  /// size), InvalidArgument (size 0, malformed name). Creating an existing signal with the same
  /// size returns it.
  Expected<Signal*> add(std::string_view name, ComponentId component, std::size_t size);
  Signal* find(std::string_view name) const noexcept;
  const std::vector<std::unique_ptr<Signal>>& all() const noexcept { return signals_; }
  /// Removes the signals created after the first `count` (undoing a failed configuration step).
  void truncate(std::size_t count) {
    if (count < signals_.size()) signals_.resize(count);
  }

private:
  std::size_t default_history_;
  std::vector<std::unique_ptr<Signal>> signals_;
};

}  // namespace safecass
