// The coordinator's configuration API on bad input (every error is clear and changes nothing) and
// address resolution.

#include <gtest/gtest.h>

#include <functional>
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

/// JR3 provides ForceData; CONTROL requires ForceData and provides Motion; one connection.
struct Model : Gcm {
  Model() {
    component("JR3", {"ForceData"}, {});
    component("CONTROL", {"Motion"}, {"ForceData"});
    component("ARM", {}, {"Cmd"});
    pair("EVT_FORCE_ERROR", 50, State::Error);
    connect("CONTROL.ForceData", "JR3.ForceData");
  }
};

struct Counts {
  std::size_t components, machines, events, connections;
  bool operator==(const Counts&) const = default;
};
Counts counts(const Coordinator& co) {
  return Counts{co.structure().component_count(), co.structure().machine_count(), co.structure().event_count(),
                co.structure().connections().size()};
}

/// Runs a failing configuration call and checks the error names `offending`, has `code`, and
/// leaves the model's counts unchanged.
template <class T>
void expect_rejected(Model& m, const std::function<Expected<T>()>& call, ErrorCode code, const std::string& offending) {
  const Counts before = counts(m.co);
  const Expected<T> r = call();
  ASSERT_FALSE(r) << offending << " was accepted";
  EXPECT_EQ(r.error().code, code) << r.error().message;
  EXPECT_NE(r.error().message.find(offending), std::string::npos)
      << "message '" << r.error().message << "' does not name '" << offending << "'";
  EXPECT_TRUE(counts(m.co) == before) << "the model changed after rejecting " << offending;
}

// ---- bad input --------------------------------------------------------------------------------------

TEST(BadInput, DuplicateComponentIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<ComponentId>(
      m, [&] { return m.co.add_component("JR3"); }, ErrorCode::Duplicate, "JR3");
  EXPECT_EQ(m.co.structure().provided_machines(m.comp("JR3")).size(), 1u);
}

TEST(BadInput, InvalidComponentNamesAreRejected) {
  Model m;
  for (const char* bad : {"", "A.B", "has space", "tab\there"}) {
    expect_rejected<ComponentId>(
        m, [&] { return m.co.add_component(bad); }, ErrorCode::InvalidArgument, std::string("'") + bad + "'");
  }
}

TEST(BadInput, AComponentCannotTakeANameThatAddressesTheWholeSystem) {
  // "SYSTEM" resolves to the system: a component so named could never be addressed.
  Model m;
  expect_rejected<ComponentId>(
      m, [&] { return m.co.add_component("SYSTEM"); }, ErrorCode::InvalidArgument, "SYSTEM");
}

TEST(Addresses, TheCoordinatorsNameAddressesTheSystemUnlessAComponentHasThatName) {
  Model m;
  const auto system = m.co.structure().resolve("robot");
  ASSERT_TRUE(system);
  EXPECT_EQ(system->kind, Address::Kind::System);
  const ComponentId robot = *m.co.add_component("robot");
  const auto component = m.co.structure().resolve("robot");
  ASSERT_TRUE(component);
  EXPECT_EQ(component->kind, Address::Kind::Component);
  EXPECT_EQ(component->component, robot);
}

TEST(BadInput, DuplicateInterfaceIsRejectedAndChangesNothing) {
  Model m;
  const ComponentId jr3 = m.comp("JR3");
  const ComponentId control = m.comp("CONTROL");
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_provided(jr3, "ForceData"); }, ErrorCode::Duplicate, "ForceData");
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_required(control, "ForceData"); }, ErrorCode::Duplicate, "ForceData");
  // The message also names the component.
  const auto r = m.co.add_provided(jr3, "ForceData");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("JR3"), std::string::npos);
  EXPECT_EQ(m.co.structure().provided_machines(jr3).size(), 1u);
  EXPECT_EQ(m.co.structure().required_machines(control).size(), 1u);
}

TEST(BadInput, AProvidedAndARequiredInterfaceMayShareAName) {
  Model m;
  EXPECT_TRUE(m.co.add_provided(m.comp("CONTROL"), "ForceData"));
  EXPECT_EQ(m.co.structure().address_of(m.machine("CONTROL.s_P.ForceData")), "CONTROL.s_P.ForceData");
  EXPECT_NE(m.machine("CONTROL.s_P.ForceData"), m.machine("CONTROL.s_R.ForceData"));
}

TEST(BadInput, InterfacesOfAnUnknownComponentOrWithInvalidNamesAreRejected) {
  Model m;
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_provided(ComponentId{77}, "X"); }, ErrorCode::NotFound, "77");
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_required(ComponentId{77}, "X"); }, ErrorCode::NotFound, "77");
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_provided(m.comp("JR3"), "a.b"); }, ErrorCode::InvalidArgument, "a.b");
  expect_rejected<MachineId>(
      m, [&] { return m.co.add_required(m.comp("JR3"), ""); }, ErrorCode::InvalidArgument, "JR3");
}

TEST(BadInput, DuplicateEventNameIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<EventId>(
      m, [&] { return m.co.add_event(onset("EVT_FORCE_ERROR", 60, kToError)); }, ErrorCode::Duplicate,
      "EVT_FORCE_ERROR");
  EXPECT_EQ(m.co.structure().event(m.id("EVT_FORCE_ERROR")).severity, 50);
}

TEST(BadInput, EventMixingWorseningAndImprovingTransitionsIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<EventId>(
      m,
      [&] {
        return m.co.add_event(onset("EVT_BAD", 10, {Transition::N2E, Transition::E2N}));
      },
      ErrorCode::InvalidArgument, "EVT_BAD");
  EXPECT_FALSE(m.co.structure().find_event("EVT_BAD"));
}

TEST(BadInput, SeverityOutside1To255IsRejectedAndChangesNothing) {
  Model m;
  for (int severity : {0, 256, -1}) {
    expect_rejected<EventId>(
        m, [&] { return m.co.add_event(onset("EVT_SEV", severity, kToError)); }, ErrorCode::InvalidArgument, "EVT_SEV");
  }
  EXPECT_FALSE(m.co.structure().find_event("EVT_SEV"));
}

TEST(BadInput, ACompletionThatFailsDoesNotLinkItselfToItsOnset) {
  Model m;
  m.event(onset("EVT_ON", 10, kToError));
  EventDef bad = completion("/EVT_ON", 10, kFromError);
  bad.latched = true;
  expect_rejected<EventId>(
      m, [&] { return m.co.add_event(bad); }, ErrorCode::InvalidArgument, "/EVT_ON");
  EXPECT_EQ(m.co.structure().event(m.id("EVT_ON")).counterpart, kNoEvent);
}

TEST(BadInput, ConnectionToAnUnknownComponentIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("ARM.Cmd", "GHOST.Out"); }, ErrorCode::NotFound, "GHOST");
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("GHOST.In", "JR3.ForceData"); }, ErrorCode::NotFound, "GHOST");
}

TEST(BadInput, ConnectionToAnUnknownInterfaceIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("ARM.Nope", "CONTROL.Motion"); }, ErrorCode::NotFound, "Nope");
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("ARM.Cmd", "CONTROL.Nope"); }, ErrorCode::NotFound, "Nope");
  // Direction matters: a provided interface is not a required one.
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("JR3.ForceData", "CONTROL.Motion"); }, ErrorCode::NotFound, "ForceData");
}

TEST(BadInput, MalformedConnectionTextIsRejectedAndChangesNothing) {
  Model m;
  for (const char* bad : {"ARM", "ARM.", ".Cmd", "ARM.Cmd.x", "", "."}) {
    expect_rejected<ConnectionId>(
        m, [&] { return m.co.connect(bad, "CONTROL.Motion"); }, ErrorCode::InvalidArgument,
        std::string("'") + bad + "'");
    expect_rejected<ConnectionId>(
        m, [&] { return m.co.connect("ARM.Cmd", bad); }, ErrorCode::InvalidArgument, std::string("'") + bad + "'");
  }
}

TEST(BadInput, ConnectingARequiredInterfaceTwiceIsRejectedAndChangesNothing) {
  Model m;
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("CONTROL.ForceData", "JR3.ForceData"); }, ErrorCode::Duplicate, "CONTROL.ForceData");
}

TEST(BadInput, ConnectingAComponentToItselfIsRejectedAndChangesNothing) {
  Model m;
  test::must(m.co.add_provided(m.comp("ARM"), "State"), "add_provided");
  expect_rejected<ConnectionId>(
      m, [&] { return m.co.connect("ARM.Cmd", "ARM.State"); }, ErrorCode::InvalidArgument, "ARM");
}

TEST(BadInput, ARejectedConnectionDoesNotPropagateAnything) {
  Model m;
  m.gen("EVT_FORCE_ERROR", "JR3.s_A");
  ASSERT_FALSE(m.co.connect("ARM.Cmd", "JR3.Nope"));
  EXPECT_EQ(m.at("ARM"), State::Normal);
}

TEST(BadInput, GeneratingUnknownEventsOrOnUnknownOrNonMachineTargetsIsAnError) {
  Model m;
  auto r = generate(m.co, "EVT_NOPE", "JR3.s_A");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_NE(r.error().message.find("EVT_NOPE"), std::string::npos);

  r = generate(m.co, "EVT_FORCE_ERROR", "JR3.s_X");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("JR3.s_X"), std::string::npos);

  for (const char* not_a_machine : {"JR3", "SYSTEM", "JR3.s_S.ForceData"}) {
    r = generate(m.co, "EVT_FORCE_ERROR", not_a_machine);
    ASSERT_FALSE(r) << not_a_machine;
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument) << not_a_machine;
    EXPECT_NE(r.error().message.find(not_a_machine), std::string::npos) << r.error().message;
  }
  EXPECT_EQ(m.at("SYSTEM"), State::Normal);
}

// ---- address resolution -----------------------------------------------------------------------------

TEST(Address, SystemAndTheCoordinatorsNameResolveToTheSystem) {
  Model m;
  for (const char* a : {"SYSTEM", "robot"}) {
    const auto r = m.co.structure().resolve(a);
    ASSERT_TRUE(r) << a;
    EXPECT_EQ(r->kind, Address::Kind::System) << a;
  }
}

TEST(Address, AComponentNameResolvesToItsExtendedState) {
  Model m;
  const auto r = m.co.structure().resolve("CONTROL");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kind, Address::Kind::Component);
  EXPECT_EQ(r->component, m.comp("CONTROL"));
}

TEST(Address, EveryMachineAddressResolvesToThatMachine) {
  Model m;
  const ComponentId control = m.comp("CONTROL");
  struct Row {
    const char* text;
    MachineId expected;
  };
  const Row rows[] = {
      {"CONTROL.s_F", m.co.structure().framework_machine(control)},
      {"CONTROL.s_A", m.co.structure().application_machine(control)},
      {"CONTROL.s_P.Motion", m.co.structure().provided_machines(control)[0]},
      {"CONTROL.s_R.ForceData", m.co.structure().required_machines(control)[0]},
  };
  for (const Row& row : rows) {
    const auto r = m.co.structure().resolve(row.text);
    ASSERT_TRUE(r) << row.text;
    EXPECT_EQ(r->kind, Address::Kind::Machine) << row.text;
    EXPECT_EQ(r->component, control) << row.text;
    EXPECT_EQ(r->machine, row.expected) << row.text;
    EXPECT_EQ(m.co.structure().address_of(row.expected), row.text) << "address_of round-trips";
    const auto id = m.co.structure().find_machine(row.text);
    ASSERT_TRUE(id) << row.text;
    EXPECT_EQ(*id, row.expected);
  }
}

TEST(Address, AServiceAddressResolvesToTheProvidedInterfacesServiceState) {
  Model m;
  const auto r = m.co.structure().resolve("CONTROL.s_S.Motion");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kind, Address::Kind::Service);
  EXPECT_EQ(r->component, m.comp("CONTROL"));
  EXPECT_EQ(r->service, 0u);
  m.gen("EVT_FORCE_ERROR", "CONTROL.s_A");
  EXPECT_EQ(m.co.state_of(*r), State::Error);
  const auto machine = m.co.structure().find_machine("CONTROL.s_S.Motion");
  ASSERT_FALSE(machine);
  EXPECT_EQ(machine.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(machine.error().message.find("CONTROL.s_S.Motion"), std::string::npos);
}

TEST(Address, StateOfFollowsEveryKindOfAddress) {
  Model m;
  m.gen("EVT_FORCE_ERROR", "JR3.s_A");
  for (const char* a :
       {"SYSTEM", "JR3", "JR3.s_A", "JR3.s_S.ForceData", "CONTROL", "CONTROL.s_R.ForceData", "CONTROL.s_S.Motion"}) {
    EXPECT_EQ(m.at(a), State::Error) << a;
  }
  for (const char* a : {"ARM", "JR3.s_F", "JR3.s_P.ForceData", "CONTROL.s_A", "CONTROL.s_P.Motion"}) {
    EXPECT_EQ(m.at(a), State::Normal) << a;
  }
}

TEST(Address, BadAddressesGiveClearErrors) {
  Model m;
  struct Row {
    const char* text;
    ErrorCode code;
    const char* named;  // what the message must mention
  };
  const Row rows[] = {
      {"", ErrorCode::NotFound, "''"},
      {"GHOST", ErrorCode::NotFound, "GHOST"},
      {"GHOST.s_A", ErrorCode::NotFound, "GHOST"},
      {"JR3.", ErrorCode::Parse, "JR3."},
      {"JR3.s_X", ErrorCode::Parse, "JR3.s_X"},
      {"JR3.s_P", ErrorCode::Parse, "JR3.s_P"},
      {"JR3.s_F.extra", ErrorCode::Parse, "JR3.s_F.extra"},
      {"JR3.ForceData", ErrorCode::Parse, "JR3.ForceData"},
      {"JR3.s_P.Nope", ErrorCode::NotFound, "Nope"},
      {"CONTROL.s_R.Motion", ErrorCode::NotFound, "Motion"},
      {"CONTROL.s_S.ForceData", ErrorCode::NotFound, "ForceData"},
      {"JR3.s_R.ForceData", ErrorCode::NotFound, "ForceData"},
      {"system", ErrorCode::NotFound, "system"},
  };
  for (const Row& row : rows) {
    const auto r = m.co.structure().resolve(row.text);
    ASSERT_FALSE(r) << "'" << row.text << "' resolved";
    EXPECT_EQ(r.error().code, row.code) << row.text << ": " << r.error().message;
    EXPECT_NE(r.error().message.find(row.named), std::string::npos)
        << "'" << r.error().message << "' does not mention " << row.named;
  }
}

TEST(Address, LookupsByNameFailClearlyForUnknownNames) {
  Model m;
  const auto c = m.co.structure().find_component("GHOST");
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().code, ErrorCode::NotFound);
  EXPECT_NE(c.error().message.find("GHOST"), std::string::npos);
  const auto e = m.co.structure().find_event("EVT_GHOST");
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("EVT_GHOST"), std::string::npos);
}

// ---- configuration results ----------------------------------------------------------------------------

TEST(Configuration, ConnectionsRecordClientAndProviderInterfaces) {
  Model m;
  ASSERT_EQ(m.co.structure().connections().size(), 1u);
  const Connection& c = m.co.structure().connections()[0];
  EXPECT_EQ(c.client, m.comp("CONTROL"));
  EXPECT_EQ(c.required, 0u);
  EXPECT_EQ(c.provider, m.comp("JR3"));
  EXPECT_EQ(c.provided, 0u);
}

TEST(Configuration, CountsGrowWithTheModel) {
  Model m;
  const Counts before = counts(m.co);
  const ComponentId id = m.component("NEW", {"a", "b"}, {"c"});
  EXPECT_EQ(m.co.structure().component_name(id), "NEW");
  EXPECT_EQ(m.co.structure().component_count(), before.components + 1);
  EXPECT_EQ(m.co.structure().machine_count(), before.machines + 2 + 2 + 1);
  m.pair("EVT_NEW", 5, State::Warning);
  EXPECT_EQ(m.co.structure().event_count(), before.events + 2);
  m.connect("NEW.c", "CONTROL.Motion");
  EXPECT_EQ(m.co.structure().connections().size(), before.connections + 1);
}

TEST(Configuration, TheCoordinatorReadsTimeFromTheInjectedClock) {
  Model m;
  m.clock.set(seconds_to_time(7.0));
  EXPECT_EQ(m.co.clock().now(), seconds_to_time(7.0));
  EXPECT_EQ(m.co.structure().name(), "robot");
  Coordinator owned;  // no clock: an owned steady clock
  const Time t0 = owned.clock().now();
  EXPECT_GE(owned.clock().now(), t0);
}

}  // namespace
}  // namespace safecass

// ---- history: one bounded ring for the whole coordinator (docs/semantics.md §8) ---------------

namespace safecass {
namespace {

using test::Gcm;

TEST(History, AnAddressReturnsAtMostHistoryCapacityOfItsNewestRecordsOldestFirst) {
  CoordinatorOptions options;
  options.history_capacity = 4;
  Gcm g(options);
  g.component("JR3");
  g.pair("EVT_X", 50, State::Error);
  for (int i = 0; i < 5; ++i) {
    g.gen("EVT_X", "JR3.s_A");
    g.gen("/EVT_X", "JR3.s_A");
  }
  const auto h = g.co.history(g.machine("JR3.s_A"));
  ASSERT_EQ(h.size(), 4u);
  for (std::size_t i = 1; i < h.size(); ++i) EXPECT_LT(h[i - 1].seq, h[i].seq) << "oldest first";
  EXPECT_EQ(g.co.structure().event(h.back().event).name, "/EVT_X") << "the newest record is last";
}

TEST(History, AQuietAddressKeepsItsRecordsUntilTheCoordinatorHasProducedARingOfNewerOnes) {
  CoordinatorOptions options;
  options.history_records = 16;
  options.history_per_address = 1;
  options.history_records_max = 16;
  Gcm g(options);
  g.component("QUIET");
  g.component("BUSY");
  g.pair("EVT_X", 50, State::Error);
  ASSERT_EQ(g.co.history_size(), 16u);
  g.gen("EVT_X", "QUIET.s_A");
  g.gen("EVT_X", "BUSY.s_A");  // each event adds ~3 records (event, transition, component transition)
  EXPECT_FALSE(g.co.history(g.machine("QUIET.s_A")).empty()) << "still within the ring";
  for (int i = 0; i < 10; ++i) g.gen("EVT_X", "BUSY.s_A"), g.gen("/EVT_X", "BUSY.s_A");
  EXPECT_TRUE(g.co.history(g.machine("QUIET.s_A")).empty()) << "a ring's worth of newer records pushed it out";
  EXPECT_EQ(g.co.history(Address{}).size(), 16u) << "the ring is full, never larger";
}

TEST(History, TheRingGrowsWithTheModelWhileConfiguringAndStaysWithinItsCap) {
  CoordinatorOptions options;
  options.history_records = 4;
  options.history_per_address = 2;
  options.history_records_max = 64;
  Gcm g(options);
  for (int i = 0; i < 5; ++i) g.component("C" + std::to_string(i));  // 5 components, 10 machines
  EXPECT_GE(g.co.history_size(), 30u) << "2 per address";
  for (int i = 5; i < 100; ++i) g.component("C" + std::to_string(i));
  EXPECT_EQ(g.co.history_size(), 64u) << "capped";
}

TEST(History, AScopesHistoryIsEveryRecordInItInStreamOrder) {
  Gcm g;
  g.component("JR3", {"ForceData"});
  g.component("CONTROL", {}, {"ForceData"});
  g.connect("CONTROL.ForceData", "JR3.ForceData");
  g.pair("EVT_X", 50, State::Error);
  g.gen("EVT_X", "JR3.s_A");
  g.gen("/EVT_X", "JR3.s_A");
  const auto all = g.co.history(Address{});
  ASSERT_FALSE(all.empty());
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].seq, all[i].seq);
  bool control = false, jr3 = false, component_transition = false;
  for (const Record& r : all) {
    control = control || r.component == g.comp("CONTROL");
    jr3 = jr3 || r.component == g.comp("JR3");
    component_transition = component_transition || r.kind == RecordKind::ComponentTransition;
  }
  EXPECT_TRUE(control && jr3 && component_transition);
  Address control_scope;
  control_scope.kind = Address::Kind::Component;
  control_scope.component = g.comp("CONTROL");
  for (const Record& r : g.co.history(control_scope)) EXPECT_EQ(r.component, g.comp("CONTROL"));
}

}  // namespace
}  // namespace safecass
