// Good specifications load without errors and instantiate into a working coordinator + monitor.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "safecass/core/clock.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

constexpr const char* kRobodoc = "tests/data/good_specs/robodoc.json";
constexpr const char* kLegacy = "tests/data/good_specs/legacy_2016/system.json";

const ComponentSpec& find(const SystemSpec& s, const std::string& name) {
  for (const ComponentSpec& c : s.components) {
    if (c.name == name) return c;
  }
  throw std::runtime_error("no component " + name);
}

TEST(GoodSpecs, RobodocLoadsWithoutAnyDiagnostic) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  EXPECT_EQ(formatted(r), "");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.system);
  const SystemSpec& s = *r.system;
  EXPECT_EQ(s.name, "robodoc");
  EXPECT_EQ(s.path, kRobodoc);
  ASSERT_EQ(s.components.size(), 3u);
  EXPECT_EQ(s.components[0].name, "JR3");
  EXPECT_EQ(s.components[0].file, "tests/data/good_specs/jr3.json");
  EXPECT_EQ(s.components[1].file, "tests/data/good_specs/parts/control.json");
  EXPECT_EQ(s.components[2].file, kRobodoc);
  EXPECT_EQ(s.components[0].where.line, 3);
  ASSERT_EQ(s.connections.size(), 2u);
  EXPECT_EQ(s.connections[0].required, "CONTROL.ForceData");
  EXPECT_EQ(s.connections[0].provided, "JR3.ForceData");
  ASSERT_EQ(s.coordinators.size(), 2u);
  EXPECT_EQ(s.coordinators[0].first, "robot");
  EXPECT_THAT(s.coordinators[0].second, ::testing::ElementsAre("JR3", "CONTROL"));
  EXPECT_EQ(s.coordinators[1].first, "drive");
}

TEST(GoodSpecs, ComponentModelHoldsWhatTheFilesSay) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  ASSERT_TRUE(r.system);
  const ComponentSpec& jr3 = find(*r.system, "JR3");
  ASSERT_TRUE(jr3.period);
  EXPECT_DOUBLE_EQ(*jr3.period, 0.001);
  EXPECT_THAT(jr3.provided, ::testing::ElementsAre("ForceData"));
  ASSERT_EQ(jr3.signals.size(), 2u);
  EXPECT_EQ(jr3.signals[0].name, "JR3.Force");
  EXPECT_EQ(jr3.signals[0].size, 3u);
  EXPECT_EQ(jr3.signals[1].name, "JR3.Heartbeat");
  EXPECT_EQ(jr3.signals[1].size, 1u);
  ASSERT_EQ(jr3.events.size(), 5u);
  EXPECT_TRUE(jr3.events[4].latched);
  EXPECT_EQ(jr3.events[4].hazard, "H-4");
  ASSERT_EQ(jr3.filters.size(), 5u);
  EXPECT_EQ(jr3.filters[1].stages[0].name, "force_limit");
  EXPECT_EQ(jr3.filters[1].stages[0].type, "Threshold");
  EXPECT_EQ(jr3.filters[2].stages[0].detection, DetectionMode::Level);
  EXPECT_EQ(jr3.filters[4].stages[0].execution, ExecutionMode::Passive);
  EXPECT_EQ(jr3.filters[4].stages[0].target.kind, MachineKind::Framework);
  EXPECT_EQ(jr3.filters[4].stages[0].target.component, "JR3");
  // The pipeline: unnamed stages are called <pipeline>.<k>; stages are wired output to input.
  const FilterSpec& spike = jr3.filters[3];
  EXPECT_EQ(spike.pipeline, "force_spike");
  ASSERT_EQ(spike.stages.size(), 3u);
  EXPECT_EQ(spike.stages[0].name, "force_spike.1");
  EXPECT_EQ(spike.stages[2].name, "force_spike.3");
  EXPECT_EQ(std::get<std::string>(spike.stages[1].params.at("input_signal")), "JR3.force_spike_1");
  EXPECT_EQ(std::get<std::string>(spike.stages[2].params.at("input_signal")), "JR3.force_spike_2");
  EXPECT_EQ(spike.where.file, "tests/data/good_specs/jr3.json");
  ASSERT_EQ(jr3.services.size(), 1u);
  EXPECT_TRUE(jr3.services[0].dependency.framework);
  EXPECT_FALSE(jr3.services[0].dependency.all_required);

  const ComponentSpec& control = find(*r.system, "CONTROL");
  ASSERT_EQ(control.services.size(), 1u);
  EXPECT_EQ(control.services[0].dependency.propagate, State::Warning);
  EXPECT_THAT(control.services[0].dependency.required, ::testing::ElementsAre("ForceData"));
  EXPECT_EQ(control.filters[0].stages[1].type, "Threshold");  // "FilterThreshold", the 2016 name
}

TEST(GoodSpecs, RobodocInstantiatesEveryComponentMachineAndFilter) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  ASSERT_TRUE(r.system);
  SimulatedClock clock;
  Coordinator co("robodoc", &clock);
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor);
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(co.structure().component_count(), 3u);
  EXPECT_EQ(co.structure().machine_count(), 10u);  // JR3: F, A, P; CONTROL: F, A, P, R; SERVO: F, A, R
  EXPECT_EQ(co.structure().event_count(), framework_event::kCount + 9);
  EXPECT_EQ(co.structure().connections().size(), 2u);
  EXPECT_EQ(monitor.filters().size(), 10u);
  for (const char* name : {"force_norm", "force_limit", "force_warn", "force_spike.1", "force_spike.2", "force_spike.3",
                           "heartbeat", "tracking.1", "tracking.2", "servo_duty"}) {
    EXPECT_NE(monitor.find_filter(name), nullptr) << name;
  }
  EXPECT_NE(monitor.signals().find("JR3.ForceNorm"), nullptr);
  EXPECT_EQ(monitor.signals().find("JR3.Force")->size(), 3u);
  EXPECT_EQ(monitor.find_filter("heartbeat")->execution(), ExecutionMode::Passive);
}

TEST(GoodSpecs, InstantiatedSystemDetectsAndPropagatesAForceError) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  ASSERT_TRUE(r.system);
  SimulatedClock clock;
  Coordinator co("robodoc", &clock);
  Monitor monitor(co, builtin_registry());
  ASSERT_TRUE(instantiate(*r.system, co, monitor));
  const ComponentId jr3 = *co.structure().find_component("JR3");
  const double force[3] = {0.0, 0.0, 35.0};
  monitor.signals().find("JR3.Force")->push(clock.now(), force);
  monitor.run_active(jr3, clock.now());
  EXPECT_EQ(co.state(*co.structure().find_machine("JR3.s_A")), State::Error);
  EXPECT_EQ(co.state(*co.structure().find_machine("CONTROL.s_R.ForceData")), State::Error);
  // CONTROL's Command service passes warnings and errors on to SERVO.
  EXPECT_EQ(co.state(*co.structure().find_machine("SERVO.s_R.Command")), State::Error);
}

TEST(GoodSpecs, OnlyOneCoordinatorsComponentsAreInstantiated) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  ASSERT_TRUE(r.system);
  SimulatedClock clock;
  Coordinator co("drive", &clock);
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor, "drive");
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(co.structure().component_count(), 1u);
  EXPECT_EQ(co.structure().machine_count(), 3u);
  EXPECT_TRUE(co.structure().connections().empty());  // SERVO.Command's provider runs elsewhere
  EXPECT_EQ(monitor.filters().size(), 1u);
  EXPECT_TRUE(co.structure().find_event("EVT_FORCE_ERROR"));  // events are system-wide

  Coordinator robot("robot", &clock);
  Monitor robot_monitor(robot, builtin_registry());
  ASSERT_TRUE(instantiate(*r.system, robot, robot_monitor, "robot"));
  EXPECT_EQ(robot.structure().component_count(), 2u);
  EXPECT_EQ(robot.structure().connections().size(), 1u);
  EXPECT_EQ(robot_monitor.filters().size(), 9u);
}

TEST(GoodSpecs, UnknownCoordinatorIsNotFound) {
  const LoadResult r = load_system(kRobodoc, builtin_registry());
  ASSERT_TRUE(r.system);
  Coordinator co("x");
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor, "arm");
  ASSERT_FALSE(made);
  EXPECT_EQ(made.error().code, ErrorCode::NotFound);
  EXPECT_EQ(made.error().message, "system 'robodoc' has no coordinator 'arm' (known: robot, drive)");
}

TEST(GoodSpecs, A2016ComponentFileLoadsUnchanged) {
  const LoadResult r = load_system("tests/data/good_specs/legacy_2016/jr3.json", builtin_registry());
  EXPECT_EQ(r.errors(), 0u) << formatted(r);
  ASSERT_TRUE(r.system);
  // A single component file is a system of that one component.
  EXPECT_EQ(r.system->name, "JR3");
  ASSERT_EQ(r.system->components.size(), 1u);
  const ComponentSpec& jr3 = r.system->components[0];
  EXPECT_THAT(jr3.provided, ::testing::ElementsAre("JR3Interface"));  // implied by the service
  ASSERT_EQ(jr3.filters.size(), 2u);
  EXPECT_EQ(jr3.filters[0].stages[0].type, "OnOff");
  EXPECT_EQ(jr3.filters[0].stages[0].name, "JR3.OnOff_1");
  EXPECT_EQ(jr3.filters[1].stages[0].target.kind, MachineKind::Framework);
  // Signals are implied (as scalars), with a warning each.
  ASSERT_EQ(jr3.signals.size(), 2u);
  EXPECT_EQ(jr3.signals[0].name, "JR3.WarningBits");
  EXPECT_EQ(r.warnings(), 2u) << formatted(r);
}

TEST(GoodSpecs, A2016SystemInstantiatesAndPropagates) {
  const LoadResult r = load_system(kLegacy, builtin_registry());
  EXPECT_EQ(formatted(r),
            "tests/data/good_specs/legacy_2016/jr3.json:30:34: warning: signal 'JR3.WarningBits' is not declared; "
            "assumed to be a scalar (component 'JR3' has no \"signals\" list, as in 2016 files) "
            "[/filter/0/argument/input_signal]\n"
            "tests/data/good_specs/legacy_2016/jr3.json:39:34: warning: signal 'JR3.DeviceError' is not declared; "
            "assumed to be a scalar (component 'JR3' has no \"signals\" list, as in 2016 files) "
            "[/filter/1/argument/input_signal]\n");
  ASSERT_TRUE(r.system);
  SimulatedClock clock;
  Coordinator co("legacy", &clock);
  Monitor monitor(co, builtin_registry());
  const auto made = instantiate(*r.system, co, monitor);
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(co.structure().machine_count(), 2u + 1u + 2u + 2u);  // JR3: F, A, P; Control: F, A, P, R
  const ComponentId jr3 = *co.structure().find_component("JR3");
  monitor.signals().find("JR3.DeviceError")->push(clock.now(), 1.0);
  monitor.run_active(jr3, clock.now());
  EXPECT_EQ(co.state(*co.structure().find_machine("JR3.s_F")), State::Error);
  EXPECT_EQ(co.state(*co.structure().find_machine("Control.s_R.ReadSensorValue")), State::Error);
  monitor.signals().find("JR3.DeviceError")->push(clock.now(), 0.0);
  monitor.run_active(jr3, clock.now());
  EXPECT_EQ(co.state(*co.structure().find_machine("Control.s_R.ReadSensorValue")), State::Normal);
}

TEST(GoodSpecs, ProvidedInterfaceWithoutServiceEntryGetsTheConservativeDefault) {
  const LoadResult r = load_text(R"({"component": "A", "interfaces": {"provided": ["P", "Q"], "required": ["R"]},
    "service": [{"name": "Q", "dependency": {}}]})");
  ASSERT_TRUE(r.system) << formatted(r);
  const auto& services = r.system->components[0].services;
  ASSERT_EQ(services.size(), 2u);
  EXPECT_EQ(services[0].provided, "Q");
  EXPECT_FALSE(services[0].dependency.framework);
  EXPECT_FALSE(services[0].dependency.application);
  EXPECT_FALSE(services[0].dependency.all_required);
  EXPECT_EQ(services[1].provided, "P");
  EXPECT_TRUE(services[1].dependency.framework);
  EXPECT_TRUE(services[1].dependency.all_required);
}

}  // namespace
}  // namespace safecass::spec
