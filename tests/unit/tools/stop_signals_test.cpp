// How `safecass run --coordinator` and `safecass supervisor` wait for their end
// (tools/safecass/stop_signals.hpp): SIGINT or SIGTERM, or the end of --duration, without polling.

#include "stop_signals.hpp"

#include <gtest/gtest.h>
#include <pthread.h>

#include <chrono>
#include <csignal>
#include <thread>

namespace safecass::tools {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

TEST(StopSignals, TheWaitEndsAtTheDeadlineWhenNoSignalComesAndNotBefore) {
  const StopSignals signals;
  const auto deadline = Clock::now() + 30ms;
  EXPECT_FALSE(signals.wait(deadline));
  EXPECT_GE(Clock::now(), deadline);
  EXPECT_FALSE(signals.wait(Clock::now() - 1s)) << "a deadline already past: at once";
}

TEST(StopSignals, ASigtermThatCameBeforeTheWaitEndsItAtOnceAndKillsNobody) {
  const StopSignals signals;
  ASSERT_EQ(std::raise(SIGTERM), 0);  // blocked: pending, not fatal
  const auto start = Clock::now();
  EXPECT_TRUE(signals.wait(std::nullopt));
  EXPECT_LT(Clock::now() - start, 30s);
}

TEST(StopSignals, ASigintSentWhileTheMainThreadWaitsWithoutADeadlineEndsTheWait) {
  const StopSignals signals;
  const pthread_t waiting = pthread_self();
  std::thread sender([waiting] {
    std::this_thread::sleep_for(20ms);
    pthread_kill(waiting, SIGINT);
  });
  EXPECT_TRUE(signals.wait(std::nullopt));
  sender.join();
}

TEST(StopSignals, ASignalThatComesAfterTheWaitIsTakenWhenTheWaitingEndsAndKillsNobody) {
  {
    const StopSignals signals;
    EXPECT_FALSE(signals.wait(Clock::now()));
    ASSERT_EQ(std::raise(SIGINT), 0);  // a second Ctrl-C while the run stops
  }
  sigset_t pending;
  ASSERT_EQ(sigpending(&pending), 0);
  EXPECT_EQ(sigismember(&pending, SIGINT), 0) << "taken before the mask was restored";
}

TEST(StopSignals, ADurationThatIsNotPositiveMeansUntilASignal) {
  EXPECT_FALSE(deadline_after(0.0).has_value());
  EXPECT_FALSE(deadline_after(-1.0).has_value());
  const auto before = Clock::now();
  const auto deadline = deadline_after(2.5);
  ASSERT_TRUE(deadline.has_value());
  EXPECT_GE(*deadline - before, 2500ms);
  EXPECT_LE(*deadline - Clock::now(), 2500ms);
}

}  // namespace
}  // namespace safecass::tools
