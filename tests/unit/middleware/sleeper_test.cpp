// How the middleware's threads wait for their next duty (middleware/src/sleeper.hpp): until it is
// due, or until woken or stopped. Bounds below are lower bounds or generous upper ones: a loaded
// machine can make a wait longer, never shorter.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <thread>

#include "ice_util.hpp"
#include "sleeper.hpp"

namespace safecass::middleware {
namespace {

constexpr std::int64_t kMillisecond = 1'000'000;

TEST(Sleeper, ASleepEndsAtItsDeadlineAndNeverBefore) {
  Sleeper sleeper;
  const std::int64_t deadline = steady_ns() + 30 * kMillisecond;
  EXPECT_TRUE(sleeper.sleep_until(deadline));
  EXPECT_GE(steady_ns(), deadline);
  EXPECT_TRUE(sleeper.sleep_until(deadline - 1000 * kMillisecond)) << "a deadline already past: at once";
}

TEST(Sleeper, AWakeEndsTheSleepEarlyAndAWakeBeforeTheSleepEndsTheNextOne) {
  Sleeper sleeper;
  const std::int64_t start = steady_ns();
  std::thread waker([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    sleeper.wake();
  });
  EXPECT_TRUE(sleeper.sleep_until(start + 60'000 * kMillisecond)) << "woken, not stopped";
  waker.join();
  EXPECT_LT(steady_ns() - start, 30'000 * kMillisecond) << "the wake, not the minute, ended it";
  sleeper.wake();  // a duty that came up while the thread was busy is not lost
  EXPECT_TRUE(sleeper.sleep_until(steady_ns() + 60'000 * kMillisecond));
}

TEST(Sleeper, AStopEndsTheSleepAndEverySleepAfterItUntilRestarted) {
  Sleeper sleeper;
  std::atomic<bool> returned_true{true};
  std::thread sleeping([&] { returned_true = sleeper.sleep_until(std::numeric_limits<std::int64_t>::max()); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  sleeper.stop();
  sleeping.join();  // a sleep "forever" ends at the stop
  EXPECT_FALSE(returned_true.load());
  EXPECT_FALSE(sleeper.sleep_until(steady_ns() + 60'000 * kMillisecond)) << "stopped: at once";
  sleeper.restart();
  EXPECT_TRUE(sleeper.sleep_until(steady_ns() + kMillisecond));
}

}  // namespace
}  // namespace safecass::middleware
