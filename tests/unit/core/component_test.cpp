// DESIGN §2.2 (a component's machines, service state, extended state) and §2.5 (callbacks,
// dispatch, exceptions thrown by callbacks, events generated from callbacks).

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

using test::Gcm;

using test::E;
using test::N;
using test::W;

/// Component C provides p and q, requires r1 and r2; events EF (error) and WF (warning).
struct Comp : Gcm {
  Comp() {
    component("C", {"p", "q"}, {"r1", "r2"});
    component("D", {"x"}, {});
    pair("EF", 50, E);
    pair("WF", 20, W);
  }
  void set(std::string_view provided, const ServiceDependency& d) {
    test::must(co.set_service(comp("C"), provided, d), "set_service");
  }
  State service(std::uint32_t provided) const { return co.service_state(comp("C"), provided); }
};

const char* const kMachinesOfC[] = {"C.s_F", "C.s_A", "C.s_P.p", "C.s_P.q", "C.s_R.r1", "C.s_R.r2"};

// ---- machines ---------------------------------------------------------------------------------------

TEST(ComponentModel, AComponentOwnsFrameworkApplicationProvidedAndRequiredMachines) {
  Comp c;
  const ComponentId id = c.comp("C");
  EXPECT_EQ(c.co.structure().machine_kind(c.co.structure().framework_machine(id)), MachineKind::Framework);
  EXPECT_EQ(c.co.structure().machine_kind(c.co.structure().application_machine(id)), MachineKind::Application);
  ASSERT_EQ(c.co.structure().provided_machines(id).size(), 2u);
  ASSERT_EQ(c.co.structure().required_machines(id).size(), 2u);
  EXPECT_EQ(c.co.structure().address_of(c.co.structure().framework_machine(id)), "C.s_F");
  EXPECT_EQ(c.co.structure().address_of(c.co.structure().application_machine(id)), "C.s_A");
  EXPECT_EQ(c.co.structure().address_of(c.co.structure().provided_machines(id)[1]), "C.s_P.q");
  EXPECT_EQ(c.co.structure().address_of(c.co.structure().required_machines(id)[0]), "C.s_R.r1");
  EXPECT_EQ(c.co.structure().interface_name(c.co.structure().provided_machines(id)[0]), "p");
  EXPECT_EQ(c.co.structure().interface_name(c.co.structure().required_machines(id)[1]), "r2");
  for (MachineId m : c.co.structure().provided_machines(id))
    EXPECT_EQ(c.co.structure().machine_kind(m), MachineKind::Provided);
  for (MachineId m : c.co.structure().required_machines(id))
    EXPECT_EQ(c.co.structure().machine_kind(m), MachineKind::Required);
  for (const char* a : kMachinesOfC) {
    EXPECT_EQ(c.co.structure().machine_component(c.machine(a)), id) << a;
    EXPECT_EQ(c.at(a), N) << a;
  }
  EXPECT_EQ(c.co.structure().machine_count(), 6u + 3u);
}

// ---- service state ----------------------------------------------------------------------------------

TEST(ServiceState, WithoutAServiceEntryDependsOnFrameworkApplicationAndEveryRequiredInterface) {
  // The conservative default (a change from the original, which used s_P alone).
  const ServiceDependency d;
  EXPECT_TRUE(d.framework);
  EXPECT_TRUE(d.application);
  EXPECT_TRUE(d.all_required);
  EXPECT_EQ(d.propagate, E);
  for (const char* source : {"C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r1", "C.s_R.r2"}) {
    Comp c;
    c.gen("EF", source);
    EXPECT_EQ(c.service(0), E) << "s_S.p must see " << source;
    EXPECT_EQ(c.at("C.s_S.p"), E) << source;
    c.gen("/EF", source);
    EXPECT_EQ(c.service(0), N) << source;
  }
}

TEST(ServiceState, AnotherProvidedInterfaceIsNotPartOfTheServiceState) {
  Comp c;
  c.gen("EF", "C.s_P.q");
  EXPECT_EQ(c.at("C.s_S.p"), N);
  EXPECT_EQ(c.at("C.s_S.q"), E);
}

TEST(ServiceState, ProvidedOnlyMeansTheProvidedMachineAlone) {
  const ServiceDependency d = ServiceDependency::provided_only();
  EXPECT_FALSE(d.framework);
  EXPECT_FALSE(d.application);
  EXPECT_FALSE(d.all_required);
  EXPECT_TRUE(d.required.empty());
  for (const char* source : {"C.s_F", "C.s_A", "C.s_R.r1", "C.s_R.r2", "C.s_P.q"}) {
    Comp c;
    c.set("p", d);
    c.gen("EF", source);
    EXPECT_EQ(c.at("C.s_S.p"), N) << source << " must not reach a provided-only service";
    EXPECT_EQ(c.at("C"), E) << source;
  }
  Comp c;
  c.set("p", d);
  c.gen("WF", "C.s_P.p");
  EXPECT_EQ(c.at("C.s_S.p"), W);
}

TEST(ServiceState, AnExplicitDependencyEntryListsExactlyWhatTheServiceUses) {
  ServiceDependency d;
  d.framework = false;
  d.application = true;
  d.all_required = false;
  d.required = {"r1"};
  struct Row {
    const char* source;
    State expected;
  };
  for (const Row row : {Row{"C.s_F", N}, Row{"C.s_A", E}, Row{"C.s_P.p", E}, Row{"C.s_R.r1", E}, Row{"C.s_R.r2", N}}) {
    Comp c;
    c.set("p", d);
    c.gen("EF", row.source);
    EXPECT_EQ(c.at("C.s_S.p"), row.expected) << row.source;
    const State q = std::string(row.source) == "C.s_P.p" ? N : E;
    EXPECT_EQ(c.at("C.s_S.q"), q) << "q keeps the conservative default; " << row.source;
  }
}

TEST(ServiceState, IsTheProductOfItsTerms) {
  Comp c;
  c.gen("WF", "C.s_A");
  EXPECT_EQ(c.at("C.s_S.p"), W);
  c.gen("EF", "C.s_R.r2");
  EXPECT_EQ(c.at("C.s_S.p"), E);
  c.gen("/EF", "C.s_R.r2");
  EXPECT_EQ(c.at("C.s_S.p"), W);
}

TEST(ServiceState, ServiceEntryErrorsNameTheServiceAndChangeNothing) {
  Comp c;
  ServiceDependency unknown_required;
  unknown_required.all_required = false;
  unknown_required.required = {"nope"};
  auto r = c.co.set_service(c.comp("C"), "p", unknown_required);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_NE(r.error().message.find("nope"), std::string::npos);
  EXPECT_TRUE(c.co.structure().service(c.comp("C"), 0).all_required) << "the failed entry must not be applied";

  r = c.co.set_service(c.comp("C"), "zz", ServiceDependency{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_NE(r.error().message.find("zz"), std::string::npos);

  ServiceDependency normal;
  normal.propagate = N;
  r = c.co.set_service(c.comp("C"), "p", normal);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_EQ(c.co.structure().service(c.comp("C"), 0).propagate, E);

  r = c.co.set_service(ComponentId{99}, "p", ServiceDependency{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
}

TEST(ServiceState, TheServiceEntryCannotChangeWhileTheComponentHoldsConditions) {
  Comp c;
  c.gen("WF", "C.s_A");
  const auto r = c.co.set_service(c.comp("C"), "p", ServiceDependency::provided_only());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidState);
  EXPECT_NE(r.error().message.find("C.p"), std::string::npos) << r.error().message;
  EXPECT_TRUE(c.co.structure().service(c.comp("C"), 0).application) << "the entry is unchanged";
  c.gen("/WF", "C.s_A");
  EXPECT_TRUE(c.co.set_service(c.comp("C"), "p", ServiceDependency::provided_only()));
  EXPECT_FALSE(c.co.structure().service(c.comp("C"), 0).application);
}

// Only conditions on C's own machines can flow through C's services (anything that reaches C
// through a connection is mirrored on C.s_R first), so a fault elsewhere does not block the change.
TEST(ServiceState, AConditionOnAnotherComponentDoesNotBlockTheChange) {
  Comp c;
  c.gen("WF", "D.s_A");
  EXPECT_TRUE(c.co.set_service(c.comp("C"), "p", ServiceDependency::provided_only()));
  EXPECT_FALSE(c.co.structure().service(c.comp("C"), 0).application);
}

// ---- extended state ---------------------------------------------------------------------------------

TEST(ExtendedState, IsTheProductOfEveryMachineOfTheComponent) {
  for (const char* source : kMachinesOfC) {
    Comp c;
    c.gen("WF", source);
    EXPECT_EQ(c.at("C"), W) << source;
    EXPECT_EQ(c.co.extended(c.comp("C")).state, W) << source;
    EXPECT_EQ(c.at("D"), N) << source;
    c.gen("EF", source);
    EXPECT_EQ(c.at("C"), E) << source;
    c.gen("/EF", source);
    EXPECT_EQ(c.at("C"), W) << source;
    c.gen("/WF", source);
    EXPECT_EQ(c.at("C"), N) << source;
  }
}

TEST(ExtendedState, EveryPairOfMachineStatesCombinesByTheStateProduct) {
  for (const char* a : kMachinesOfC) {
    for (const char* b : kMachinesOfC) {
      if (std::string(a) == b) continue;
      for (State sa : {N, W, E}) {
        for (State sb : {N, W, E}) {
          Comp c;
          if (sa != N) c.gen(sa == W ? "WF" : "EF", a);
          if (sb != N) c.gen(sb == W ? "WF" : "EF", b);
          ASSERT_EQ(c.at("C"), sa * sb) << a << "=" << to_string(sa) << " " << b << "=" << to_string(sb);
        }
      }
    }
  }
}

TEST(ExtendedState, OutstandingEventIsTheHighestSeverityAtTheExtendedLevel) {
  Comp c;
  c.pair("E90", 90, E);
  c.pair("W200", 200, W);
  c.gen("W200", "C.s_P.p");
  c.gen("EF", "C.s_A");
  c.gen("E90", "C.s_R.r1");
  EXPECT_EQ(c.component_outstanding("C"), "E90");
  c.gen("/E90", "C.s_R.r1");
  EXPECT_EQ(c.component_outstanding("C"), "EF");
  c.gen("/EF", "C.s_A");
  EXPECT_EQ(c.component_outstanding("C"), "W200");
  c.gen("/W200", "C.s_P.p");
  EXPECT_EQ(c.component_outstanding("C"), "");
}

TEST(ExtendedState, SystemAndCoordinatorStatesAreTheProductOverComponents) {
  Comp c;
  EXPECT_EQ(c.at("SYSTEM"), N);
  c.gen("WF", "D.s_A");
  EXPECT_EQ(c.at("SYSTEM"), W);
  EXPECT_EQ(c.at("robot"), W);
  c.gen("EF", "C.s_F");
  EXPECT_EQ(c.co.coordinator_state(), E);
  c.gen("/EF", "C.s_F");
  EXPECT_EQ(c.co.coordinator_state(), W);
}

// ---- callbacks --------------------------------------------------------------------------------------

struct Log {
  std::vector<std::string> lines;
  StateCallbacks callbacks(const std::string& who) {
    return StateCallbacks{[this, who](State s) { lines.push_back(who + " exit " + std::string(to_string(s))); },
                          [this, who](const TransitionInfo& i) {
                            lines.push_back(who + " transition " + std::string(to_string(i.transition)));
                          },
                          [this, who](State s) { lines.push_back(who + " entry " + std::string(to_string(s))); }};
  }
};

TEST(Callbacks, MachineCallbacksFireExitThenTransitionThenEntry) {
  Comp c;
  Log log;
  c.co.on_machine(c.machine("C.s_A"), log.callbacks("s_A"));
  c.gen("WF", "C.s_A");
  c.gen("EF", "C.s_A");
  c.gen("/EF", "C.s_A");
  c.gen("/WF", "C.s_A");
  EXPECT_EQ(log.lines, (std::vector<std::string>{"s_A exit Normal", "s_A transition N2W", "s_A entry Warning",  //
                                                 "s_A exit Warning", "s_A transition W2E", "s_A entry Error",   //
                                                 "s_A exit Error", "s_A transition E2W", "s_A entry Warning",   //
                                                 "s_A exit Warning", "s_A transition W2N", "s_A entry Normal"}));
}

TEST(Callbacks, ExtendedStateCallbacksFireExitThenTransitionThenEntryAfterTheMachines) {
  Comp c;
  Log log;
  c.co.on_machine(c.machine("C.s_F"), log.callbacks("s_F"));
  c.co.on_component(c.comp("C"), log.callbacks("C"));
  c.gen("EF", "C.s_F");
  c.gen("WF", "C.s_A");  // no transition of C: Error already
  c.gen("/EF", "C.s_F");
  EXPECT_EQ(log.lines, (std::vector<std::string>{"s_F exit Normal", "s_F transition N2E", "s_F entry Error",  //
                                                 "C exit Normal", "C transition N2E", "C entry Error",        //
                                                 "s_F exit Error", "s_F transition E2N", "s_F entry Normal",  //
                                                 "C exit Error", "C transition E2W", "C entry Warning"}));
}

TEST(Callbacks, NoCallbackFiresWhenTheStateDoesNotChange) {
  Comp c;
  c.pair("E90", 90, E);
  c.gen("EF", "C.s_A");
  Log log;
  c.co.on_machine(c.machine("C.s_A"), log.callbacks("s_A"));
  c.co.on_component(c.comp("C"), log.callbacks("C"));
  c.gen("E90", "C.s_A");   // override
  c.gen("WF", "C.s_A");    // masked
  c.gen("EF", "C.s_A");    // refresh
  c.gen("/E90", "C.s_A");  // cleared, still Error
  c.gen("/WF", "C.s_F");   // ignored
  EXPECT_TRUE(log.lines.empty()) << log.lines.front();
}

TEST(Callbacks, TransitionInfoNamesTheMachineEventRootAndTime) {
  Comp c;
  std::vector<TransitionInfo> seen;
  std::vector<RootCause> roots;
  auto keep = [&](const TransitionInfo& i) {
    seen.push_back(i);
    roots.push_back(i.root != nullptr ? *i.root : RootCause{});
  };
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{{}, keep, {}});
  c.co.on_component(c.comp("C"), StateCallbacks{{}, keep, {}});
  c.clock.set(seconds_to_time(2.5));
  c.gen("EF", "C.s_A");
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].machine, c.machine("C.s_A"));
  EXPECT_EQ(seen[0].component, c.comp("C"));
  EXPECT_EQ(seen[0].event, c.id("EF"));
  EXPECT_EQ(seen[0].time, seconds_to_time(2.5));
  EXPECT_EQ(seen[0].transition, Transition::N2E);
  EXPECT_EQ(roots[0].event, c.id("EF"));
  EXPECT_EQ(roots[0].origin, c.machine("C.s_A"));
  EXPECT_EQ(seen[1].machine, kNoMachine) << "the extended state is not a machine";
  EXPECT_EQ(seen[1].component, c.comp("C"));
  EXPECT_EQ(seen[1].event, c.id("EF"));
  EXPECT_EQ(roots[1].event, c.id("EF"));
}

TEST(Callbacks, SeveralCallbacksOnOneMachineAllFireInRegistrationOrder) {
  Comp c;
  Log log;
  c.co.on_machine(c.machine("C.s_A"), log.callbacks("first"));
  c.co.on_machine(c.machine("C.s_A"), log.callbacks("second"));
  c.gen("EF", "C.s_A");
  EXPECT_EQ(log.lines, (std::vector<std::string>{"first exit Normal", "first transition N2E", "first entry Error",
                                                 "second exit Normal", "second transition N2E", "second entry Error"}));
}

TEST(Callbacks, EmptyCallbackSlotsAreSkipped) {
  Comp c;
  int entries = 0;
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{{}, {}, [&](State) { ++entries; }});
  c.co.on_component(c.comp("C"), StateCallbacks{});
  c.gen("EF", "C.s_A");
  EXPECT_EQ(entries, 1);
  EXPECT_EQ(c.at("C.s_F"), N) << "an empty slot is not an error";
}

TEST(Callbacks, AThrowingMachineCallbackBecomesCallbackExceptionOnTheComponentsFramework) {
  Comp c;
  c.co.on_machine(c.machine("C.s_A"),
                  StateCallbacks{{}, [](const TransitionInfo&) { throw std::runtime_error("bug in user code"); }, {}});
  EXPECT_NO_THROW(c.gen("EF", "C.s_A"));
  EXPECT_EQ(c.at("C.s_A"), E) << "the event itself is still applied";
  EXPECT_EQ(c.at("C.s_F"), E);
  EXPECT_EQ(c.outstanding("C.s_F"), "EVT_CALLBACK_EXCEPTION");
  EXPECT_EQ(c.at("D.s_F"), N) << "only the component whose callback threw";
  // The callback keeps throwing; the condition is refreshed, never duplicated.
  EXPECT_NO_THROW(c.gen("/EF", "C.s_A"));
  EXPECT_EQ(c.co.conditions(c.machine("C.s_F")).size(), 1u);
  EXPECT_EQ(c.co.conditions(c.machine("C.s_F"))[0].count, 2u);
}

TEST(Callbacks, AThrowingCallbackOfAnyKindDoesNotPropagateTheException) {
  for (int slot = 0; slot < 3; ++slot) {
    Comp c;
    StateCallbacks cb;
    if (slot == 0) cb.on_exit = [](State) { throw 42; };
    if (slot == 1) cb.on_transition = [](const TransitionInfo&) { throw std::logic_error("x"); };
    if (slot == 2) cb.on_entry = [](State) { throw std::runtime_error("x"); };
    c.co.on_component(c.comp("D"), cb);
    EXPECT_NO_THROW(c.gen("WF", "D.s_A")) << slot;
    EXPECT_EQ(c.outstanding("D.s_F"), "EVT_CALLBACK_EXCEPTION") << slot;
    EXPECT_EQ(c.at("D"), E) << slot;
  }
}

TEST(Callbacks, AThrowingCallbackDoesNotStopTheOtherCallbacks) {
  Comp c;
  Log log;
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{[](State) { throw std::runtime_error("x"); }, {}, {}});
  c.co.on_machine(c.machine("C.s_A"), log.callbacks("other"));
  c.gen("EF", "C.s_A");
  ASSERT_GE(log.lines.size(), 3u);
  EXPECT_EQ(log.lines[0], "other exit Normal");
  EXPECT_EQ(log.lines[2], "other entry Error");
}

TEST(Callbacks, EventsGeneratedFromACallbackAreProcessedBeforeTheOuterGenerateReturns) {
  Comp c;
  // C.s_A entering Error makes D degrade; D's extended state entering Warning raises D.s_F.
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{{}, {}, [&](State s) {
                                                       if (s == E) c.co.generate(c.id("WF"), c.machine("D.s_A"));
                                                     }});
  c.co.on_component(c.comp("D"), StateCallbacks{{}, {}, [&](State s) {
                                                  if (s == W) test::must(generate(c.co, "EF", "D.s_F"), "generate");
                                                }});
  c.gen("EF", "C.s_A");
  EXPECT_EQ(c.at("D.s_A"), W);
  EXPECT_EQ(c.at("D.s_F"), E);
  EXPECT_EQ(c.at("D"), E);
}

TEST(Callbacks, AResetRequestedFromACallbackIsAppliedBeforeTheOuterCallReturns) {
  Comp c;
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{{}, {}, [&](State s) {
                                                       if (s == E)
                                                         test::must(reset(c.co, "D", "C", "interlock"), "reset");
                                                     }});
  c.pair("LATCHED", 40, E, true);
  c.gen("LATCHED", "D.s_A");
  c.gen("EF", "C.s_A");
  EXPECT_EQ(c.at("D"), N);
  const auto resets = c.records_of_kind("D.s_A", RecordKind::Reset);
  ASSERT_EQ(resets.size(), 1u);
  EXPECT_EQ(resets[0].text, "C: interlock");
}

TEST(Callbacks, ACallbackLoopIsBoundedAndTheDroppedRequestsAreCounted) {
  // A callback that undoes every transition it sees would keep the monitored thread busy forever.
  Comp c;
  c.co.on_machine(c.machine("C.s_A"), StateCallbacks{{}, {}, [&](State s) {
                                                       c.co.generate(c.id(s == E ? "/EF" : "EF"), c.machine("C.s_A"));
                                                     }});
  EXPECT_EQ(c.co.dropped_requests(), 0u);
  c.gen("EF", "C.s_A");  // returns
  EXPECT_GT(c.co.dropped_requests(), 0u);
  // The coordinator still works afterwards.
  c.gen("WF", "D.s_A");
  EXPECT_EQ(c.at("D.s_A"), W);
}

TEST(Callbacks, ACallbackSeesTheNewStateWhenItsEntryFires) {
  Comp c;
  State seen_machine = N;
  State seen_component = N;
  c.co.on_machine(c.machine("C.s_A"),
                  StateCallbacks{{}, {}, [&](State) { seen_machine = c.co.state(c.machine("C.s_A")); }});
  c.co.on_component(c.comp("C"),
                    StateCallbacks{{}, {}, [&](State) { seen_component = c.co.extended(c.comp("C")).state; }});
  c.gen("WF", "C.s_A");
  EXPECT_EQ(seen_machine, W);
  EXPECT_EQ(seen_component, W);
}

TEST(Callbacks, CallbacksRunOnceTheWriteIsCompleteSoTheOriginsCallbackSeesItsClientUpdated) {
  // C requires P's Out: a fault at P.s_A reaches C.s_R.In in the same write. P.s_A's callback runs
  // after the whole write, so it reads C's required interface after the propagation.
  Gcm g;
  g.component("P", {"Out"}, {});
  g.component("C", {}, {"In"});
  g.pair("EF", 50, E);
  test::must(g.co.connect("C.In", "P.Out"), "connect");
  State client_seen = N;
  g.co.on_machine(g.machine("P.s_A"), StateCallbacks{{}, {}, [&](State) { client_seen = g.at("C.s_R.In"); }});
  g.gen("EF", "P.s_A");
  EXPECT_EQ(client_seen, E);
}

TEST(Callbacks, AMachineThatChangesTwiceInOneWriteFiresBothTransitionsEachReadingTheStateTheWriteLeft) {
  // C.s_R.In mirrors every root active at P.Out: connecting while P.s_F holds a warning and P.s_A
  // an error carries both in one write (machine by machine: s_F first), N → W → E. Both
  // transitions fire, in order; both entries read Error, the state the write left.
  Gcm g;
  g.component("P", {"Out"}, {});
  g.component("C", {}, {"In"});
  g.pair("EF", 50, E);
  g.pair("WF", 20, W);
  ServiceDependency warnings;
  warnings.propagate = W;
  test::must(g.co.set_service(g.comp("P"), "Out", warnings), "set_service");
  g.gen("WF", "P.s_F");
  g.gen("EF", "P.s_A");
  std::vector<std::pair<State, State>> entries;  // (entered, read back)
  g.co.on_machine(g.machine("C.s_R.In"),
                  StateCallbacks{{}, {}, [&](State s) { entries.emplace_back(s, g.at("C.s_R.In")); }});
  test::must(g.co.connect("C.In", "P.Out"), "connect");
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].first, W);
  EXPECT_EQ(entries[1].first, E);
  EXPECT_EQ(entries[0].second, E);
  EXPECT_EQ(entries[1].second, E);
}

// ---- dispatch ---------------------------------------------------------------------------------------

struct DispatchCount {
  int normal = 0;
  int warning = 0;
  int error = 0;
  std::string event;
};

DispatchCount dispatch_once(const Comp& c, std::string_view component) {
  DispatchCount d;
  c.co.dispatch(
      c.comp(component), [&] { ++d.normal; },
      [&](const Event& e) {
        ++d.warning;
        d.event = e.name;
      },
      [&](const Event& e) {
        ++d.error;
        d.event = e.name;
      });
  return d;
}

TEST(Dispatch, CallsExactlyOneHandlerAccordingToTheExtendedStateWithTheOutstandingEvent) {
  Comp c;
  DispatchCount d = dispatch_once(c, "C");
  EXPECT_EQ(d.normal + d.warning + d.error, 1);
  EXPECT_EQ(d.normal, 1);

  c.gen("WF", "C.s_R.r1");
  d = dispatch_once(c, "C");
  EXPECT_EQ(d.normal + d.warning + d.error, 1);
  EXPECT_EQ(d.warning, 1);
  EXPECT_EQ(d.event, "WF");

  c.gen("EF", "C.s_P.q");
  d = dispatch_once(c, "C");
  EXPECT_EQ(d.normal + d.warning + d.error, 1);
  EXPECT_EQ(d.error, 1);
  EXPECT_EQ(d.event, "EF");

  c.gen("/EF", "C.s_P.q");
  d = dispatch_once(c, "C");
  EXPECT_EQ(d.warning, 1);
  EXPECT_EQ(d.event, "WF");

  d = dispatch_once(c, "D");
  EXPECT_EQ(d.normal, 1) << "dispatch reads the named component only";
}

TEST(Dispatch, FollowsTheStateChangesMadeByPropagation) {
  Comp c;
  test::must(c.co.add_required(c.comp("D"), "in"), "add_required");
  c.connect("D.in", "C.p");
  c.gen("EF", "C.s_A");
  const DispatchCount d = dispatch_once(c, "D");
  EXPECT_EQ(d.error, 1);
  EXPECT_EQ(d.event, "EVT_SERVICE_FAILURE");
}

}  // namespace
}  // namespace safecass
