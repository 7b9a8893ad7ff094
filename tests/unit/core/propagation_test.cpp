// DESIGN §2.6 (propagation of root causes along connections, explain) and §2.7 (broadcast and
// framework events).

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

using test::completion;
using test::Gcm;
using test::kFromError;
using test::kToError;
using test::onset;

using test::E;
using test::N;
using test::W;

/// The paper's example: JR3 provides ForceData, CONTROL requires it.
struct Robot : Gcm {
  explicit Robot(bool connected = true) {
    component("JR3", {"ForceData"}, {});
    component("CONTROL", {"Motion"}, {"ForceData"});
    event(onset("EVT_FORCE_ERROR", 50, kToError, false, "H-3"));
    event(completion("/EVT_FORCE_ERROR", 50, kFromError));
    pair("EVT_FORCE_WARNING", 20, W);
    pair("EVT_JR3_FAULT", 60, E);
    if (connected) connect("CONTROL.ForceData", "JR3.ForceData");
  }
};

/// Components named `names`, each providing "out" and requiring "in".
struct Net : Gcm {
  explicit Net(std::initializer_list<std::string_view> names) {
    for (std::string_view n : names) component(n, {"out"}, {"in"});
    pair("EVT_ROOT", 50, E);
    pair("EVT_OTHER", 70, E);
    pair("EVT_WARN", 20, W);
    pair("EVT_LATCH", 40, E, true);
  }
  void link(std::string_view client, std::string_view provider) {
    connect(std::string(client) + ".in", std::string(provider) + ".out");
  }
};

std::vector<std::string> path_of(const Gcm& g, std::string_view address, std::size_t index = 0) {
  const auto why = explain(g.co, address);
  if (!why || why->size() <= index) {
    ADD_FAILURE() << "no explanation " << index << " at " << address;
    return {};
  }
  return (*why)[index].path;
}

// ---- direction and the mirror ---------------------------------------------------------------------

TEST(Propagation, ErrorsFlowFromProviderToClient) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("JR3.s_S.ForceData"), E);
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  EXPECT_EQ(g.at("CONTROL"), E);
  EXPECT_EQ(g.at("CONTROL.s_A"), N);
  EXPECT_EQ(g.at("CONTROL.s_S.Motion"), E) << "by default Motion depends on every required interface";
}

TEST(Propagation, ErrorsNeverFlowFromClientToProvider) {
  Robot g;
  for (const char* source : {"CONTROL.s_A", "CONTROL.s_F", "CONTROL.s_R.ForceData", "CONTROL.s_P.Motion"}) {
    g.gen("EVT_JR3_FAULT", source);
    for (const char* a : {"JR3", "JR3.s_F", "JR3.s_A", "JR3.s_P.ForceData", "JR3.s_S.ForceData"}) {
      EXPECT_EQ(g.at(a), N) << a << " after a fault on " << source;
    }
  }
  EXPECT_EQ(g.at("CONTROL"), E);
}

TEST(Propagation, TheMirrorIsServiceFailureAtErrorAndKeepsTheRootCause) {
  Robot g;
  SampleCause cause;
  cause.filter = g.co.intern("force_limit");
  cause.signal = g.co.intern("JR3.ForceNorm");
  cause.value = 42.0;
  g.clock.set(seconds_to_time(1.5));
  g.co.generate(g.id("EVT_FORCE_ERROR"), g.machine("JR3.s_A"), cause);

  const auto conditions = g.co.conditions(g.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(conditions.size(), 1u);
  const Condition& m = conditions[0];
  EXPECT_TRUE(m.mirror);
  EXPECT_EQ(m.event, framework_event::kServiceFailure);
  EXPECT_EQ(g.co.structure().event(m.event).name, "EVT_SERVICE_FAILURE");
  EXPECT_EQ(m.severity, 220);
  EXPECT_EQ(m.level, E);
  EXPECT_EQ(m.via, ConnectionId{0});
  EXPECT_EQ(m.root.event, g.id("EVT_FORCE_ERROR"));
  EXPECT_EQ(m.root.origin, g.machine("JR3.s_A"));
  EXPECT_EQ(m.root.time, seconds_to_time(1.5));
  EXPECT_EQ(m.root.sample.filter, cause.filter);
  EXPECT_EQ(m.root.sample.signal, cause.signal);
  EXPECT_DOUBLE_EQ(m.root.sample.value, 42.0);
  EXPECT_EQ(g.outstanding("CONTROL.s_R.ForceData"), "EVT_SERVICE_FAILURE");
  EXPECT_EQ(g.component_outstanding("CONTROL"), "EVT_SERVICE_FAILURE");

  const auto records = g.event_records("CONTROL.s_R.ForceData");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_TRUE(records[0].mirror);
  EXPECT_EQ(records[0].outcome, Outcome::Raised);
  EXPECT_EQ(records[0].event, framework_event::kServiceFailure);
  EXPECT_EQ(records[0].root.event, g.id("EVT_FORCE_ERROR"));
  EXPECT_EQ(records[0].time, seconds_to_time(1.5));
}

TEST(Propagation, ClearingTheRootClearsTheMirrorAndRecordsItsCompletion) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL"), N);
  EXPECT_TRUE(g.co.conditions(g.machine("CONTROL.s_R.ForceData")).empty());
  const auto records = g.event_records("CONTROL.s_R.ForceData");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].outcome, Outcome::Cleared);
  EXPECT_EQ(records[1].event, g.id("/EVT_SERVICE_FAILURE"));
  EXPECT_TRUE(records[1].mirror);
}

TEST(Propagation, PropagationIsSynchronousCallbacksOfTheClientHaveFiredWhenGenerateReturns) {
  Robot g;
  std::vector<State> entered;
  g.co.on_component(g.comp("CONTROL"), StateCallbacks{{}, {}, [&](State s) { entered.push_back(s); }});
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(entered, std::vector<State>{E});
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(entered, (std::vector<State>{E, N}));
}

TEST(Propagation, AMirrorIsClearedOnlyByItsRootNeverByACompletionOnTheClient) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("/EVT_SERVICE_FAILURE", "CONTROL.s_R.ForceData");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E) << "the provider's fault is still present";
  const auto records = g.event_records("CONTROL.s_R.ForceData");
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records.back().outcome, Outcome::Ignored);
  EXPECT_EQ(records.back().text, "not active");
}

TEST(Propagation, ARefreshOfTheRootStaysAtTheRoot) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  const std::size_t client_records = g.history("CONTROL.s_R.ForceData").size();
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.co.conditions(g.machine("JR3.s_A"))[0].count, 3u);
  const auto mirror = g.co.conditions(g.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(mirror.size(), 1u);
  EXPECT_EQ(mirror[0].count, 1u);
  EXPECT_EQ(g.history("CONTROL.s_R.ForceData").size(), client_records);
}

TEST(Propagation, AMirrorIsAddedToTheClientLikeAnyOnset) {
  // Joined: the client already has a more severe error of its own.
  Robot g;
  g.gen("EVT_STALE", "CONTROL.s_R.ForceData");  // 230 > 220
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  auto records = g.event_records("CONTROL.s_R.ForceData");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_TRUE(records[1].mirror);
  EXPECT_EQ(records[1].outcome, Outcome::Joined);
  EXPECT_EQ(g.outstanding("CONTROL.s_R.ForceData"), "EVT_STALE");
  // Clearing the client's own error leaves the mirror: the provider is still failed.
  g.gen("/EVT_STALE", "CONTROL.s_R.ForceData");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  EXPECT_EQ(g.outstanding("CONTROL.s_R.ForceData"), "EVT_SERVICE_FAILURE");

  // Masked: a degraded service reported to a client that is already in Error.
  Robot h;
  ServiceDependency warn;
  warn.propagate = W;
  test::must(h.co.set_service(h.comp("JR3"), "ForceData", warn), "set_service");
  h.gen("EVT_JR3_FAULT", "CONTROL.s_R.ForceData");
  h.gen("EVT_FORCE_WARNING", "JR3.s_A");
  records = h.event_records("CONTROL.s_R.ForceData");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].outcome, Outcome::Masked);
  EXPECT_EQ(records[1].event, framework_event::kServiceDegraded);
  h.gen("/EVT_JR3_FAULT", "CONTROL.s_R.ForceData");
  EXPECT_EQ(h.at("CONTROL.s_R.ForceData"), W) << "the masked degradation is still present";
}

// ---- warnings ---------------------------------------------------------------------------------------

TEST(Propagation, WarningsDoNotCrossAConnectionByDefault) {
  Robot g;
  g.gen("EVT_FORCE_WARNING", "JR3.s_A");
  EXPECT_EQ(g.at("JR3.s_S.ForceData"), W);
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), N);
  EXPECT_EQ(g.at("CONTROL"), N);
}

TEST(Propagation, WarningsCrossAsServiceDegradedWhenTheServicePropagatesWarnings) {
  Robot g;
  ServiceDependency d;
  d.propagate = W;
  test::must(g.co.set_service(g.comp("JR3"), "ForceData", d), "set_service");
  g.gen("EVT_FORCE_WARNING", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), W);
  const auto conditions = g.co.conditions(g.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].event, framework_event::kServiceDegraded);
  EXPECT_EQ(g.co.structure().event(conditions[0].event).name, "EVT_SERVICE_DEGRADED");
  EXPECT_EQ(conditions[0].severity, 215);
  EXPECT_EQ(conditions[0].level, W);
  EXPECT_EQ(conditions[0].root.event, g.id("EVT_FORCE_WARNING"));
  // Errors still cross, as failures.
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  EXPECT_EQ(g.outstanding("CONTROL.s_R.ForceData"), "EVT_SERVICE_FAILURE");
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), W);
  g.gen("/EVT_FORCE_WARNING", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), N);
}

TEST(Propagation, EachHopAppliesItsOwnServicesPropagationLevel) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  ServiceDependency warn;
  warn.propagate = W;
  test::must(g.co.set_service(g.comp("A"), "out", warn), "set_service");
  g.gen("EVT_WARN", "A.s_A");
  EXPECT_EQ(g.at("B.s_R.in"), W);
  EXPECT_EQ(g.at("B.s_S.out"), W);
  EXPECT_EQ(g.at("C.s_R.in"), N) << "B's service passes errors only";
}

// ---- topologies -------------------------------------------------------------------------------------

TEST(Propagation, AChainCarriesTheRootToTheEndAndClearingTheRootClearsAll) {
  Net g{"A", "B", "C", "D"};
  g.link("B", "A");
  g.link("C", "B");
  g.link("D", "C");
  g.gen("EVT_ROOT", "A.s_A");
  for (const char* m : {"B.s_R.in", "C.s_R.in", "D.s_R.in"}) {
    EXPECT_EQ(g.at(m), E) << m;
    const auto cs = g.co.conditions(g.machine(m));
    ASSERT_EQ(cs.size(), 1u) << m;
    EXPECT_TRUE(cs[0].mirror);
    EXPECT_EQ(cs[0].event, framework_event::kServiceFailure);
    EXPECT_EQ(cs[0].root.origin, g.machine("A.s_A")) << m;
  }
  EXPECT_EQ(path_of(g, "D.s_R.in"), (std::vector<std::string>{"A.s_A", "A.s_S.out", "B.s_R.in", "B.s_S.out", "C.s_R.in",
                                                              "C.s_S.out", "D.s_R.in"}));
  g.gen("/EVT_ROOT", "A.s_A");
  for (const char* c : {"A", "B", "C", "D"}) EXPECT_EQ(g.at(c), N) << c;
}

TEST(Propagation, ADiamondGivesOneMirrorPerRootPerMachineAndClearsOnce) {
  //        A
  //      /   \        D requires b (from B) and c (from C); E requires D.
  //     B     C
  //      \   /
  //        D --- E
  Gcm g;
  g.component("A", {"out"}, {});
  g.component("B", {"out"}, {"in"});
  g.component("C", {"out"}, {"in"});
  g.component("D", {"out"}, {"b", "c"});
  g.component("E", {}, {"in"});
  g.pair("EVT_ROOT", 50, E);
  g.connect("B.in", "A.out");
  g.connect("C.in", "A.out");
  g.connect("D.b", "B.out");
  g.connect("D.c", "C.out");
  g.connect("E.in", "D.out");
  g.gen("EVT_ROOT", "A.s_A");
  for (const char* m : {"B.s_R.in", "C.s_R.in", "D.s_R.b", "D.s_R.c", "E.s_R.in"}) {
    EXPECT_EQ(g.mirrors(m), 1u) << m;
    EXPECT_EQ(g.at(m), E) << m;
  }
  const auto raised = g.event_records("E.s_R.in");
  ASSERT_EQ(raised.size(), 1u) << "two paths, one mirror";
  g.gen("/EVT_ROOT", "A.s_A");
  for (const char* c : {"A", "B", "C", "D", "E"}) EXPECT_EQ(g.at(c), N) << c;
  const auto records = g.event_records("E.s_R.in");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].outcome, Outcome::Cleared);
  EXPECT_EQ(g.records_of_kind("E.s_R.in", RecordKind::Transition).size(), 2u);
}

TEST(Propagation, ACycleOfConnectionsClearsWholeWhenTheRootClears) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  g.link("A", "C");  // A -> B -> C -> A
  g.gen("EVT_ROOT", "A.s_A");
  for (const char* m : {"A.s_R.in", "B.s_R.in", "C.s_R.in"}) {
    EXPECT_EQ(g.at(m), E) << m;
    EXPECT_EQ(g.mirrors(m), 1u) << m;
  }
  EXPECT_EQ(path_of(g, "A.s_R.in"), (std::vector<std::string>{"A.s_A", "A.s_S.out", "B.s_R.in", "B.s_S.out", "C.s_R.in",
                                                              "C.s_S.out", "A.s_R.in"}));
  g.gen("/EVT_ROOT", "A.s_A");
  for (const char* c : {"A", "B", "C"}) {
    EXPECT_EQ(g.at(c), N) << c << ": the original latched forever in a cycle";
    EXPECT_TRUE(g.co.conditions(g.machine(std::string(c) + ".s_R.in")).empty()) << c;
  }
}

TEST(Propagation, ARootOnARequiredInterfaceInsideACycleReachesEveryOtherMachineButNotItself) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  g.link("A", "C");
  g.gen("EVT_ROOT", "B.s_R.in");
  EXPECT_EQ(g.mirrors("B.s_R.in"), 0u);
  EXPECT_EQ(g.co.conditions(g.machine("B.s_R.in")).size(), 1u);
  EXPECT_EQ(g.mirrors("C.s_R.in"), 1u);
  EXPECT_EQ(g.mirrors("A.s_R.in"), 1u);
  g.gen("/EVT_ROOT", "B.s_R.in");
  for (const char* c : {"A", "B", "C"}) EXPECT_EQ(g.at(c), N) << c;
}

TEST(Propagation, ALatchedRootInACycleIsClearedEverywhereByAReset) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  g.link("A", "C");
  g.gen("EVT_LATCH", "A.s_A");
  g.gen("/EVT_LATCH", "A.s_A");
  EXPECT_EQ(g.at("C"), E) << "latched";
  g.reset("A", "operator", "fixed");
  for (const char* c : {"A", "B", "C"}) EXPECT_EQ(g.at(c), N) << c;
}

TEST(Propagation, TwoRootsReachingTheSameMachineGiveTwoMirrorsAndClearingOneLeavesTheOther) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("EVT_JR3_FAULT", "JR3.s_F");
  EXPECT_EQ(g.mirrors("CONTROL.s_R.ForceData"), 2u);
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.mirrors("CONTROL.s_R.ForceData"), 1u);
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  const auto why = explain(g.co, "CONTROL.s_R.ForceData");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  EXPECT_EQ((*why)[0].root.event, "EVT_JR3_FAULT");
  EXPECT_EQ((*why)[0].root.origin, "JR3.s_F");
  g.gen("/EVT_JR3_FAULT", "JR3.s_F");
  EXPECT_EQ(g.at("CONTROL"), N);
}

TEST(Propagation, RootsInDifferentComponentsGiveSeparateMirrorsDownstream) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  g.gen("EVT_ROOT", "A.s_A");
  g.gen("EVT_ROOT", "B.s_A");  // same event, another origin: another root cause
  EXPECT_EQ(g.mirrors("C.s_R.in"), 2u);
  g.gen("/EVT_ROOT", "A.s_A");
  EXPECT_EQ(g.mirrors("C.s_R.in"), 1u);
  EXPECT_EQ(g.at("C.s_R.in"), E);
  EXPECT_EQ(g.at("B.s_R.in"), N);
  g.gen("/EVT_ROOT", "B.s_A");
  EXPECT_EQ(g.at("C"), N);
}

TEST(Propagation, TheServiceDependencyFormulaLimitsWhatCrosses) {
  {
    Robot g;
    ServiceDependency framework_only = ServiceDependency::provided_only();
    framework_only.framework = true;
    test::must(g.co.set_service(g.comp("JR3"), "ForceData", framework_only), "set_service");
    g.gen("EVT_FORCE_ERROR", "JR3.s_A");
    EXPECT_EQ(g.at("JR3"), E);
    EXPECT_EQ(g.at("CONTROL"), N) << "a fault in s_A must not cross a service that excludes s_A";
    g.gen("EVT_JR3_FAULT", "JR3.s_F");
    EXPECT_EQ(g.at("CONTROL"), E);
  }
  {
    Robot g;
    test::must(g.co.set_service(g.comp("JR3"), "ForceData", ServiceDependency::provided_only()), "set_service");
    g.gen("EVT_FORCE_ERROR", "JR3.s_A");
    g.gen("EVT_JR3_FAULT", "JR3.s_F");
    EXPECT_EQ(g.at("CONTROL"), N);
    g.gen("EVT_JR3_FAULT", "JR3.s_P.ForceData");
    EXPECT_EQ(g.at("CONTROL"), E);
  }
  {
    // In a chain, B's service excludes its required interface: A's fault stops at B.
    Net g{"A", "B", "C"};
    g.link("B", "A");
    g.link("C", "B");
    ServiceDependency own_only;
    own_only.all_required = false;
    test::must(g.co.set_service(g.comp("B"), "out", own_only), "set_service");
    g.gen("EVT_ROOT", "A.s_A");
    EXPECT_EQ(g.at("B.s_R.in"), E);
    EXPECT_EQ(g.at("B.s_S.out"), N);
    EXPECT_EQ(g.at("C"), N);
  }
}

// ---- explain ----------------------------------------------------------------------------------------

TEST(Explain, GivesTheRootCauseAndHopPathOfAClientsError) {
  Robot g;
  SampleCause cause;
  cause.filter = g.co.intern("force_limit");
  cause.signal = g.co.intern("JR3.ForceNorm");
  cause.value = 35.0;
  cause.sample_time = seconds_to_time(0.099);
  g.clock.set(seconds_to_time(0.1));
  g.co.generate(g.id("EVT_FORCE_ERROR"), g.machine("JR3.s_A"), cause);

  const auto why = explain(g.co, "CONTROL");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  const Explanation& e = (*why)[0];
  EXPECT_EQ(e.machine, "CONTROL.s_R.ForceData");
  EXPECT_EQ(e.event, "EVT_SERVICE_FAILURE");
  EXPECT_EQ(e.level, E);
  EXPECT_EQ(e.severity, 220);
  EXPECT_TRUE(e.mirror);
  EXPECT_TRUE(e.outstanding);
  EXPECT_EQ(e.root.event, "EVT_FORCE_ERROR");
  EXPECT_EQ(e.root.origin, "JR3.s_A");
  EXPECT_EQ(e.root.time, seconds_to_time(0.1));
  EXPECT_EQ(e.hazard, "H-3");
  EXPECT_EQ(e.root.filter, "force_limit");
  EXPECT_EQ(e.root.signal, "JR3.ForceNorm");
  EXPECT_DOUBLE_EQ(e.root.value, 35.0);
  EXPECT_EQ(e.path, (std::vector<std::string>{"JR3.s_A", "JR3.s_S.ForceData", "CONTROL.s_R.ForceData"}));
  // Its one line, with all of these, is the read model's (ConsoleShell.ExplanationsPrintOneLineEach...).
}

TEST(Explain, WorksForMachinesServicesComponentsAndTheSystem) {
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  auto count = [&](std::string_view a) {
    const auto why = explain(g.co, a);
    EXPECT_TRUE(why) << a;
    return why ? why->size() : 0u;
  };
  EXPECT_EQ(count("JR3.s_A"), 1u);
  EXPECT_EQ(count("JR3.s_F"), 0u);
  EXPECT_EQ(count("JR3.s_S.ForceData"), 1u);
  EXPECT_EQ(count("JR3"), 1u);
  EXPECT_EQ(count("CONTROL.s_R.ForceData"), 1u);
  EXPECT_EQ(count("CONTROL.s_S.Motion"), 1u);
  EXPECT_EQ(count("SYSTEM"), 2u);
  const auto root = explain(g.co, "JR3.s_A");
  ASSERT_TRUE(root);
  ASSERT_EQ(root->size(), 1u);
  EXPECT_FALSE((*root)[0].mirror);
  EXPECT_EQ((*root)[0].path, std::vector<std::string>{"JR3.s_A"});
  EXPECT_EQ((*root)[0].root.origin, "JR3.s_A");
}

TEST(Explain, AServiceAddressExplainsOnlyTheMachinesTheServiceDependsOn) {
  Robot g;
  ServiceDependency framework_only = ServiceDependency::provided_only();
  framework_only.framework = true;
  test::must(g.co.set_service(g.comp("JR3"), "ForceData", framework_only), "set_service");
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("EVT_FORCE_WARNING", "JR3.s_F");
  const auto why = explain(g.co, "JR3.s_S.ForceData");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  EXPECT_EQ((*why)[0].machine, "JR3.s_F");
  EXPECT_EQ(g.at("JR3.s_S.ForceData"), W);
}

TEST(Explain, ListsTheMostSevereConditionFirstAndMarksTheOutstandingOne) {
  Robot g;
  g.gen("EVT_FORCE_WARNING", "CONTROL.s_A");
  g.gen("EVT_JR3_FAULT", "CONTROL.s_A");
  g.gen("EVT_FORCE_ERROR", "CONTROL.s_A");
  const auto why = explain(g.co, "CONTROL.s_A");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 3u);
  EXPECT_EQ((*why)[0].event, "EVT_JR3_FAULT");
  EXPECT_TRUE((*why)[0].outstanding);
  EXPECT_EQ((*why)[1].event, "EVT_FORCE_ERROR");
  EXPECT_FALSE((*why)[1].outstanding);
  EXPECT_EQ((*why)[2].event, "EVT_FORCE_WARNING");
  EXPECT_EQ((*why)[2].level, W);
}

TEST(Explain, AnUnknownAddressIsAnError) {
  Robot g;
  const auto why = explain(g.co, "NOPE.s_A");
  ASSERT_FALSE(why);
  EXPECT_EQ(why.error().code, ErrorCode::NotFound);
  EXPECT_NE(why.error().message.find("NOPE"), std::string::npos);
}

// ---- connections made while faults are active -------------------------------------------------------

TEST(Propagation, ConnectingWhileAFaultIsActiveCarriesItAtOnce) {
  Robot g(false);
  g.clock.set(seconds_to_time(1.0));
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL"), N);
  g.clock.set(seconds_to_time(2.0));
  g.connect("CONTROL.ForceData", "JR3.ForceData");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  const auto records = g.event_records("CONTROL.s_R.ForceData");
  ASSERT_EQ(records.size(), 1u);
  // The mirror and its record carry the activation time of the root (docs/semantics.md §6.8).
  EXPECT_EQ(records[0].time, seconds_to_time(1.0));
  EXPECT_EQ(records[0].root.event, g.id("EVT_FORCE_ERROR"));
  const auto cs = g.co.conditions(g.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(cs.size(), 1u);
  EXPECT_EQ(cs[0].first, seconds_to_time(1.0));
  EXPECT_EQ(cs[0].root.time, seconds_to_time(1.0));
  EXPECT_EQ(path_of(g, "CONTROL.s_R.ForceData"),
            (std::vector<std::string>{"JR3.s_A", "JR3.s_S.ForceData", "CONTROL.s_R.ForceData"}));
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL"), N);
}

TEST(Propagation, ExtendingAChainWhileAFaultIsActiveCarriesItToTheNewEnd) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.gen("EVT_ROOT", "A.s_A");
  g.link("C", "B");
  EXPECT_EQ(g.at("C.s_R.in"), E);
  EXPECT_EQ(g.mirrors("B.s_R.in"), 1u) << "no second mirror for the same root";
  g.gen("/EVT_ROOT", "A.s_A");
  EXPECT_EQ(g.at("C"), N);
}

TEST(Propagation, WarningsStillDoNotCrossWhenConnectingDuringAWarning) {
  Robot g(false);
  g.gen("EVT_FORCE_WARNING", "JR3.s_A");
  g.connect("CONTROL.ForceData", "JR3.ForceData");
  EXPECT_EQ(g.at("CONTROL"), N);
}

// ---- reset and propagation --------------------------------------------------------------------------

TEST(Propagation, ResetOfTheRootsComponentClearsItsMirrorsDownstream) {
  Net g{"A", "B", "C"};
  g.link("B", "A");
  g.link("C", "B");
  g.gen("EVT_LATCH", "A.s_A");
  g.reset("A", "operator", "replaced sensor");
  for (const char* c : {"A", "B", "C"}) EXPECT_EQ(g.at(c), N) << c;
}

TEST(Propagation, ResetOfAClientKeepsTheMirrorOfARootThatIsStillActive) {
  // A mirror exists exactly while its root is active and reachable (§2.6): resetting the client
  // does not make the provider's fault go away.
  Robot g;
  g.gen("EVT_FORCE_ERROR", "JR3.s_A");
  g.gen("EVT_JR3_FAULT", "CONTROL.s_A");
  g.reset("CONTROL", "operator", "restart");
  EXPECT_EQ(g.at("CONTROL.s_A"), N);
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  EXPECT_EQ(g.records_of_kind("CONTROL.s_R.ForceData", RecordKind::Reset).size(), 1u);
  g.gen("/EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(g.at("CONTROL"), N);
}

// ---- broadcast (§2.7) -------------------------------------------------------------------------------

TEST(Broadcast, AnEventOfSeverity251To255AppliesToTheApplicationMachineOfEveryComponent) {
  Robot g;
  g.component("ARM");
  g.event(onset("EVT_ESTOP", 255, kToError));
  g.event(completion("/EVT_ESTOP", 255, kFromError));
  test::must(broadcast(g.co, "EVT_ESTOP"), "broadcast");
  for (const char* c : {"JR3", "CONTROL", "ARM"}) {
    const std::string a = std::string(c) + ".s_A";
    EXPECT_EQ(g.at(a), E) << a;
    EXPECT_EQ(g.outstanding(a), "EVT_ESTOP") << a;
    EXPECT_EQ(g.at(std::string(c) + ".s_F"), N) << c;
  }
  test::must(broadcast(g.co, "/EVT_ESTOP"), "broadcast");
  EXPECT_EQ(g.at("SYSTEM"), N);
}

TEST(Broadcast, GeneratingABroadcastEventOnAnyTargetAppliesItEverywhere) {
  Robot g;
  g.event(onset("EVT_PAUSE", 251, test::kToWarning));
  g.gen("EVT_PAUSE", "JR3.s_F");
  EXPECT_EQ(g.at("JR3.s_A"), W);
  EXPECT_EQ(g.at("CONTROL.s_A"), W);
  EXPECT_EQ(g.at("JR3.s_F"), N);
  g.co.generate(g.id("EVT_PAUSE"), kNoMachine);  // refresh everywhere, no crash
  EXPECT_EQ(g.co.conditions(g.machine("CONTROL.s_A"))[0].count, 2u);
}

TEST(Broadcast, ABroadcastCompletionIsIgnoredWhereItsOnsetIsNotActive) {
  Robot g;
  g.event(onset("EVT_ESTOP", 255, kToError));
  g.event(completion("/EVT_ESTOP", 255, kFromError));
  test::must(broadcast(g.co, "EVT_ESTOP"), "broadcast");
  g.component("LATE");  // added after the onset: nothing to clear there
  test::must(broadcast(g.co, "/EVT_ESTOP"), "broadcast");
  const auto late = g.event_records("LATE.s_A");
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0].outcome, Outcome::Ignored);
  EXPECT_EQ(late[0].text, "not active");
  EXPECT_EQ(g.event_records("JR3.s_A").back().outcome, Outcome::Cleared);
  EXPECT_EQ(g.at("SYSTEM"), N);
}

TEST(Broadcast, BroadcastingAnOrdinaryEventIsAnErrorAndChangesNothing) {
  Robot g;
  const auto r = broadcast(g.co, "EVT_FORCE_ERROR");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("EVT_FORCE_ERROR"), std::string::npos);
  EXPECT_EQ(g.at("SYSTEM"), N);
  const auto unknown = broadcast(g.co, "EVT_NOPE");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::NotFound);
}

TEST(Broadcast, ABroadcastErrorStillPropagatesAlongConnections) {
  Robot g;
  g.event(onset("EVT_ESTOP", 252, kToError));
  test::must(broadcast(g.co, "EVT_ESTOP"), "broadcast");
  EXPECT_EQ(g.at("CONTROL.s_R.ForceData"), E);
  const auto cs = g.co.conditions(g.machine("CONTROL.s_R.ForceData"));
  ASSERT_EQ(cs.size(), 1u);
  EXPECT_EQ(cs[0].root.origin, g.machine("JR3.s_A"));
}

// ---- framework events (§2.7) ------------------------------------------------------------------------

TEST(FrameworkEvents, EveryCoordinatorDefinesThemWithTheirSeveritiesAndCompletions) {
  Gcm g;
  struct Row {
    const char* name;
    int severity;
    EventId id;
  };
  const Row rows[] = {
      {"EVT_SERVICE_FAILURE", 220, framework_event::kServiceFailure},
      {"EVT_SERVICE_DEGRADED", 215, framework_event::kServiceDegraded},
      {"EVT_THREAD_EXCEPTION", 210, framework_event::kThreadException},
      {"EVT_PERIOD_OVERRUN", 205, framework_event::kPeriodOverrun},
      {"EVT_STALE", 230, framework_event::kStale},
      {"EVT_CALLBACK_EXCEPTION", 210, framework_event::kCallbackException},
      {"EVT_COORDINATOR_LOST", 240, framework_event::kCoordinatorLost},
      {"EVT_INVALID_SAMPLE", 225, framework_event::kInvalidSample},
  };
  EXPECT_EQ(g.co.structure().event_count(), framework_event::kCount);
  for (const Row& row : rows) {
    const EventId on = g.id(row.name);
    EXPECT_EQ(on, row.id) << row.name;
    const Event& e = g.co.structure().event(on);
    EXPECT_TRUE(e.is_onset) << row.name;
    EXPECT_EQ(e.severity, row.severity) << row.name;
    EXPECT_GE(e.severity, 201) << row.name << " is in the framework band";
    EXPECT_LE(e.severity, 250) << row.name << " is in the framework band";
    EXPECT_FALSE(e.description.empty()) << row.name;
    const EventId off = g.id(std::string("/") + row.name);
    EXPECT_EQ(off, framework_event::completion_of(on)) << row.name;
    EXPECT_FALSE(g.co.structure().event(off).is_onset) << row.name;
    EXPECT_EQ(g.co.structure().event(off).counterpart, on) << row.name;
    EXPECT_EQ(e.counterpart, off) << row.name;
  }
  EXPECT_EQ(onset_level(g.co.structure().event(framework_event::kServiceFailure).transitions, N), E);
  EXPECT_EQ(onset_level(g.co.structure().event(framework_event::kServiceDegraded).transitions, N), W);
}

TEST(FrameworkEvents, EachCanBeRaisedOnAFrameworkMachineAndClearedByItsCompletion) {
  for (const char* name : {"EVT_SERVICE_FAILURE", "EVT_SERVICE_DEGRADED", "EVT_THREAD_EXCEPTION", "EVT_PERIOD_OVERRUN",
                           "EVT_STALE", "EVT_CALLBACK_EXCEPTION", "EVT_COORDINATOR_LOST", "EVT_INVALID_SAMPLE"}) {
    Gcm g;
    g.component("C");
    g.gen(name, "C.s_F");
    EXPECT_NE(g.at("C.s_F"), N) << name;
    EXPECT_EQ(g.outstanding("C.s_F"), name);
    g.gen(std::string("/") + name, "C.s_F");
    EXPECT_EQ(g.at("C.s_F"), N) << name;
  }
}

}  // namespace
}  // namespace safecass
