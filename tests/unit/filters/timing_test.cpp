// Behaviour of the timing-supervision filters (DESIGN §3): Occurrence, Watchdog, Frequency,
// DutyCycle, Deadline.

#include "builtin_fixture.hpp"

namespace safecass::test {
namespace {

using OccurrenceFilter = BuiltinFixture;
using WatchdogFilter = BuiltinFixture;
using FrequencyFilter = BuiltinFixture;
using DutyCycleFilter = BuiltinFixture;
using DeadlineFilter = BuiltinFixture;

// ---- Occurrence -------------------------------------------------------------------------------

Params occurrence_params(double count, double window) {
  return {{"input_signal", std::string("x")},
          {"count", count},
          {"window", window},
          {"event_onset", std::string("EVT_X")},
          {"output_signal", std::string("n")}};
}

TEST_F(OccurrenceFilter, CountsRisingEdgesWithinTheWindow) {
  Signal* x = signal("x");
  Filter* f = make("Occurrence", occurrence_params(3, 1.0));
  feed(x, f, 0.1, 1);  // edge 1
  feed(x, f, 0.2, 5);  // still on: not an edge
  feed(x, f, 0.3, 0);
  feed(x, f, 0.4, 1);  // edge 2
  feed(x, f, 0.5, 0);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 0.6, 2);  // edge 3
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(times_, at({0.6}));
  EXPECT_EQ(values_, Values{2});
  // One output sample per run: the occurrences within the window at that time.
  EXPECT_EQ(values_of("n"), (Values{1, 1, 1, 2, 2, 3}));
}

TEST_F(OccurrenceFilter, ClearsAsOldOccurrencesAgeOutOnTick) {
  Signal* x = signal("x");
  Filter* f = make("Occurrence", occurrence_params(3, 1.0));
  for (double t : {0.1, 0.4, 0.6}) {
    feed(x, f, t, 1);
    feed(x, f, t + 0.05, 0);
  }
  ASSERT_EQ(events_, Events{"EVT_X"});
  tick(f, 1.1);  // 0.1 is exactly one window old: still counted
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(latest("C.n"), 3);
  tick(f, 1.15);  // 0.1 has left the window
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({0.6, 1.15}));
  EXPECT_EQ(latest("C.n"), 2);
  tick(f, 1.45);
  EXPECT_EQ(latest("C.n"), 1);
  tick(f, 1.65);
  EXPECT_EQ(latest("C.n"), 0);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
}

TEST_F(OccurrenceFilter, EdgesFartherApartThanTheWindowNeverAccumulate) {
  Signal* x = signal("x");
  Filter* f = make("Occurrence", occurrence_params(2, 0.5));
  for (double t : {1.0, 1.6, 2.2, 2.8}) {
    feed(x, f, t, 1);
    feed(x, f, t + 0.1, 0);
  }
  EXPECT_TRUE(events_.empty());
  feed(x, f, 3.0, 1);  // 0.2 s after the previous edge
  EXPECT_EQ(events_, Events{"EVT_X"});
}

// ---- Watchdog ---------------------------------------------------------------------------------

TEST_F(WatchdogFilter, TimeoutIsCountedFromTheFirstRunAndANewSampleClears) {
  Signal* hb = signal("hb");
  Filter* f =
      make("Watchdog", {{"input_signal", std::string("hb")}, {"timeout", 0.5}, {"output_signal", std::string("age")}});
  tick(f, 10.0);  // start-up
  tick(f, 10.4);
  EXPECT_TRUE(events_.empty());
  tick(f, 10.6);
  EXPECT_EQ(events_, Events{"EVT_STALE"});  // the default events
  EXPECT_EQ(machines_, Events{"C.s_A"});
  EXPECT_NEAR(values_.at(0), 0.6, 1e-12);  // the age that fired it
  EXPECT_EQ(times_, at({10.6}));
  tick(f, 10.65);
  feed(hb, f, 10.7, 42);
  EXPECT_EQ(events_, (Events{"EVT_STALE", "/EVT_STALE"}));
  EXPECT_EQ(times_, at({10.6, 10.7}));
  EXPECT_EQ(app_state(), State::Normal);
  const Values age = values_of("age");
  ASSERT_EQ(age.size(), 5u);
  EXPECT_NEAR(age[0], 0.0, 1e-12);
  EXPECT_NEAR(age[1], 0.4, 1e-12);
  EXPECT_NEAR(age[2], 0.6, 1e-12);
  EXPECT_NEAR(age[3], 0.65, 1e-12);
  EXPECT_NEAR(age[4], 0.0, 1e-12);
}

TEST_F(WatchdogFilter, HoldingAValueWithoutANewSampleIsNotANewSample) {
  Signal* hb = signal("hb");
  Filter* f = make("Watchdog", {{"input_signal", std::string("hb")}, {"timeout", 0.5}});
  feed(hb, f, 10.1, 1);
  tick(f, 10.5);
  tick(f, 10.7);  // 0.6 s since the sample
  ASSERT_EQ(events_, Events{"EVT_STALE"});
  // The old sample written again (same time stamp, same value) and runs without a sample: stale.
  push(hb, 10.1, 1);
  tick(f, 10.8);
  tick(f, 11.5);
  EXPECT_EQ(events_, Events{"EVT_STALE"});
  EXPECT_EQ(app_state(), State::Error);
  // A new sample, even of the same value, is a sign of life.
  feed(hb, f, 11.6, 1);
  EXPECT_EQ(events_, (Events{"EVT_STALE", "/EVT_STALE"}));
}

TEST_F(WatchdogFilter, AnOlderSampleArrivingLateDoesNotMoveTheLastSignOfLifeBack) {
  Signal* hb = signal("hb");
  Filter* f =
      make("Watchdog", {{"input_signal", std::string("hb")}, {"timeout", 0.5}, {"output_signal", std::string("age")}});
  feed(hb, f, 10.1, 1);
  push(hb, 9.9, 1);  // stamped before the newest sample
  tick(f, 10.5);
  EXPECT_TRUE(events_.empty());
  EXPECT_NEAR(latest("C.age"), 0.4, 1e-12);
  tick(f, 10.65);
  EXPECT_EQ(events_, Events{"EVT_STALE"});
}

TEST_F(WatchdogFilter, RegularSamplesKeepItQuiet) {
  Signal* hb = signal("hb");
  Filter* f = make("Watchdog", {{"input_signal", std::string("hb")}, {"timeout", 0.5}});
  for (int k = 0; k < 20; ++k) {
    feed(hb, f, 1.0 + 0.3 * k, k);
    tick(f, 1.0 + 0.3 * k + 0.25);
  }
  EXPECT_TRUE(events_.empty());
  tick(f, 1.0 + 0.3 * 19 + 0.55);
  EXPECT_EQ(events_, Events{"EVT_STALE"});
}

TEST_F(WatchdogFilter, HeartbeatAliasWatchesAVectorSignalWithChosenEvents) {
  Signal* v = signal("v", 3);
  Filter* f = make("Heartbeat", {{"input_signal", std::string("v")},
                                 {"timeout", 1.0},
                                 {"event_onset", std::string("EVT_X")},
                                 {"event_completion", std::string("/EVT_X")}});
  feed(v, f, 0.0, {1, 2, 3});
  tick(f, 1.5);
  feed(v, f, 2.0, {1, 2, 3});
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.5, 2.0}));
}

// ---- Frequency --------------------------------------------------------------------------------

TEST_F(FrequencyFilter, MeanRateBelowMinRateRaisesAndRecovers) {
  Signal* x = signal("x");
  Filter* f = make("Frequency", {{"input_signal", std::string("x")},
                                 {"min_rate", 9.0},
                                 {"window", 4.0},
                                 {"event_onset", std::string("EVT_X")},
                                 {"output_signal", std::string("rate")}});
  for (double t : {1.0, 1.1, 1.2, 1.3, 1.4}) feed(x, f, t, 0);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.6, 0);  // intervals 0.1 0.1 0.1 0.2: 8 Hz
  EXPECT_EQ(events_, Events{"EVT_X"});
  for (double t : {1.7, 1.8, 1.9}) feed(x, f, t, 0);  // the slow interval is still in the window
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 2.0, 0);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.6, 2.0}));
  EXPECT_NEAR(values_.at(0), 8.0, 1e-9);
  const Values rate = values_of("rate");
  ASSERT_EQ(rate.size(), 6u);
  EXPECT_NEAR(rate[0], 10.0, 1e-9);
  EXPECT_NEAR(rate[1], 8.0, 1e-9);
  EXPECT_NEAR(rate[5], 10.0, 1e-9);
}

TEST_F(FrequencyFilter, MeanRateAboveMaxRateRaises) {
  Signal* x = signal("x");
  Filter* f = make(
      "Frequency",
      {{"input_signal", std::string("x")}, {"max_rate", 20.0}, {"window", 3.0}, {"event_onset", std::string("EVT_X")}});
  for (double t : {0.0, 0.1, 0.2, 0.3, 0.32}) feed(x, f, t, 0);  // 10 Hz, then 0.1 0.1 0.02: 13.6 Hz
  EXPECT_TRUE(events_.empty());
  feed(x, f, 0.34, 0);  // 0.1 0.02 0.02: 21.4 Hz
  feed(x, f, 0.44, 0);  // 0.02 0.02 0.1: still 21.4 Hz
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_NEAR(values_.at(0), 3 / 0.14, 1e-9);
  feed(x, f, 0.54, 0);  // 0.02 0.1 0.1: 13.6 Hz
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({0.34, 0.54}));
}

TEST_F(FrequencyFilter, IntervalFarFromTheMeanIsJitter) {
  Signal* x = signal("x");
  Filter* f = make("Frequency", {{"input_signal", std::string("x")},
                                 {"max_jitter", 0.02},
                                 {"window", 4.0},
                                 {"event_onset", std::string("EVT_X")}});
  for (double t : {1.0, 1.1, 1.2, 1.3, 1.4}) feed(x, f, t, 0);
  feed(x, f, 1.515, 0);  // 0.115 vs mean 0.10375: 0.01125, within
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.665, 0);  // 0.15 vs mean 0.11625: 0.03375, jitter
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 1.765, 0);  // 0.1 vs mean 0.11625: 0.01625, within
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.665, 1.765}));
  EXPECT_NEAR(values_.at(0), 1 / 0.11625, 1e-9);
}

TEST_F(FrequencyFilter, JudgedOnlyOnceTheWindowIsFull) {
  Signal* x = signal("x");
  Filter* f = make("Period", {{"input_signal", std::string("x")},
                              {"min_rate", 100.0},
                              {"window", 5.0},
                              {"event_onset", std::string("EVT_X")},
                              {"output_signal", std::string("rate")}});
  for (double t : {1.0, 2.0, 3.0, 4.0, 5.0}) feed(x, f, t, 0);  // four intervals at 1 Hz
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(count_of("rate"), 0u);
  feed(x, f, 6.0, 0);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(times_, at({6.0}));
  ASSERT_EQ(count_of("rate"), 1u);
  EXPECT_NEAR(latest("C.rate"), 1.0, 1e-12);
}

// ---- DutyCycle --------------------------------------------------------------------------------

TEST_F(DutyCycleFilter, ExecutionTimeAboveMaxDutyOfThePeriodRaises) {
  Signal* x = signal("exec");
  Filter* f = make("DutyCycle", {{"input_signal", std::string("exec")},
                                 {"period", 0.01},
                                 {"max_duty", 0.8},
                                 {"event_onset", std::string("EVT_X")},
                                 {"output_signal", std::string("duty")}});
  feed(x, f, 1.00, 0.005);
  feed(x, f, 1.01, 0.009);
  feed(x, f, 1.02, 0.0085);
  feed(x, f, 1.03, 0.007);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.01, 1.03}));
  EXPECT_NEAR(values_.at(0), 0.9, 1e-12);
  const Values duty = values_of("duty");
  ASSERT_EQ(duty.size(), 4u);
  const double expected[] = {0.5, 0.9, 0.85, 0.7};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(duty[i], expected[i], 1e-12) << i;
}

TEST_F(DutyCycleFilter, DefaultMaxDutyIsEightyPercent) {
  Signal* x = signal("exec");
  Filter* f = make("DutyCycle",
                   {{"input_signal", std::string("exec")}, {"period", 2.0}, {"event_onset", std::string("EVT_X")}});
  feed(x, f, 1.0, 1.5);  // 0.75
  EXPECT_TRUE(events_.empty());
  feed(x, f, 2.0, 1.75);  // 0.875
  EXPECT_EQ(events_, Events{"EVT_X"});
}

// ---- Deadline ---------------------------------------------------------------------------------

Params deadline_params(double deadline) {
  return {{"input_signals", std::vector<std::string>{"start", "end"}},
          {"deadline", deadline},
          {"event_onset", std::string("EVT_X")},
          {"output_signal", std::string("elapsed")}};
}

TEST_F(DeadlineFilter, LateEndRaisesAndAPairWithinTheDeadlineClears) {
  Signal* start = signal("start");
  Signal* end = signal("end");
  make("Deadline", deadline_params(0.1));
  push(start, 1.0, 1);
  run_all(1.0);
  push(end, 1.05, 1);
  run_all(1.05);
  EXPECT_TRUE(events_.empty());
  push(start, 2.0, 1);
  run_all(2.0);
  push(end, 2.25, 1);  // the first run after the start: judged by the end checkpoint
  run_all(2.25);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_NEAR(values_.at(0), 0.25, 1e-12);
  push(start, 3.0, 1);
  push(end, 3.08, 1);
  run_all(3.1);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  const Values elapsed = values_of("elapsed");
  ASSERT_EQ(elapsed.size(), 3u);
  EXPECT_NEAR(elapsed[0], 0.05, 1e-12);
  EXPECT_NEAR(elapsed[1], 0.25, 1e-12);
  EXPECT_NEAR(elapsed[2], 0.08, 1e-12);
}

TEST_F(DeadlineFilter, StartStillOpenAfterTheDeadlineRaisesOnTick) {
  Signal* start = signal("start");
  Signal* end = signal("end");
  make("Deadline", deadline_params(0.1));
  push(start, 1.0, 1);
  run_all(1.0);
  run_all(1.05);
  EXPECT_TRUE(events_.empty());
  run_all(1.2);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(times_, at({1.2}));
  EXPECT_NEAR(values_.at(0), 0.2, 1e-12);
  run_all(1.3);
  push(end, 1.4, 1);  // late, but the onset is already out (EDGE)
  run_all(1.4);
  EXPECT_EQ(events_, Events{"EVT_X"});
  push(start, 2.0, 1);
  run_all(2.0);
  push(end, 2.02, 1);
  run_all(2.02);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.2, 2.02}));
}

TEST_F(DeadlineFilter, RepeatedStartsWithoutAnEndDoNotRestartTheDeadline) {
  Signal* start = signal("start");
  signal("end");  // never written
  make("Deadline", deadline_params(0.1));
  // A loop that starts every 50 ms and never reaches its end checkpoint.
  for (int k = 0; k <= 4; ++k) {
    push(start, 1.0 + 0.05 * k, 1);
    run_all(1.0 + 0.05 * k);
  }
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(times_, at({1.15})) << "the deadline runs from the first unmatched start";
}

TEST_F(DeadlineFilter, EndWithoutAStartIsIgnored) {
  signal("start");
  Signal* end = signal("end");
  make("Deadline", deadline_params(0.1));
  push(end, 1.0, 1);
  run_all(1.0);
  run_all(5.0);
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(count_of("elapsed"), 0u);
}

TEST_F(DeadlineFilter, NeedsExactlyTwoCheckpointSignals) {
  signal("start");
  signal("end");
  Params p = deadline_params(0.1);
  p["input_signals"] = std::vector<std::string>{"start"};
  auto f = try_make("Deadline", p);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'input_signals'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.signals().find("C.elapsed"), nullptr);
  EXPECT_EQ(monitor_.filters().size(), 0u);
}

}  // namespace
}  // namespace safecass::test
