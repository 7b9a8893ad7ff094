#pragma once
/// @file clock.hpp
/// Injectable time source: every timestamp in SAFECASS comes from a Clock, so tests, scenarios
/// and replay run deterministically in simulated time.

#include <atomic>
#include <chrono>

namespace safecass {

/// A point in time, as the duration since the clock's epoch.
using Time = std::chrono::nanoseconds;

/// Converts seconds (as in specs and scenarios) to Time, rounding to the nearest nanosecond.
constexpr Time seconds_to_time(double seconds) noexcept {
  return Time{static_cast<Time::rep>(seconds * 1e9 + (seconds < 0 ? -0.5 : 0.5))};
}
constexpr double to_seconds(Time t) noexcept { return static_cast<double>(t.count()) * 1e-9; }

/// The largest magnitude of a time read from outside (a recording, a log, an answer), in seconds:
/// 2^32 (136 years) rounded down. Its nanoseconds fit Time, and a double still holds its
/// microseconds, so what is written back as text reads back the same.
inline constexpr double kMaxReadSeconds = 4e9;
/// True when `seconds` (read from outside) converts to a Time: finite and at most kMaxReadSeconds
/// in magnitude. Beyond, seconds_to_time() would overflow (undefined behaviour).
constexpr bool readable_seconds(double seconds) noexcept {
  return seconds <= kMaxReadSeconds && seconds >= -kMaxReadSeconds;
}

/// A time read from text (a recording, a log, an answer; check readable_seconds() first), to the
/// microsecond: SAFECASS writes times with six decimals (seconds_text()), so what is read, written
/// and read again is the same time. Half a microsecond rounds away from zero.
constexpr Time read_seconds(double seconds) noexcept {
  const double micros = seconds * 1e6;
  return Time{static_cast<Time::rep>(micros + (micros < 0 ? -0.5 : 0.5)) * 1000};
}

/// Source of time. now() is thread-safe, lock-free and never allocates.
class Clock {
public:
  virtual ~Clock() = default;
  virtual Time now() const noexcept = 0;
};

/// Monotonic wall time (std::chrono::steady_clock), epoch = construction.
class SteadyClock final : public Clock {
public:
  SteadyClock() noexcept : start_(std::chrono::steady_clock::now()) {}
  Time now() const noexcept override {
    return std::chrono::duration_cast<Time>(std::chrono::steady_clock::now() - start_);
  }

private:
  std::chrono::steady_clock::time_point start_;
};

/// Simulated time: only set() and advance() move it. Thread-safe.
class SimulatedClock final : public Clock {
public:
  explicit SimulatedClock(Time start = Time{0}) noexcept : now_(start.count()) {}
  Time now() const noexcept override { return Time{now_.load(std::memory_order_acquire)}; }
  void set(Time t) noexcept { now_.store(t.count(), std::memory_order_release); }
  void advance(Time dt) noexcept { now_.fetch_add(dt.count(), std::memory_order_acq_rel); }

private:
  std::atomic<Time::rep> now_;
};

}  // namespace safecass
