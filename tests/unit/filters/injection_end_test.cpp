// DESIGN §3: when a filter's shallow injection queue runs out, its next run judges the input's
// current (held) real value once, as a new sample. The injection stood in for reality; its end
// restores reality, even for a sensor that publishes only on change.

#include "filter_fixture.hpp"

namespace safecass::test {
namespace {

using ShallowInjectionEnd = FilterFixture;

FilterConfig named(std::string name, const std::string& type, Params p) {
  FilterConfig c;
  c.name = std::move(name);
  c.type = type;
  c.target.component = "C";
  c.params = std::move(p);
  return c;
}

TEST_F(ShallowInjectionEnd, TheEndOfAShallowInjectionRestoresTheUnchangedRealScalarValue) {
  Signal* x = signal("x");
  ASSERT_TRUE(monitor_.add_filter(named("limit", "Threshold",
                                        {{"input_signal", std::string("x")},
                                         {"threshold", 10.0},
                                         {"output_signal", std::string("above")},
                                         {"event_onset", std::string("EVT_X")}})));
  x->push(seconds_to_time(0.0), 1.0);
  monitor_.run_active(component_, seconds_to_time(0.0));
  ASSERT_EQ(app_state(), State::Normal);
  ASSERT_TRUE(monitor_.inject_shallow("limit", {{50}, {60}}));
  monitor_.run_active(component_, seconds_to_time(0.1));
  EXPECT_EQ(app_state(), State::Error) << "the first injected value is judged";
  monitor_.run_active(component_, seconds_to_time(0.2));
  EXPECT_EQ(app_state(), State::Error) << "the second injected value is judged";
  // The real signal has not changed (no new sample): the next run judges its held value, 1.
  monitor_.run_active(component_, seconds_to_time(0.3));
  EXPECT_EQ(app_state(), State::Normal) << "the end of the injection restores reality";
  EXPECT_EQ(events_, (std::vector<std::string>{"EVT_X", "/EVT_X"}));
  EXPECT_DOUBLE_EQ(latest("C.above"), 0.0) << "the real value, 1, was judged: below the threshold";
  // Judged once: further runs without a sample send nothing.
  monitor_.run_active(component_, seconds_to_time(0.4));
  EXPECT_EQ(events_.size(), 2u);
}

TEST_F(ShallowInjectionEnd, TheEndOfAShallowInjectionRestoresTheUnchangedRealVectorValue) {
  Signal* force = signal("force", 3);
  ASSERT_TRUE(monitor_.add_filter(
      named("norm", "Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}})));
  ASSERT_TRUE(monitor_.add_filter(
      named("limit", "Threshold",
            {{"input_signal", std::string("norm")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}})));
  const double real[3] = {3, 4, 0};
  force->push(seconds_to_time(0.0), real);
  monitor_.run_active(component_, seconds_to_time(0.0));
  EXPECT_DOUBLE_EQ(latest("C.norm"), 5.0);
  ASSERT_TRUE(monitor_.inject_shallow("norm", {{30, 40, 0}}));
  monitor_.run_active(component_, seconds_to_time(0.1));
  EXPECT_DOUBLE_EQ(latest("C.norm"), 50.0);
  EXPECT_EQ(app_state(), State::Error);
  monitor_.run_active(component_, seconds_to_time(0.2));
  EXPECT_DOUBLE_EQ(latest("C.norm"), 5.0) << "the unchanged real vector is judged again";
  EXPECT_EQ(app_state(), State::Normal);
}

TEST_F(ShallowInjectionEnd, ASensorThatPublishesOnlyOnChangeDoesNotStayInErrorAfterATestInjection) {
  // An on/off sensor that publishes once, at start-up, and then only when its value changes.
  Signal* door = signal("door_open");
  ASSERT_TRUE(monitor_.add_filter(
      named("door", "OnOff", {{"input_signal", std::string("door_open")}, {"event_on", std::string("EVT_X")}})));
  door->push(seconds_to_time(0.0), 0.0);
  monitor_.run_active(component_, seconds_to_time(0.0));
  ASSERT_TRUE(monitor_.inject_shallow("door", {{1}}));  // a test: "the door opens"
  monitor_.run_active(component_, seconds_to_time(0.5));
  EXPECT_EQ(app_state(), State::Error);
  for (int k = 1; k <= 10; ++k) monitor_.run_active(component_, seconds_to_time(0.5 + 0.1 * k));
  EXPECT_EQ(app_state(), State::Normal) << "the door never opened: the real value is judged after the test";
  EXPECT_EQ(events_, (std::vector<std::string>{"EVT_X", "/EVT_X"}));
}

TEST_F(ShallowInjectionEnd, ARealSampleWrittenDuringTheInjectionIsTheValueRestored) {
  Signal* x = signal("x");
  ASSERT_TRUE(monitor_.add_filter(
      named("limit", "Threshold",
            {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}})));
  x->push(seconds_to_time(0.0), 1.0);
  monitor_.run_active(component_, seconds_to_time(0.0));
  ASSERT_TRUE(monitor_.inject_shallow("limit", {{50}}));
  x->push(seconds_to_time(0.1), 20.0);  // replaced by the injection in this run
  monitor_.run_active(component_, seconds_to_time(0.1));
  EXPECT_EQ(app_state(), State::Error);
  monitor_.run_active(component_, seconds_to_time(0.2));
  EXPECT_EQ(app_state(), State::Error) << "reality is 20, above the limit: the fault stays";
  ASSERT_FALSE(values_.empty());
  EXPECT_EQ(events_, (std::vector<std::string>{"EVT_X"}));
}

TEST_F(ShallowInjectionEnd, ASignalWithoutAnyRealSampleHasNothingToRestore) {
  signal("x");
  ASSERT_TRUE(monitor_.add_filter(
      named("limit", "Threshold",
            {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}})));
  ASSERT_TRUE(monitor_.inject_shallow("limit", {{50}}));
  monitor_.run_active(component_, seconds_to_time(0.1));
  monitor_.run_active(component_, seconds_to_time(0.2));
  EXPECT_EQ(app_state(), State::Error) << "no real value to judge: the injected one is held";
}

}  // namespace
}  // namespace safecass::test
