// DESIGN §2.6 across processes: remote provided interfaces, full-state updates (apply_remote) and
// the path-vector rule. Two coordinators in one test stand for two processes; `sync` plays the
// middleware (service_roots() on the provider, apply_remote() on the client).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

using test::Gcm;
using test::must;

using test::E;
using test::N;
using test::W;

/// The events every "process" of these tests defines (events are system-wide names).
void define_events(Gcm& g) {
  g.pair("EVT_FORCE_ERROR", 50, E);
  g.pair("EVT_FORCE_WARNING", 20, W);
}

/// Robot in one process: JR3 provides ForceData, CONTROL requires it and provides Command, SERVO
/// requires Command.
struct InProcess : Gcm {
  InProcess() {
    component("JR3", {"ForceData"}, {});
    component("CONTROL", {"Command"}, {"ForceData"});
    component("SERVO", {}, {"Command"});
    define_events(*this);
    connect("CONTROL.ForceData", "JR3.ForceData");
    connect("SERVO.Command", "CONTROL.Command");
  }
};

/// The same robot split: JR3 in `sensor`, CONTROL and SERVO in `robot`.
struct Split {
  Gcm sensor;
  Gcm robot;
  MachineId proxy = kNoMachine;
  Split(State propagate = E) {
    sensor.component("JR3", {"ForceData"}, {});
    define_events(sensor);
    if (propagate == W) {
      ServiceDependency d;
      d.propagate = W;
      must(sensor.co.set_service(sensor.comp("JR3"), "ForceData", d), "set_service");
    }
    robot.component("CONTROL", {"Command"}, {"ForceData"});
    robot.component("SERVO", {}, {"Command"});
    define_events(robot);
    proxy = must(robot.co.add_remote_provided("JR3.ForceData", propagate), "add_remote_provided");
    robot.connect("CONTROL.ForceData", "JR3.ForceData");
    robot.connect("SERVO.Command", "CONTROL.Command");
  }
  RemoteApplyResult sync() {
    return must(robot.co.apply_remote(proxy, sensor.co.service_roots(sensor.comp("JR3"), 0)), "apply_remote");
  }
};

std::vector<std::string> lines(const Coordinator& co, std::string_view address) {
  std::vector<std::string> out;
  for (const Explanation& e : must(explain(co, address), "explain")) {
    out.push_back(e.machine + " " + e.event + " " + std::string(to_string(e.level)) + " <- " + e.root.origin + ":" +
                  e.root.event);
    for (const std::string& hop : e.path) out.back() += " / " + hop;
  }
  return out;
}

TEST(RemoteProvider, RemoteRootReachesTheClientWithTheSameStatesAsInProcess) {
  InProcess one;
  Split two;
  one.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(two.robot.at("CONTROL.s_R.ForceData"), N) << "nothing crosses before the update arrives";
  const RemoteApplyResult r = two.sync();
  EXPECT_EQ(r.added, 1u);
  for (const char* a : {"CONTROL.s_R.ForceData", "CONTROL", "CONTROL.s_S.Command", "SERVO.s_R.Command", "SERVO"}) {
    EXPECT_EQ(two.robot.at(a), one.at(a)) << a;
  }
  EXPECT_EQ(two.robot.outstanding("CONTROL.s_R.ForceData"), "EVT_SERVICE_FAILURE");
}

TEST(RemoteProvider, ExplainGivesTheSameRootCauseAndHopPathAsInProcess) {
  InProcess one;
  Split two;
  two.sensor.clock.set(one.clock.now());
  one.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  for (const char* a : {"CONTROL.s_R.ForceData", "SERVO.s_R.Command", "SERVO"}) {
    EXPECT_EQ(lines(two.robot.co, a), lines(one.co, a)) << a;
  }
}

TEST(RemoteProvider, AnUpdateWithoutTheRootClearsEveryMirror) {
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  ASSERT_EQ(two.robot.at("SERVO"), E);
  two.sensor.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  const RemoteApplyResult r = two.sync();
  EXPECT_EQ(r.removed, 1u);
  for (const char* a : {"JR3.s_P.ForceData", "CONTROL.s_R.ForceData", "CONTROL", "SERVO"}) {
    EXPECT_EQ(two.robot.at(a), N) << a;
  }
  EXPECT_EQ(two.robot.mirrors("SERVO.s_R.Command"), 0u);
}

TEST(RemoteProvider, ARepeatedFullStateUpdateChangesNothing) {
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  const auto before = two.robot.history("CONTROL.s_R.ForceData").size();
  const RemoteApplyResult r = two.sync();
  EXPECT_EQ(r.kept, 1u);
  EXPECT_EQ(r.added + r.removed, 0u);
  EXPECT_EQ(two.robot.history("CONTROL.s_R.ForceData").size(), before);
}

TEST(RemoteProvider, WarningsCrossOnlyAServiceThatPropagatesWarnings) {
  Split errors_only(E);
  errors_only.sensor.gen("EVT_FORCE_WARNING", "JR3.s_A");
  errors_only.sync();
  EXPECT_EQ(errors_only.robot.at("JR3.s_P.ForceData"), W) << "the stand-in holds what the provider reports";
  EXPECT_EQ(errors_only.robot.at("CONTROL.s_R.ForceData"), N);

  Split warnings(W);
  warnings.sensor.gen("EVT_FORCE_WARNING", "JR3.s_A");
  warnings.sync();
  EXPECT_EQ(warnings.robot.at("CONTROL.s_R.ForceData"), W);
  EXPECT_EQ(warnings.robot.outstanding("CONTROL.s_R.ForceData"), "EVT_SERVICE_DEGRADED");
}

/// A root without a sample.
ResolvedRoot root_at(std::string event, std::string origin, Time time) {
  ResolvedRoot r;
  r.event = std::move(event);
  r.origin = std::move(origin);
  r.time = time;
  return r;
}

TEST(RemoteProvider, AnUpdateNamingAnUnknownEventIsRefusedAndChangesNothing) {
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  std::vector<RemoteRoot> bad = two.sensor.co.service_roots(two.sensor.comp("JR3"), 0);
  bad.push_back(RemoteRoot{root_at("EVT_NO_SUCH_THING", "JR3.s_A", Time{5}), E, {"JR3.s_A"}});
  bad.front().root.event = "EVT_FORCE_ERROR";
  auto r = two.robot.co.apply_remote(two.proxy, bad);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("EVT_NO_SUCH_THING"), std::string::npos) << r.error().message;
  EXPECT_EQ(two.robot.at("CONTROL.s_R.ForceData"), E) << "the previous state is kept";
}

TEST(RemoteProvider, AnUpdateWithACompletionLevelNormalOrNoOriginIsRefused) {
  Split two;
  RemoteRoot completion{root_at("/EVT_FORCE_ERROR", "JR3.s_A", Time{1}), E, {}};
  RemoteRoot normal{root_at("EVT_FORCE_ERROR", "JR3.s_A", Time{1}), N, {}};
  RemoteRoot nowhere{root_at("EVT_FORCE_ERROR", "", Time{1}), E, {}};
  for (const RemoteRoot& r : {completion, normal, nowhere}) {
    EXPECT_FALSE(two.robot.co.apply_remote(two.proxy, {r}));
  }
  EXPECT_FALSE(two.robot.co.apply_remote(two.proxy, {nowhere, nowhere}));
  EXPECT_FALSE(two.robot.co.apply_remote(two.robot.machine("CONTROL.s_P.Command"), {}))
      << "a local provided interface is not a remote one";
  EXPECT_EQ(two.robot.at("SYSTEM"), N);
}

TEST(RemoteProvider, ResetDoesNotClearARootThatIsStillActiveInItsProcess) {
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  two.robot.reset("SYSTEM");
  EXPECT_EQ(two.robot.at("CONTROL.s_R.ForceData"), E);
  two.robot.reset("JR3");
  EXPECT_EQ(two.robot.at("JR3.s_P.ForceData"), E);
}

TEST(RemoteProvider, RemoteComponentsAreLeftOutOfTheCoordinatorState) {
  Split two;
  two.sensor.gen("EVT_FORCE_WARNING", "JR3.s_A");
  two.sync();
  EXPECT_TRUE(two.robot.co.structure().is_remote(two.robot.comp("JR3")));
  EXPECT_FALSE(two.robot.co.structure().is_remote(two.robot.comp("CONTROL")));
  EXPECT_EQ(two.robot.at("JR3"), W);
  EXPECT_EQ(two.robot.at("SYSTEM"), N);
}

TEST(RemoteProvider, ALocalComponentCannotBeDeclaredRemote) {
  Split two;
  auto r = two.robot.co.add_remote_provided("CONTROL.Command");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Duplicate);
  EXPECT_FALSE(two.robot.co.add_remote_provided("JR3.ForceData")) << "declared twice";
  EXPECT_FALSE(two.robot.co.add_remote_provided("JR3"));
  EXPECT_FALSE(two.robot.co.add_remote_provided("JR3.Other", N));
}

TEST(RemoteProvider, RootOriginNamesTheMachineInTheProvidersProcess) {
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  const auto c = two.robot.co.conditions(two.robot.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(two.robot.co.resolve_root(c[0].root).origin, "JR3.s_A");
}

TEST(RemoteProvider, FilterDataOfTheRootCrossesWithIt) {
  Split two;
  SampleCause cause;
  cause.filter = two.sensor.co.intern("force_limit");
  cause.signal = two.sensor.co.intern("JR3.ForceNorm");
  cause.value = 42.5;
  two.sensor.co.generate(two.sensor.id("EVT_FORCE_ERROR"), two.sensor.machine("JR3.s_A"), cause);
  two.sync();
  const auto why = must(explain(two.robot.co, "CONTROL.s_R.ForceData"), "explain");
  ASSERT_EQ(why.size(), 1u);
  EXPECT_EQ(why[0].root.filter, "force_limit");
  EXPECT_EQ(why[0].root.signal, "JR3.ForceNorm");
  EXPECT_DOUBLE_EQ(why[0].root.value, 42.5);
}

/// Two processes whose connections form a cycle: A.in -> B.out (remote in A), B.in -> A.out
/// (remote in B).
struct Cycle {
  Gcm a, b;
  MachineId b_in_a = kNoMachine, a_in_b = kNoMachine;
  Cycle() {
    for (Gcm* g : {&a, &b}) g->pair("EVT_ROOT", 50, E);
    a.component("A", {"out"}, {"in"});
    b.component("B", {"out"}, {"in"});
    b_in_a = must(a.co.add_remote_provided("B.out"), "remote B.out");
    a_in_b = must(b.co.add_remote_provided("A.out"), "remote A.out");
    a.connect("A.in", "B.out");
    b.connect("B.in", "A.out");
  }
  /// Delivers updates both ways until nothing changes; returns the number of rounds.
  int settle() {
    for (int round = 1; round <= 20; ++round) {
      const auto to_b = must(b.co.apply_remote(a_in_b, a.co.service_roots(a.comp("A"), 0)), "to b");
      const auto to_a = must(a.co.apply_remote(b_in_a, b.co.service_roots(b.comp("B"), 0)), "to a");
      if (to_b.added + to_b.removed + to_a.added + to_a.removed == 0) return round;
    }
    return -1;
  }
};

TEST(RemoteProvider, ARootGoesAroundACycleOfProcessesOnceAsInProcess) {
  Cycle c;
  c.a.gen("EVT_ROOT", "A.s_A");
  ASSERT_GT(c.settle(), 0);
  EXPECT_EQ(c.b.at("B.s_R.in"), E);
  EXPECT_EQ(c.a.at("A.s_R.in"), E) << "in one process the root reaches A.s_R.in around the cycle too";
  EXPECT_EQ(c.b.mirrors("B.s_R.in"), 1u);
  EXPECT_EQ(c.a.mirrors("A.s_R.in"), 1u);
}

TEST(RemoteProvider, ARootThatClearsClearsEverywhereAroundACycleOfProcesses) {
  Cycle c;
  c.a.gen("EVT_ROOT", "A.s_A");
  ASSERT_GT(c.settle(), 0);
  c.a.gen("/EVT_ROOT", "A.s_A");
  ASSERT_GT(c.settle(), 0) << "the updates converge";
  for (const char* m : {"A.s_R.in", "A.s_P.out"}) EXPECT_EQ(c.a.at(m), N) << m;
  EXPECT_EQ(c.b.at("B.s_R.in"), N);
  EXPECT_EQ(c.a.at("SYSTEM"), N);
  EXPECT_EQ(c.b.at("SYSTEM"), N);
}

TEST(RemoteProvider, ARootWhosePathContainsTheReceivingMachineIsDropped) {
  Split two;
  RemoteRoot looped{root_at("EVT_FORCE_ERROR", "X.s_A", Time{1}),
                    E,
                    {"X.s_A", "X.s_S.out", "CONTROL.s_R.ForceData", "CONTROL.s_S.Command", "JR3.s_R.in"}};
  const auto r = must(two.robot.co.apply_remote(two.proxy, {looped}), "apply_remote");
  EXPECT_EQ(r.dropped, 1u);
  EXPECT_EQ(two.robot.at("CONTROL.s_R.ForceData"), N);
  EXPECT_EQ(two.robot.at("JR3.s_P.ForceData"), N);
}

TEST(RemoteProvider, AHistoryRecordKeepsTheRootCauseItWasMadeWithAfterItsRemoteSlotIsReused) {
  // Finding: the client's history named the root of a later fault, because records kept only
  // the index of a remote root's slot, which the next remote root reused.
  Split two;
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  two.sensor.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  two.sync();
  two.sensor.gen("EVT_FORCE_WARNING", "JR3.s_P.ForceData");
  two.sensor.gen("EVT_FORCE_ERROR", "JR3.s_P.ForceData");
  two.sync();
  std::vector<std::string> causes;
  for (const Record& r : two.robot.co.history(two.robot.machine("CONTROL.s_R.ForceData"))) {
    if (r.kind != RecordKind::Transition) continue;
    causes.push_back(std::string(to_string(r.to)) + " <- " + two.robot.co.resolve_root(r.root).origin + ":" +
                     two.robot.co.structure().event(r.root.event).name);
  }
  EXPECT_EQ(causes, (std::vector<std::string>{"Error <- JR3.s_A:EVT_FORCE_ERROR", "Normal <- JR3.s_A:EVT_FORCE_ERROR",
                                              "Error <- JR3.s_P.ForceData:EVT_FORCE_ERROR"}));
}

}  // namespace
}  // namespace safecass
