// `safecass viewer`, its message handling (safecass/viewer/protocol.hpp) on the robodoc example run
// in-process: the JSON picture of the system, explain, pushed updates, refused bad requests and
// refused writes. No network here (viewer_server_test.cpp does the sockets).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "safecass/json/read.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/protocol.hpp"

#include "../../../examples/custom_filter/frozen_filter.hpp"
#include "viewer_test_support.hpp"

namespace safecass::viewer {
namespace {

using test::kStory;
using test::kSystem;
using test::parse;
using test::str;

using ::testing::HasSubstr;

/// The robodoc story, driven by hand (advance_to): the wall clock barely moves it (speed 0.001).
std::unique_ptr<InProcessSource> open_story() {
  InProcessOptions o;
  o.scenario = kStory;
  o.speed = 0.001;
  o.log = nullptr;
  auto source = InProcessSource::open(o);
  EXPECT_TRUE(source.has_value()) << (source ? "" : source.error().message);
  return source ? std::move(*source) : nullptr;
}

/// The component `name` of the view, or nullptr.
const json::JsonValue* component(const json::JsonValue& view, std::string_view name) {
  for (const json::JsonValue& co : view.find("coordinators")->array) {
    for (const json::JsonValue& c : co.find("components")->array) {
      if (str(c, "name") == name) return &c;
    }
  }
  return nullptr;
}

const json::JsonValue* machine(const json::JsonValue& view, std::string_view component_name, std::string_view address) {
  const json::JsonValue* c = component(view, component_name);
  if (c == nullptr) return nullptr;
  for (const json::JsonValue& m : c->find("machines")->array) {
    if (str(m, "address") == address) return &m;
  }
  return nullptr;
}

ProtocolOptions writable(std::string token = "s3cret") {
  ProtocolOptions o;
  o.allow_write = true;
  o.token = std::move(token);
  return o;
}

TEST(ViewerProtocol, ViewListsCoordinatorsComponentsAndEveryMachineWithItsState) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, {});
  json::JsonValue view = parse(protocol.view_json());
  EXPECT_EQ(str(view, "system"), "robodoc");
  EXPECT_EQ(str(view, "state"), "Normal");
  const auto& coordinators = view.find("coordinators")->array;
  ASSERT_EQ(coordinators.size(), 2u);
  EXPECT_EQ(str(coordinators[0], "name"), "robot");
  EXPECT_EQ(str(coordinators[0], "address"), "coordinator:robot");
  EXPECT_EQ(str(coordinators[1], "name"), "ui");
  ASSERT_EQ(coordinators[1].find("components")->array.size(), 1u);
  EXPECT_EQ(str(coordinators[1].find("components")->array[0], "name"), "PENDANT");

  // CONTROL: framework, application, two provided, two required, two services, in that order.
  const json::JsonValue* control = component(view, "CONTROL");
  ASSERT_NE(control, nullptr);
  std::vector<std::string> addresses;
  std::vector<std::string> kinds;
  for (const json::JsonValue& m : control->find("machines")->array) {
    addresses.push_back(str(m, "address"));
    kinds.push_back(str(m, "kind"));
  }
  EXPECT_THAT(addresses, ::testing::ElementsAre("CONTROL.s_F", "CONTROL.s_A", "CONTROL.s_P.Command",
                                                "CONTROL.s_P.Status", "CONTROL.s_R.ForceData", "CONTROL.s_R.BoneMotion",
                                                "CONTROL.s_S.Command", "CONTROL.s_S.Status"));
  EXPECT_THAT(kinds, ::testing::ElementsAre("framework", "application", "provided", "provided", "required", "required",
                                            "service", "service"));

  // At t = 0.5 s the force is above 30 N: JR3.s_A is Error and CONTROL in Error through ForceData.
  source->advance_to(0.5);
  view = parse(protocol.view_json());
  EXPECT_EQ(str(view, "state"), "Error");
  EXPECT_EQ(str(*component(view, "CONTROL"), "state"), "Error");
  EXPECT_EQ(str(*component(view, "CONTROL"), "outstanding"), "EVT_SERVICE_FAILURE");
  EXPECT_EQ(str(*machine(view, "JR3", "JR3.s_A"), "state"), "Error");
  EXPECT_EQ(str(*machine(view, "JR3", "JR3.s_A"), "outstanding"), "EVT_FORCE_ERROR");
  EXPECT_EQ(str(*machine(view, "CONTROL", "CONTROL.s_R.ForceData"), "state"), "Error");
  EXPECT_EQ(str(*machine(view, "CONTROL", "CONTROL.s_S.Command"), "state"), "Error");
  EXPECT_EQ(str(*machine(view, "CONTROL", "CONTROL.s_R.BoneMotion"), "state"), "Normal");
  EXPECT_EQ(str(*component(view, "BMM"), "state"), "Normal");
  EXPECT_NEAR(view.find("t")->number, 0.5, 1e-9);
}

TEST(ViewerProtocol, HelloSaysWhetherWritesAreAllowedAndCarriesTheView) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  const json::JsonValue read_only = parse(Protocol(*source, {}).hello());
  EXPECT_EQ(str(read_only, "type"), "hello");
  EXPECT_FALSE(read_only.find("write")->boolean);
  EXPECT_EQ(str(*read_only.find("view"), "system"), "robodoc");
  EXPECT_TRUE(parse(Protocol(*source, writable()).hello()).find("write")->boolean);
}

TEST(ViewerProtocol, ExplainGivesEachConditionWithRootCauseFilterSignalAndHopPath) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, {});
  source->advance_to(0.5);
  const json::JsonValue reply = parse(protocol.handle(R"({"id":7,"op":"explain","address":"CONTROL"})"));
  EXPECT_EQ(str(reply, "type"), "reply");
  EXPECT_EQ(reply.find("id")->number, 7);
  EXPECT_EQ(str(reply, "state"), "Error");
  const auto& conditions = reply.find("conditions")->array;
  ASSERT_EQ(conditions.size(), 1u);
  const json::JsonValue& c = conditions[0];
  EXPECT_EQ(str(c, "machine"), "CONTROL.s_R.ForceData");
  EXPECT_EQ(str(c, "event"), "EVT_SERVICE_FAILURE");
  EXPECT_TRUE(c.find("mirror")->boolean);
  EXPECT_EQ(str(c, "root_event"), "EVT_FORCE_ERROR");
  EXPECT_EQ(str(c, "root_origin"), "JR3.s_A");
  EXPECT_EQ(str(c, "filter"), "force_limit");
  EXPECT_EQ(str(c, "signal"), "JR3.ForceNorm");
  EXPECT_GT(c.find("value")->number, 30.0);
  EXPECT_EQ(str(c, "hazard"), "H-3");
  std::vector<std::string> path;
  for (const json::JsonValue& hop : c.find("path")->array) path.push_back(hop.string);
  ASSERT_GE(path.size(), 2u);
  EXPECT_EQ(path.front(), "JR3.s_A");
  EXPECT_EQ(path.back(), "CONTROL.s_R.ForceData");

  // A coordinator explains every condition of its components; a Normal state has none.
  const json::JsonValue robot = parse(protocol.handle(R"({"op":"explain","address":"coordinator:robot"})"));
  EXPECT_GE(robot.find("conditions")->array.size(), 4u);  // JR3, CONTROL, SERVO (and services)
  const json::JsonValue bmm = parse(protocol.handle(R"({"op":"explain","address":"BMM"})"));
  EXPECT_EQ(str(bmm, "state"), "Normal");
  EXPECT_TRUE(bmm.find("conditions")->array.empty());
}

TEST(ViewerProtocol, UpdatePushesOnlyChangedStatesAndTheListedRecords) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, {});
  source->advance_to(0.5);
  const json::JsonValue update = parse(protocol.update(0));
  EXPECT_EQ(str(update, "type"), "update");
  const json::JsonValue& states = *update.find("states");
  ASSERT_NE(states.find("CONTROL"), nullptr);
  EXPECT_EQ(states.find("CONTROL")->array[0].string, "Error");
  EXPECT_EQ(states.find("CONTROL")->array[1].string, "EVT_SERVICE_FAILURE");
  EXPECT_EQ(states.find("SYSTEM")->array[0].string, "Error");
  EXPECT_EQ(states.find("coordinator:ui")->array[0].string, "Error");  // PENDANT through Status
  EXPECT_EQ(states.find("BMM"), nullptr) << "unchanged states are not sent";
  EXPECT_EQ(states.find("JR3.s_F"), nullptr);
  bool saw_jr3 = false;
  for (const json::JsonValue& r : update.find("records")->array) {
    EXPECT_NE(str(r, "kind"), "event") << "plain events are not listed";
    saw_jr3 = saw_jr3 || (str(r, "machine") == "JR3.s_A" && str(r, "to") == "Error");
  }
  EXPECT_TRUE(saw_jr3);
  // The listed records are kept for pages that connect later.
  EXPECT_GE(parse(protocol.hello()).find("recent")->array.size(), update.find("records")->array.size());

  // Nothing changed: only the clock, at most every 250 ms.
  EXPECT_EQ(str(parse(protocol.update(1000)), "type"), "time");
  EXPECT_EQ(protocol.update(1100), "");
}

TEST(ViewerProtocol, MalformedMessagesGetAnErrorThatSaysWhatIsWrongAndChangeNothing) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, writable());
  source->take_records();  // what happened at t = 0
  const std::string before = protocol.view_json();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "not JSON"},
      {"{", "not JSON"},
      {"nonsense", "not JSON"},
      {"[1,2]", "must be a JSON object"},
      {"42", "must be a JSON object"},
      {"{}", "missing key 'op'"},
      {R"({"op":5})", "'op' must be a string"},
      {R"({"op":"launch"})", "unknown op 'launch'"},
      {R"({"op":"view","extra":true})", "unknown key 'extra'"},
      {R"({"op":"explain"})", "missing key 'address'"},
      {R"({"op":"explain","address":3})", "'address' must be a string, not number"},
      {R"({"op":"explain","address":""})", "must not be empty"},
      {R"({"op":"explain","address":"NOPE"})", "NOPE"},
      {R"({"op":"explain","address":"coordinator:nope"})", "no coordinator 'nope'"},
      {R"({"op":"explain","address":"CONTROL","address":"JR3"})", "given twice"},
      {R"({"id":[1],"op":"view"})", "'id' must be a number or a string"},
      {R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","token":"s3cret"})", "missing key 'target'"},
      {R"({"op":"generate","event":"EVT_NOPE","target":"CONTROL.s_A","token":"s3cret"})", "EVT_NOPE"},
      {R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL","token":"s3cret"})", "CONTROL"},
      {R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A","token":7})",
       "'token' must be a string"},
      {R"({"op":"inject","samples":[[1]],"token":"s3cret"})", "give either 'filter'"},
      {R"({"op":"inject","filter":"force_limit","signal":"JR3.Fz","samples":[[1]],"token":"s3cret"})",
       "give either 'filter'"},
      {R"({"op":"inject","filter":"force_limit","token":"s3cret"})", "missing key 'samples'"},
      {R"({"op":"inject","filter":"force_limit","samples":[],"token":"s3cret"})", "non-empty array"},
      {R"({"op":"inject","filter":"force_limit","samples":[["x"]],"token":"s3cret"})",
       "samples[0] must hold numbers only"},
      {R"({"op":"inject","filter":"force_limit","samples":[1,{}],"token":"s3cret"})",
       "samples[1] must be a number or an array"},
      {R"({"op":"inject","filter":"nope","samples":[1],"token":"s3cret"})", "no filter 'nope'"},
      {R"({"op":"inject","signal":"JR3.nope","samples":[1],"token":"s3cret"})", "no signal 'JR3.nope'"},
      {R"({"op":"reset","token":"s3cret"})", "missing key 'target'"},
      {R"({"op":"reset","target":"NOPE","token":"s3cret"})", "NOPE"},
      {R"({"op":"reset","target":"JR3","reason":12,"token":"s3cret"})", "'reason' must be a string"},
      {R"({"op":"broadcast","event":"EVT_FORCE_ERROR","token":"s3cret"})", ""},
  };
  for (const auto& [message, expected] : cases) {
    const json::JsonValue reply = parse(protocol.handle(message));
    EXPECT_EQ(str(reply, "type"), "error") << message;
    EXPECT_THAT(str(reply, "error"), HasSubstr(expected)) << message;
  }
  EXPECT_EQ(protocol.view_json(), before) << "a refused message changed the system";
  EXPECT_TRUE(source->take_records().empty()) << "a refused message reached the system";
}

TEST(ViewerProtocol, TooLongMessageIsRefused) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  ProtocolOptions o;
  o.max_message = 100;
  Protocol protocol(*source, o);
  const std::string message = R"({"op":"explain","address":")" + std::string(200, 'A') + "\"}";
  EXPECT_THAT(str(parse(protocol.handle(message)), "error"),
              HasSubstr("message too long (" + std::to_string(message.size()) + " bytes; at most 100)"));
  // Names longer than 256 characters are refused too.
  Protocol wide(*source, {});
  EXPECT_THAT(str(parse(wide.handle(R"({"op":"explain","address":")" + std::string(300, 'A') + "\"}")), "error"),
              HasSubstr("longer than 256"));
}

TEST(ViewerProtocol, IdIsEchoedInRepliesAndErrors) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, {});
  EXPECT_EQ(parse(protocol.handle(R"({"id":12,"op":"view"})")).find("id")->number, 12);
  EXPECT_EQ(str(parse(protocol.handle(R"({"id":"a","op":"nope"})")), "id"), "a");
  EXPECT_EQ(str(parse(protocol.handle(R"({"id":"a","op":"view"})")), "op"), "view");
}

TEST(ViewerProtocol, WritesAreRefusedWhenTheViewerIsReadOnly) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, {});  // read-only, no token at all
  source->take_records();
  for (const std::string message :
       {R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A","token":"x"})",
        R"({"op":"broadcast","event":"EVT_CONTROL_FORCE_FREEZE","token":"x"})",
        R"({"op":"inject","filter":"force_limit","samples":[50],"token":"x"})",
        R"({"op":"reset","target":"SYSTEM"})"}) {
    const json::JsonValue reply = parse(protocol.handle(message));
    EXPECT_EQ(str(reply, "type"), "error") << message;
    EXPECT_THAT(str(reply, "error"), HasSubstr("refused: this viewer is read-only")) << message;
  }
  EXPECT_TRUE(source->take_records().empty());
  EXPECT_EQ(source->coordinator().state_of(*source->coordinator().structure().resolve("CONTROL.s_A")), State::Normal);
}

TEST(ViewerProtocol, WritesWithoutTheRightTokenAreRefusedAndWithItApplied) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, writable("s3cret"));
  source->take_records();
  const std::string generate = R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A")";
  EXPECT_THAT(str(parse(protocol.handle(generate + "}")), "error"), HasSubstr("refused: a write needs the token"));
  EXPECT_THAT(str(parse(protocol.handle(generate + R"(,"token":"s3cre"})")), "error"),
              HasSubstr("refused: wrong token"));
  EXPECT_THAT(str(parse(protocol.handle(generate + R"(,"token":"s3cret!"})")), "error"),
              HasSubstr("refused: wrong token"));
  EXPECT_THAT(str(parse(protocol.handle(generate + R"(,"token":""})")), "error"), HasSubstr("refused"));
  const Coordinator& co = source->coordinator();
  EXPECT_EQ(co.state_of(*co.structure().resolve("CONTROL.s_A")), State::Normal);
  EXPECT_TRUE(source->take_records().empty());

  const json::JsonValue ok = parse(protocol.handle(generate + R"(,"token":"s3cret","id":3})"));
  EXPECT_EQ(str(ok, "type"), "reply");
  EXPECT_EQ(str(ok, "op"), "generate");
  EXPECT_THAT(str(ok, "text"), HasSubstr("generated EVT_CONTROL_FORCE_FREEZE on CONTROL.s_A"));
  EXPECT_EQ(co.state_of(*co.structure().resolve("CONTROL.s_A")), State::Error);
  EXPECT_EQ(co.state_of(*co.structure().resolve("SERVO")), State::Error);

  const json::JsonValue reset =
      parse(protocol.handle(R"({"op":"reset","target":"CONTROL","reason":"test","token":"s3cret"})"));
  EXPECT_THAT(str(reset, "text"), HasSubstr("reset CONTROL"));
  EXPECT_EQ(co.state_of(*co.structure().resolve("SERVO")), State::Normal);
}

TEST(ViewerProtocol, InjectionWithTheTokenReachesTheFilters) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, writable("k"));
  source->advance_to(0.1);
  // Deep: a 1.5 mm bone displacement written into BMM.Displacement is seen on the next run.
  const json::JsonValue deep =
      parse(protocol.handle(R"({"op":"inject","signal":"BMM.Displacement","samples":[1.5],"token":"k"})"));
  EXPECT_THAT(str(deep, "text"), HasSubstr("wrote 1 sample into signal BMM.Displacement"));
  source->advance_to(0.102);
  const std::vector<Explanation> why = *source->explain("BMM.s_A");
  ASSERT_EQ(why.size(), 1u);
  EXPECT_EQ(why[0].root.event, "EVT_BONE_MOTION");
  EXPECT_TRUE(why[0].root.injected);
  // Shallow: queued into one filter.
  const json::JsonValue shallow =
      parse(protocol.handle(R"({"op":"inject","filter":"force_limit","samples":[[50],[50]],"token":"k"})"));
  EXPECT_THAT(str(shallow, "text"), HasSubstr("queued 2 samples into filter force_limit"));
}

/// Hazard `name` of a coverage message (`analyze now`), or nullptr.
const json::JsonValue* hazard(const json::JsonValue& coverage, std::string_view name) {
  for (const json::JsonValue& h : coverage.find("hazards")->array) {
    if (str(h, "hazard") == name) return &h;
  }
  return nullptr;
}

TEST(ViewerProtocol, TheHazardsCoverageIsInHelloAndPushedWhenItChangesMarkingAnUncoveredHazard) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, writable("k"));
  source->advance_to(0.1);
  const json::JsonValue hello = parse(protocol.hello());
  const json::JsonValue* h3 = hazard(*hello.find("coverage"), "H-3");
  ASSERT_NE(h3, nullptr);
  EXPECT_TRUE(h3->find("covered")->boolean);
  (void)protocol.update(0);  // the coverage the pages have (protocol.update pushes it once)

  // A shallow injection into the filter that detects excessive force: H-3 is uncovered until the
  // injected samples are spent and reality is judged again.
  (void)protocol.handle(R"({"op":"inject","filter":"force_limit","samples":[[5],[5]],"token":"k"})");
  const json::JsonValue injected = parse(protocol.update(300));
  ASSERT_NE(injected.find("coverage"), nullptr);
  h3 = hazard(*injected.find("coverage"), "H-3");
  EXPECT_FALSE(h3->find("covered")->boolean);
  EXPECT_EQ(str(h3->find("gaps")->array.at(0), "reason"), "filter force_limit judges injected samples");
  EXPECT_EQ(str(h3->find("gaps")->array.at(0), "onset"), "EVT_FORCE_ERROR");
  EXPECT_EQ(protocol.update(400).find("coverage"), std::string::npos) << "unchanged: not pushed again";

  source->advance_to(0.2);
  const json::JsonValue restored = parse(protocol.update(700));
  ASSERT_NE(restored.find("coverage"), nullptr);
  EXPECT_TRUE(hazard(*restored.find("coverage"), "H-3")->find("covered")->boolean);
}

TEST(ViewerProtocol, ViewCarriesTheConnectionsForTheGraphAndScenarioSecondsAsItsClock) {
  auto source = open_story();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, ProtocolOptions{});
  const json::JsonValue view = parse(protocol.view_json());
  const json::JsonValue* connections = view.find("connections");
  ASSERT_NE(connections, nullptr);
  ASSERT_EQ(connections->array.size(), 4u);  // as robodoc.json lists them
  EXPECT_EQ(str(connections->array[2], "required"), "SERVO.Command");
  EXPECT_EQ(str(connections->array[2], "provided"), "CONTROL.Command");
  EXPECT_EQ(str(*view.find("clock"), "base"), "simulated");  // a simulated run keeps scenario seconds
  EXPECT_EQ(view.find("replay"), nullptr);                   // not a replay
  const std::string refused = protocol.handle(R"({"op":"replay","action":"play"})");
  EXPECT_THAT(refused, HasSubstr(R"("type":"error")"));
  EXPECT_THAT(refused, HasSubstr("not a replay"));
}

TEST(ViewerInProcessSource, OpenReportsWhatIsMissingOrWrong) {
  InProcessOptions none;
  none.log = nullptr;
  auto a = InProcessSource::open(none);
  ASSERT_FALSE(a.has_value());
  EXPECT_THAT(a.error().message, HasSubstr("a system file is needed"));

  InProcessOptions fast;
  fast.system = kSystem;
  fast.speed = 5000;
  auto b = InProcessSource::open(fast);
  ASSERT_FALSE(b.has_value());
  EXPECT_THAT(b.error().message, HasSubstr("--speed"));

  InProcessOptions missing;
  missing.system = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/no-such-system.json";
  auto c = InProcessSource::open(missing);
  ASSERT_FALSE(c.has_value());
  EXPECT_THAT(c.error().message, HasSubstr("no-such-system.json"));

  InProcessOptions system_only;
  system_only.system = kSystem;
  auto d = InProcessSource::open(system_only);
  ASSERT_TRUE(d.has_value()) << d.error().message;
  EXPECT_EQ((*d)->view().coordinators.size(), 2u);
}

TEST(ViewerInProcessSource, ShowsASystemWhoseFilterTypeOnlyTheApplicationsRegistryKnows) {
  const std::string path = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/custom_filter/encoders.json";
  InProcessOptions builtin;
  builtin.system = path;
  builtin.log = nullptr;
  auto refused = InProcessSource::open(builtin);
  ASSERT_FALSE(refused.has_value());
  EXPECT_THAT(refused.error().message, HasSubstr("Frozen"));

  FilterRegistry registry;
  register_builtin_filters(registry);
  ASSERT_TRUE(registry.add<Frozen>("Frozen"));
  InProcessOptions application = builtin;
  application.registry = &registry;
  auto shown = InProcessSource::open(application);
  ASSERT_TRUE(shown.has_value()) << shown.error().message;
  EXPECT_EQ((*shown)->view().coordinators.size(), 1u);
}

}  // namespace
}  // namespace safecass::viewer
