// Behaviour of the detection filters (DESIGN §3): Threshold, Range, OnOff, ChangeDetection,
// Debounce.

#include "builtin_fixture.hpp"

namespace safecass::test {
namespace {

using ThresholdFilter = BuiltinFixture;
using RangeFilter = BuiltinFixture;
using OnOffFilter = BuiltinFixture;
using ChangeDetectionFilter = BuiltinFixture;
using DebounceFilter = BuiltinFixture;

Params threshold_params(double threshold, Params extra = {}) {
  Params p{{"input_signal", std::string("x")}, {"threshold", threshold}, {"event_onset", std::string("EVT_X")}};
  for (auto& [k, v] : extra) p[k] = v;
  return p;
}

// ---- Threshold --------------------------------------------------------------------------------

TEST_F(ThresholdFilter, OnsetOnlyWhenValueExceedsThresholdPlusTolerance) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"tolerance", 2.0}}));
  feed(x, f, 1.0, 10.5);
  feed(x, f, 1.1, 12.0);  // equal to threshold + tolerance: not beyond
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(app_state(), State::Normal);
  feed(x, f, 1.2, 12.25);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_, Values{12.25});
  EXPECT_EQ(machines_, Events{"C.s_A"});
  EXPECT_EQ(app_state(), State::Error);
  EXPECT_TRUE(f->detected());
}

TEST_F(ThresholdFilter, CompletionOnlyAtOrBelowThresholdPlusToleranceMinusHysteresis) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"tolerance", 2.0}, {"hysteresis", 3.0}}));
  feed(x, f, 1.0, 13);    // onset (> 12)
  feed(x, f, 1.1, 9.25);  // > 9: still detected
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 1.2, 9.0);  // ≤ 12 − 3: completion
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.0, 1.2}));
  EXPECT_EQ(app_state(), State::Normal);
  EXPECT_FALSE(f->detected());
}

TEST_F(ThresholdFilter, InsideHysteresisBandKeepsDetection) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"hysteresis", 4.0}, {"output_signal", std::string("out")}}));
  feed(x, f, 1.0, 11);  // onset
  // Band: (6, 10]. Wandering inside it, and back above the limit, neither clears nor raises again.
  for (double v : {10.0, 8.0, 6.5, 11.0, 9.0, 6.25}) feed(x, f, 1.1, v);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(app_state(), State::Error);
  feed(x, f, 1.2, 6.0);  // completion
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  // Once cleared, values in the band do not raise: only x > 10 does.
  feed(x, f, 1.3, 9.5);
  feed(x, f, 1.4, 10.0);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_of("out"), (Values{1, 1, 1, 1, 1, 1, 1, 0, 0, 0}));
}

TEST_F(ThresholdFilter, WithoutHysteresisClearsAtTheOnsetLevel) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10));
  feed(x, f, 1.0, 10.5);
  feed(x, f, 1.1, 10.0);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_[0], 10.5);
}

TEST_F(ThresholdFilter, DirectionBelowMirrorsOnsetAndCompletion) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"tolerance", 1.0},
                                                      {"hysteresis", 2.0},
                                                      {"direction", std::string("below")},
                                                      {"output_signal", std::string("out")}}));
  feed(x, f, 1.0, 50);   // far above: fine for "below"
  feed(x, f, 1.1, 9.0);  // equal to threshold − tolerance: not beyond
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.2, 8.75);   // onset (< 9)
  feed(x, f, 1.3, 10.75);  // band [9, 11): kept
  feed(x, f, 1.4, 8.0);    // beyond again: no second onset (EDGE)
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_, Values{8.75});
  feed(x, f, 1.5, 11.0);  // ≥ 9 + 2: completion
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_of("out"), (Values{0, 0, 1, 1, 1, 0}));
}

TEST_F(ThresholdFilter, PersistenceInSamplesNeedsConsecutiveSamplesAndADipResetsTheCount) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"persistence", 3.0}}));
  feed(x, f, 1.0, 11);
  feed(x, f, 1.1, 12);
  feed(x, f, 1.2, 5);  // dip: the count starts again
  feed(x, f, 1.3, 13);
  feed(x, f, 1.4, 14);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.5, 15);  // third consecutive sample beyond
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_, Values{15});
  EXPECT_EQ(times_, at({1.5}));
  feed(x, f, 1.6, 4);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
}

TEST_F(ThresholdFilter, PersistenceInSecondsCountsTimeSinceTheFirstSampleBeyond) {
  Signal* x = signal("x");
  Filter* f =
      make("Threshold", threshold_params(10, {{"persistence", 0.5}, {"persistence_unit", std::string("seconds")}}));
  feed(x, f, 1.0, 11);
  feed(x, f, 1.3, 5);  // dip: the clock starts again at the next sample beyond
  feed(x, f, 1.6, 12);
  feed(x, f, 1.9, 13);
  feed(x, f, 2.05, 14);  // 0.45 s since 1.6
  EXPECT_TRUE(events_.empty());
  feed(x, f, 2.15, 15);  // 0.55 s since 1.6
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_, Values{15});
  EXPECT_EQ(times_, at({2.15}));
}

TEST_F(ThresholdFilter, EdgeModeSendsOneOnsetPerCrossingAndOneCompletion) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10));
  for (double v : {11.0, 12.0, 13.0, 5.0, 4.0, 21.0, 22.0, 3.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_.at(0), 11);
  EXPECT_EQ(values_.at(2), 21);
  EXPECT_EQ(event_records(app()), 4u);
}

TEST_F(ThresholdFilter, LevelModeRepeatsTheOnsetEverySampleAndTheMachineOnlyRefreshes) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10, {{"hysteresis", 2.0}}), DetectionMode::Level);
  feed(x, f, 1.0, 11);
  feed(x, f, 1.1, 12);
  feed(x, f, 1.2, 9);  // in the band: still detected, so still an onset
  feed(x, f, 1.3, 13);
  std::vector<Condition> conditions = co_.conditions(app());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(co_.structure().event(conditions[0].event).name, "EVT_X");
  EXPECT_EQ(conditions[0].count, 4u);
  EXPECT_EQ(conditions[0].first, seconds_to_time(1.0));
  EXPECT_EQ(conditions[0].last, seconds_to_time(1.3));
  // The refreshes are not in the stream nor in the history.
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(event_records(app()), 1u);
  feed(x, f, 1.4, 8);  // one completion
  feed(x, f, 1.5, 7);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_TRUE(co_.conditions(app()).empty());
  EXPECT_EQ(event_records(app()), 2u);
}

TEST_F(ThresholdFilter, LevelModeSecondCrossingStartsANewConditionCount) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold_params(10), DetectionMode::Level);
  for (double v : {11.0, 12.0, 13.0, 0.0, 14.0, 15.0}) feed(x, f, 1.0, v);
  std::vector<Condition> conditions = co_.conditions(app());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].count, 2u);
  EXPECT_EQ(conditions[0].root.sample.value, 14);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X"}));
}

TEST_F(ThresholdFilter, OutputSignalCarriesOutputAboveAndOutputBelowEverySample) {
  Signal* x = signal("x");
  Filter* f = make(
      "Threshold",
      threshold_params(10, {{"output_signal", std::string("over")}, {"output_above", 7.5}, {"output_below", -3.0}}));
  const double ts[] = {1.0, 1.1, 1.2, 1.3};
  const double xs[] = {5, 11, 12, 2};
  for (int i = 0; i < 4; ++i) feed(x, f, ts[i], xs[i]);
  const std::vector<Written> out = written("over");
  ASSERT_EQ(out.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out[i].t, seconds_to_time(ts[i])) << i;
  EXPECT_EQ(values_of("over"), (Values{-3, 7.5, 7.5, -3}));
}

TEST_F(ThresholdFilter, WithoutEventsItOnlyWritesItsOutput) {
  Signal* x = signal("x");
  Filter* f = make("Threshold",
                   {{"input_signal", std::string("x")}, {"threshold", 1.0}, {"output_signal", std::string("out")}});
  for (double v : {0.0, 2.0, 0.0}) feed(x, f, 1.0, v);
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(values_of("out"), (Values{0, 1, 0}));
}

TEST_F(ThresholdFilter, The2016NameFilterThresholdBehavesTheSame) {
  Signal* x = signal("x");
  Filter* f = make("FilterThreshold", threshold_params(10, {{"hysteresis", 1.0}}));
  EXPECT_EQ(f->type(), "Threshold");  // asked for by its 2016 name, it is a Threshold
  for (double v : {11.0, 9.5, 9.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_.at(0), 11);
}

// ---- Range ------------------------------------------------------------------------------------

Params range_params(double lo, double hi, double h = 0) {
  return {{"input_signal", std::string("x")},
          {"min", lo},
          {"max", hi},
          {"hysteresis", h},
          {"event_onset", std::string("EVT_X")},
          {"output_signal", std::string("out")}};
}

TEST_F(RangeFilter, RaisesBelowMinAndAboveMaxAndClearsInside) {
  Signal* x = signal("x");
  Filter* f = make("Range", range_params(0, 10));
  for (double v : {0.0, 10.0, 5.0}) feed(x, f, 1.0, v);  // the bounds are inside
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.1, -0.5);
  feed(x, f, 1.2, 5);
  feed(x, f, 1.3, 10.5);
  feed(x, f, 1.4, 10);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_.at(0), -0.5);
  EXPECT_EQ(values_.at(2), 10.5);
  EXPECT_EQ(values_of("out"), (Values{0, 0, 0, 1, 0, 1, 0}));
}

TEST_F(RangeFilter, JumpingFromBelowMinToAboveMaxIsOneDetection) {
  Signal* x = signal("x");
  Filter* f = make("Range", range_params(0, 10));
  for (double v : {-1.0, 11.0, -2.0, 3.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
}

TEST_F(RangeFilter, HysteresisKeepsDetectionNearEitherEdge) {
  Signal* x = signal("x");
  Filter* f = make("Range", range_params(0, 10, 2));
  feed(x, f, 1.0, 11);  // onset above
  feed(x, f, 1.1, 9);   // inside but within 2 of max: kept
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 1.2, 8);     // ≤ max − h: completion
  feed(x, f, 1.3, -0.5);  // onset below
  feed(x, f, 1.4, 1.5);   // kept
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X"}));
  feed(x, f, 1.5, 2);  // ≥ min + h: completion
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_of("out"), (Values{1, 1, 0, 1, 1, 0}));
}

TEST_F(RangeFilter, HysteresisThatLeavesNoClearingBandIsRejectedAtCreation) {
  signal("x");
  const std::size_t signals = monitor_.signals().all().size();
  auto f = try_make("Range", range_params(0, 10, 5.5));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'hysteresis'"), std::string::npos) << f.error().message;
  EXPECT_NE(f.error().message.find("'max'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.filters().size(), 0u);
  EXPECT_EQ(monitor_.signals().all().size(), signals);
  // min + 2h == max leaves a single clearing value: accepted.
  auto g = try_make("Range", range_params(0, 10, 5));
  ASSERT_TRUE(g) << g.error().message;
  for (double v : {11.0, 6.0, 5.0}) feed(monitor_.signals().find("C.x"), *g, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
}

TEST_F(RangeFilter, MinAboveMaxIsRejectedAtCreation) {
  signal("x");
  auto f = try_make("Range", range_params(10, 0));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'min'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.filters().size(), 0u);
}

TEST_F(RangeFilter, PersistenceDelaysTheOnset) {
  Signal* x = signal("x");
  Params p = range_params(0, 10);
  p["persistence"] = 2.0;
  Filter* f = make("Range", p);
  for (double v : {11.0, 5.0, -1.0}) feed(x, f, 1.0, v);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.1, 12.0);  // outside on both sides counts as one condition
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_, Values{12});
  EXPECT_EQ(values_of("out"), (Values{0, 0, 0, 1}));
}

// ---- OnOff ------------------------------------------------------------------------------------

TEST_F(OnOffFilter, NonZeroSendsEventOnAndZeroSendsEventOff) {
  Signal* x = signal("x");
  Filter* f = make("OnOff", {{"input_signal", std::string("x")},
                             {"event_on", std::string("EVT_X")},
                             {"event_off", std::string("/EVT_X")},
                             {"output_signal", std::string("out")}});
  for (double v : {0.0, 1.0, -2.0, 0.0, 0.0, 0.5}) feed(x, f, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X"}));
  EXPECT_EQ(values_.at(0), 1.0);
  EXPECT_EQ(values_.at(2), 0.5);
  EXPECT_EQ(values_of("out"), (Values{0, 1, 1, 0, 0, 1}));
}

TEST_F(OnOffFilter, EventOffDefaultsToTheCompletionOfEventOn) {
  Signal* x = signal("x");
  Filter* f = make("OnOff", {{"input_signal", std::string("x")}, {"event_on", std::string("EVT_X")}});
  for (double v : {3.0, 0.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
}

TEST_F(OnOffFilter, UsesEventOnNotEventOnset) {
  signal("x");
  auto f = try_make("OnOff", {{"input_signal", std::string("x")}, {"event_onset", std::string("EVT_X")}});
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'event_onset'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.filters().size(), 0u);
}

// ---- ChangeDetection --------------------------------------------------------------------------

TEST_F(ChangeDetectionFilter, FirstSampleIsNeverAChange) {
  Signal* x = signal("x");
  Filter* f = make("ChangeDetection", {{"input_signal", std::string("x")},
                                       {"event_onset", std::string("EVT_X")},
                                       {"output_signal", std::string("out")}});
  feed(x, f, 1.0, 1000);
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(values_of("out"), Values{0});
  feed(x, f, 1.1, 1000);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.2, 1001);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_of("out"), (Values{0, 0, 1}));
}

TEST_F(ChangeDetectionFilter, OnlyChangesLargerThanToleranceCount) {
  Signal* x = signal("x");
  Filter* f = make("ChangeDetection", {{"input_signal", std::string("x")},
                                       {"tolerance", 0.5},
                                       {"event_onset", std::string("EVT_X")},
                                       {"output_signal", std::string("out")}});
  feed(x, f, 1.0, 1.0);
  feed(x, f, 1.1, 1.5);   // change 0.5: not larger than the tolerance
  feed(x, f, 1.2, 2.25);  // change 0.75: onset
  feed(x, f, 1.3, 2.0);   // change 0.25: completion
  feed(x, f, 1.4, 1.0);   // change −1: onset again
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X", "EVT_X"}));
  EXPECT_EQ(values_.at(0), 0.75);
  EXPECT_EQ(values_.at(2), 1.0);
  EXPECT_EQ(values_of("out"), (Values{0, 0, 1, 0, 1}));
}

TEST_F(ChangeDetectionFilter, VectorInputChangesWhenAnyElementChanges) {
  Signal* v = signal("v", 3);
  Filter* f = make("ChangeDetection", {{"input_signal", std::string("v")},
                                       {"tolerance", 0.5},
                                       {"event_onset", std::string("EVT_X")},
                                       {"output_signal", std::string("changed")}});
  ASSERT_EQ(monitor_.signals().find("C.changed")->size(), 1u);
  feed(v, f, 1.0, {0, 0, 0});
  feed(v, f, 1.1, {0, 0, 0.25});
  feed(v, f, 1.2, {0, 2, 0.25});  // element 1 changed by 2
  feed(v, f, 1.3, {0, 2, 0.25});
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(values_.at(0), 2.0);
  EXPECT_EQ(values_of("changed"), (Values{0, 0, 1, 0}));
}

// ---- Debounce ---------------------------------------------------------------------------------

TEST_F(DebounceFilter, OnsetAfterPersistenceAndCompletionAfterRelease) {
  Signal* x = signal("x");
  Filter* f = make("Debounce", {{"input_signal", std::string("x")},
                                {"persistence", 3.0},
                                {"release", 2.0},
                                {"event_onset", std::string("EVT_X")},
                                {"output_signal", std::string("out")}});
  for (double v : {1.0, 1.0, 0.0, 1.0, 1.0}) feed(x, f, 1.0, v);  // the bounce resets the count
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.1, 1);  // third consecutive: onset
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 1.2, 0);  // one off sample: not released
  feed(x, f, 1.3, 1);  // on again resets the release count
  feed(x, f, 1.4, 0);
  EXPECT_EQ(events_, Events{"EVT_X"});
  feed(x, f, 1.5, 0);  // second consecutive off: completion
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.1, 1.5}));
  EXPECT_EQ(values_of("out"), (Values{0, 0, 0, 0, 0, 1, 1, 1, 1, 0}));
}

TEST_F(DebounceFilter, PersistenceAliasAndPersistenceInSeconds) {
  Signal* x = signal("x");
  Filter* f = make("Persistence", {{"input_signal", std::string("x")},
                                   {"persistence", 0.25},
                                   {"persistence_unit", std::string("seconds")},
                                   {"event_onset", std::string("EVT_X")}});
  feed(x, f, 1.0, 1);
  feed(x, f, 1.2, 1);
  EXPECT_TRUE(events_.empty());
  feed(x, f, 1.3, 1);  // on for 0.3 s
  feed(x, f, 1.4, 0);  // release defaults to one sample
  EXPECT_EQ(events_, (Events{"EVT_X", "/EVT_X"}));
  EXPECT_EQ(times_, at({1.3, 1.4}));
}

TEST_F(DebounceFilter, NeedsAnOnsetEvent) {
  signal("x");
  auto f = try_make("Debounce", {{"input_signal", std::string("x")}});
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'event_onset'"), std::string::npos) << f.error().message;
}

}  // namespace
}  // namespace safecass::test
