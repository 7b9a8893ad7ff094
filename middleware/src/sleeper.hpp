#pragma once
// Internal: how the middleware's own threads (the bus link, the watches) wait for their next duty.
// They sleep until it is due, or until woken or stopped, instead of polling: an idle process
// wakes a few times a second, not fifty to a hundred (docs/middleware.md, "Threads").

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace safecass::middleware {

class Sleeper {
public:
  /// Sleeps until `deadline` (steady_clock ns, as steady_ns()), a wake() or stop(). False once
  /// stopped (then at once, every time, until restart()).
  bool sleep_until(std::int64_t deadline) {
    using Clock = std::chrono::steady_clock;
    // A deadline past any sensible one (nothing due: INT64_MAX) waits a day at most: no overflow.
    const auto now = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch());
    const auto at = std::min(std::chrono::nanoseconds(deadline), now + std::chrono::hours(24));
    const Clock::time_point until{std::chrono::duration_cast<Clock::duration>(at)};
    std::unique_lock lock(mutex_);
    cv_.wait_until(lock, until, [this] { return stopped_ || woken_; });
    woken_ = false;
    return !stopped_;
  }
  /// Ends the current (or the next) sleep early: a duty came up that may be due sooner.
  void wake() noexcept {
    {
      std::lock_guard lock(mutex_);
      woken_ = true;
    }
    cv_.notify_all();
  }
  /// Ends every sleep, now and later, until restart().
  void stop() noexcept {
    {
      std::lock_guard lock(mutex_);
      stopped_ = true;
    }
    cv_.notify_all();
  }
  void restart() noexcept {
    std::lock_guard lock(mutex_);
    stopped_ = false;
    woken_ = false;
  }

private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stopped_ = false;
  bool woken_ = false;
};

}  // namespace safecass::middleware
