#include "filter_fixture.hpp"

namespace safecass::test {
namespace {

using PipelineTest = FilterFixture;

FilterConfig stage(const std::string& type, Params p) {
  FilterConfig c;
  c.type = type;
  c.target.component = "C";
  c.params = std::move(p);
  return c;
}

TEST_F(PipelineTest, OutputOfOneFilterFeedsTheNextInTheSameRun) {
  Signal* force = signal("force", 3);
  ASSERT_TRUE(monitor_.add_filter(
      stage("Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}})));
  ASSERT_TRUE(monitor_.add_filter(
      stage("Threshold",
            {{"input_signal", std::string("norm")}, {"threshold", 30.0}, {"event_onset", std::string("EVT_X")}})));
  const double f[] = {0, 30, 40};
  force->push(Time{1}, f);
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Error);
  EXPECT_DOUBLE_EQ(latest("C.norm"), 50);
}

TEST_F(PipelineTest, PipelineSugarChainsStagesThroughGeneratedSignals) {
  Signal* force = signal("force", 3);
  auto p = monitor_.add_pipeline(
      "force_check",
      {stage("Norm", {{"input_signal", std::string("force")}}), stage("MovingAverage", {{"window", 2.0}}),
       stage("Threshold", {{"threshold", 30.0}, {"event_onset", std::string("EVT_X")}})});
  ASSERT_TRUE(p) << p.error().message;
  ASSERT_EQ(p->size(), 3u);
  EXPECT_EQ((*p)[1]->inputs()[0]->name(), "C.force_check_1");
  EXPECT_EQ((*p)[2]->inputs()[0]->name(), "C.force_check_2");
  const double low[] = {0, 0, 20};
  const double high[] = {0, 0, 50};
  force->push(Time{1}, low);
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Normal);
  force->push(Time{2}, high);
  monitor_.run_active(component_, Time{2});
  EXPECT_EQ(app_state(), State::Error) << "average of 20 and 50 is 35 > 30";
}

TEST_F(PipelineTest, FailingStageLeavesNothingBehind) {
  signal("force", 3);
  const std::size_t signals = monitor_.signals().all().size();
  auto p = monitor_.add_pipeline(
      "broken", {stage("Norm", {{"input_signal", std::string("force")}}), stage("MovingAverage", {{"window", 0.0}}),
                 stage("Threshold", {{"threshold", 30.0}, {"event_onset", std::string("EVT_X")}})});
  ASSERT_FALSE(p);
  EXPECT_NE(p.error().message.find("stage 2"), std::string::npos) << p.error().message;
  EXPECT_NE(p.error().message.find("'window'"), std::string::npos) << p.error().message;
  EXPECT_TRUE(monitor_.filters().empty());
  EXPECT_EQ(monitor_.signals().all().size(), signals);
}

using InjectionTest = FilterFixture;

TEST_F(InjectionTest, ShallowInjectionIsSeenByThatFilterAloneAndMarked) {
  Signal* x = signal("x");
  FilterConfig a = stage(
      "Threshold", {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  a.name = "target";
  FilterConfig b = stage("Bypass", {{"input_signal", std::string("x")}, {"output_signal", std::string("copy")}});
  b.name = "bystander";
  ASSERT_TRUE(monitor_.add_filter(a));
  ASSERT_TRUE(monitor_.add_filter(b));
  std::vector<Record> injections;
  co_.subscribe([&](const Record& r) {
    if (r.kind == RecordKind::Injection) injections.push_back(r);
  });
  ASSERT_TRUE(monitor_.inject_shallow("target", {{50}}));
  x->push(Time{1}, 1.0);
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Error);
  EXPECT_DOUBLE_EQ(latest("C.copy"), 1.0) << "the other consumer saw the real sample";
  ASSERT_EQ(injections.size(), 1u);
  EXPECT_NE(std::string(injections[0].text).find("shallow injection into filter target: 50"), std::string::npos);
  const auto why = explain(co_, "C.s_A");
  ASSERT_TRUE(why);
  EXPECT_TRUE((*why)[0].root.injected);
  // After the injected sample is consumed, real samples are judged again.
  x->push(Time{2}, 1.0);
  monitor_.run_active(component_, Time{2});
  EXPECT_EQ(app_state(), State::Normal);
}

TEST_F(InjectionTest, AShallowInjectedSampleIsHeldForItsRunAndTheEndOfTheInjectionRestoresTheRealValue) {
  Signal* a = signal("a");
  Signal* b = signal("b");
  FilterConfig c = stage("Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b"}},
                                        {"output_signal", std::string("d")},
                                        {"operation", std::string("subtract")}});
  c.name = "diff";
  ASSERT_TRUE(monitor_.add_filter(c));
  a->push(Time{1}, 10.0);
  b->push(Time{1}, 1.0);
  monitor_.run_active(component_, Time{1});
  EXPECT_DOUBLE_EQ(latest("C.d"), 9.0);
  ASSERT_TRUE(monitor_.inject_shallow("diff", {{100}}));  // replaces a for one run
  monitor_.run_active(component_, Time{2});
  EXPECT_DOUBLE_EQ(latest("C.d"), 99.0);
  b->push(Time{3}, 2.0);  // the injection ran out: a's real value (10) is judged again with it
  monitor_.run_active(component_, Time{3});
  EXPECT_DOUBLE_EQ(latest("C.d"), 8.0);
  a->push(Time{4}, 20.0);
  monitor_.run_active(component_, Time{4});
  EXPECT_DOUBLE_EQ(latest("C.d"), 18.0);
}

TEST_F(InjectionTest, DeepInjectionWritesTheSignalSoEveryConsumerSeesIt) {
  Signal* x = signal("x");
  FilterConfig a = stage(
      "Threshold", {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  FilterConfig b = stage("Bypass", {{"input_signal", std::string("x")}, {"output_signal", std::string("copy")}});
  ASSERT_TRUE(monitor_.add_filter(a));
  ASSERT_TRUE(monitor_.add_filter(b));
  ASSERT_TRUE(monitor_.inject_deep("C.x", {{42}}, Time{1}));
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Error);
  EXPECT_DOUBLE_EQ(latest("C.copy"), 42);
  Time t{};
  bool injected = false;
  double v = 0;
  ASSERT_TRUE(x->latest(t, &v, &injected));
  EXPECT_DOUBLE_EQ(v, 42);
  EXPECT_TRUE(injected) << "the signal's history marks injected samples";
  const auto history = co_.history(co_.structure().application_machine(component_));
  const bool has_injection =
      std::any_of(history.begin(), history.end(), [](const Record& r) { return r.kind == RecordKind::Injection; });
  EXPECT_TRUE(has_injection) << "the injection is in the target machine's history";
}

TEST_F(InjectionTest, VectorInjectionChecksSizesAndChangesNothingOnError) {
  Signal* force = signal("force", 3);
  FilterConfig n = stage("Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}});
  n.name = "norm";
  ASSERT_TRUE(monitor_.add_filter(n));
  auto bad = monitor_.inject_shallow("norm", {{1, 2}});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("size 3"), std::string::npos) << bad.error().message;
  auto bad_deep = monitor_.inject_deep("C.force", {{1, 2, 3}, {1}}, Time{1});
  ASSERT_FALSE(bad_deep);
  EXPECT_EQ(force->count(), 0u) << "nothing written when one sample is wrong";
  ASSERT_TRUE(monitor_.inject_shallow("norm", {{3, 4, 0}}));
  monitor_.run_active(component_, Time{1});
  EXPECT_DOUBLE_EQ(latest("C.norm"), 5);
  EXPECT_FALSE(monitor_.inject_shallow("nope", {{1}}));
  EXPECT_FALSE(monitor_.inject_deep("C.nope", {{1}}, Time{1}));
}

}  // namespace
}  // namespace safecass::test
