// The 2016 SAFECASS files load unchanged (docs/spec-format.md §4): the framework filter
// template, the keys and values the 2016 loader accepted, its class names and arguments.
// The files in tests/data/good_specs/original_2016/ were written for these tests in that format.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "safecass/core/clock.hpp"
#include "safecass/core/named.hpp"
#include "spec_commands.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

using ::testing::HasSubstr;

constexpr const char* kDir = "tests/data/good_specs/original_2016/";

const ComponentSpec& component(const SystemSpec& s, const std::string& name) {
  for (const ComponentSpec& c : s.components) {
    if (c.name == name) return c;
  }
  throw std::runtime_error("no component " + name);
}

const FilterConfig& filter(const ComponentSpec& c, const std::string& name) {
  for (const FilterSpec& f : c.filters) {
    for (const FilterConfig& stage : f.stages) {
      if (stage.name == name) return stage;
    }
  }
  throw std::runtime_error("no filter " + name);
}

std::string notes(const LoadResult& r) {
  std::string out;
  for (const Diagnostic& d : r.notes) out += format(d) + "\n";
  return out;
}

TEST(Original2016, TheFrameworkFilterTemplateLoadsAloneAndItsRepeatedFrameworkEventsAreNotes) {
  const LoadResult r = load_system(std::string(kDir) + "framework_filters.json", builtin_registry());
  EXPECT_EQ(formatted(r), "") << "a 2016 template loads without error or warning";
  ASSERT_TRUE(r.system);
  EXPECT_TRUE(r.system->components.empty()) << "a template is not a component";
  EXPECT_THAT(notes(r), HasSubstr("framework_filters.json:8:19: note: event 'EVT_THREAD_EXCEPTION' redefines the "
                                  "framework event as it is (severity 210"));
  EXPECT_THAT(notes(r), HasSubstr("event 'EVT_SERVICE_FAILURE' redefines the framework event as it is"));
  EXPECT_THAT(notes(r), HasSubstr("'debug' is accepted for the 2016 files and ignored"));
  EXPECT_THAT(notes(r), HasSubstr("'last_filter' is accepted for the 2016 files and ignored"));
}

TEST(Original2016, TheFrameworkFilterTemplateIsInstantiatedForEveryComponentOfTheSystem) {
  const LoadResult r = load_system(std::string(kDir) + "system.json", builtin_registry());
  ASSERT_EQ(r.errors(), 0u) << formatted(r);
  ASSERT_TRUE(r.system);
  ASSERT_EQ(r.system->components.size(), 2u) << "Arm and Gripper; the template is not a component";
  for (const char* name : {"Arm", "Gripper"}) {
    const ComponentSpec& c = component(*r.system, name);
    const FilterConfig& f = filter(c, std::string(name) + ".framework.OnOff_1");
    EXPECT_EQ(f.target.kind, MachineKind::Framework);
    EXPECT_EQ(f.target.component, name) << "\"component\": \"\" is the component it is applied to";
    EXPECT_EQ(std::get<std::string>(f.params.at("input_signal")), "ExceptionCount");
  }
  EXPECT_THAT(formatted(r), ::testing::Not(HasSubstr("ExceptionCount"))) << "a framework signal needs no declaration";

  SimulatedClock clock;
  Coordinator co("arm_2016", &clock);
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor);
  ASSERT_TRUE(made) << made.error().message;
  const ComponentId arm = *co.structure().find_component("Arm");
  Signal* exceptions = monitor.signals().find("Arm.ExceptionCount");
  ASSERT_NE(exceptions, nullptr);
  exceptions->push(clock.now(), 1.0);
  monitor.run_active(arm, clock.now());
  EXPECT_EQ(co.state(*co.structure().find_machine("Arm.s_F")), State::Error);
  EXPECT_EQ(co.state(*co.structure().find_machine("Gripper.s_R.ArmMotion")), State::Error)
      << "the exception fails Arm's service";
  EXPECT_EQ(co.snapshot(*co.structure().find_machine("Arm.s_F")).outstanding,
            *co.structure().find_event("EVT_THREAD_EXCEPTION"));
  exceptions->push(clock.now(), 0.0);
  monitor.run_active(arm, clock.now());
  EXPECT_EQ(co.state(*co.structure().find_machine("Gripper.s_R.ArmMotion")), State::Normal);
}

TEST(Original2016, TheKeysAndValuesTheOriginalAcceptedLoad) {
  const LoadResult r = load_system(std::string(kDir) + "arm.json", builtin_registry());
  ASSERT_EQ(r.errors(), 0u) << formatted(r);
  ASSERT_TRUE(r.system);
  const ComponentSpec& arm = component(*r.system, "Arm");
  EXPECT_EQ(filter(arm, "arm_speed").execution, ExecutionMode::Active) << "\"active\"";
  EXPECT_EQ(filter(arm, "arm_step").execution, ExecutionMode::Active) << "\"INTERNAL\": runs in the component";
  EXPECT_EQ(filter(arm, "arm_too_fast").execution, ExecutionMode::Passive) << "\"passive\"";
  EXPECT_EQ(filter(arm, "arm_too_fast").detection, DetectionMode::Level) << "\"level\"";
  EXPECT_EQ(filter(arm, "arm_mode").detection, DetectionMode::Edge) << "\"edge\"";
  EXPECT_THAT(
      notes(r),
      HasSubstr("arm.json:19:13: note: filter 'arm_speed': 'debug' is accepted for the 2016 files and ignored"));
  EXPECT_THAT(notes(r),
              HasSubstr("note: filter 'arm_too_fast': 'last_filter' is accepted for the 2016 files and ignored"));
  for (const Diagnostic& d : r.diagnostics) {
    EXPECT_THAT(d.message, HasSubstr("is not declared; assumed to be a scalar")) << format(d);
  }
}

TEST(Original2016, TheOriginalClassNamesAndArgumentsLoadAsTheirBuiltins) {
  const LoadResult r = load_system(std::string(kDir) + "arm.json", builtin_registry());
  ASSERT_TRUE(r.system) << formatted(r);
  const ComponentSpec& arm = component(*r.system, "Arm");
  EXPECT_EQ(filter(arm, "arm_speed").type, "Derivative") << "FilterTrendVel";
  EXPECT_EQ(filter(arm, "arm_step").type, "Derivative") << "TrendVel";
  EXPECT_EQ(std::get<std::string>(filter(arm, "arm_speed").params.at("output_signal")), "Arm.arm_speed")
      << "a 2016 transform names its own output: the signal named after the filter";
  EXPECT_EQ(std::get<std::string>(filter(arm, "arm_mode").params.at("event_onset")), "EVT_ARM_MODE")
      << "ChangeDetection's 2016 'event' is its onset";
  EXPECT_EQ(filter(arm, "arm_brake").type, "Bypass");
  for (const char* name : {"arm_mean", "arm_offset", "arm_vector", "arm_norm"}) {
    EXPECT_TRUE(filter(arm, name).params.count("output_signal") > 0) << name << " needs no more than an input";
  }

  SimulatedClock clock;
  Coordinator co("arm", &clock);
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor);
  ASSERT_TRUE(made) << made.error().message;
  const ComponentId id = *co.structure().find_component("Arm");
  Signal* angle = monitor.signals().find("Arm.JointAngle");
  angle->push(seconds_to_time(0.0), 1.0);
  monitor.run_active(id, seconds_to_time(0.0));
  angle->push(seconds_to_time(0.5), 3.0);
  monitor.run_active(id, seconds_to_time(0.5));
  Time t{};
  double v = 0;
  ASSERT_TRUE(monitor.signals().find("Arm.arm_speed")->latest(t, &v));
  EXPECT_DOUBLE_EQ(v, 4.0) << "time_scaling: true divides by the 0.5 s between the samples";
  ASSERT_TRUE(monitor.signals().find("Arm.arm_step")->latest(t, &v));
  EXPECT_DOUBLE_EQ(v, 2.0) << "time_scaling: false is the difference alone";
  // Bypass with event_on/event_off reports a non-zero input, as the 2016 Bypass did.
  monitor.signals().find("Arm.BrakeFault")->push(seconds_to_time(0.6), 1.0);
  monitor.run_active(id, seconds_to_time(0.6));
  EXPECT_EQ(co.snapshot(*co.structure().find_machine("Arm.s_A")).outstanding,
            *co.structure().find_event("EVT_ARM_BRAKE"));
  // ChangeDetection's 'event'.
  monitor.signals().find("Arm.Mode")->push(seconds_to_time(0.7), 1.0);
  monitor.run_active(id, seconds_to_time(0.7));
  monitor.signals().find("Arm.Mode")->push(seconds_to_time(0.8), 2.0);
  monitor.run_active(id, seconds_to_time(0.8));
  const auto why = explain(co, "Arm.s_A");
  ASSERT_TRUE(why);
  bool mode = false;
  for (const Explanation& e : *why) mode = mode || e.root.event == "EVT_ARM_MODE";
  EXPECT_TRUE(mode);
}

TEST(Original2016, ValidateVerbosePrintsTheNotesAndCountsThemAsNothing) {
  ::testing::internal::CaptureStdout();
  const int code = run_validate({std::string(kDir) + "framework_filters.json"}, false, true);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
  EXPECT_THAT(out, HasSubstr("note: filter: 'debug' is accepted for the 2016 files and ignored"));
  EXPECT_THAT(out, HasSubstr("0 errors, 0 warnings\n"));
  ::testing::internal::CaptureStdout();
  run_validate({std::string(kDir) + "framework_filters.json"}, false, false);
  EXPECT_THAT(::testing::internal::GetCapturedStdout(), ::testing::Not(HasSubstr("note:")))
      << "notes only with --verbose";
}

TEST(Original2016, ARedefinitionOfAFrameworkEventThatChangesItIsRefused) {
  const LoadResult r = load_text(R"({"component": "",
    "event": [ { "name": "EVT_THREAD_EXCEPTION", "severity": 100, "state_transition": [ "N2W" ] } ] })");
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(formatted(r), HasSubstr("event 'EVT_THREAD_EXCEPTION' redefines the framework event differently: "
                                      "its severity is 210, not 100"));
}

}  // namespace
}  // namespace safecass::spec
