// The network-free part of `safecass viewer --ice` (tools/viewer/live_diff.hpp): the rows of a
// coordinator's state list, the picture built from them, the records of what changed between two
// polls, and how the protocol pushes a live coordinator's status. The live system itself is
// tested in tests/integration/viewer_ice/.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/json.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/live_diff.hpp"
#include "safecass/viewer/protocol.hpp"

namespace safecass::viewer {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::string kSystem = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";

/// One coordinator of robodoc built locally, as MiddlewareSource builds its skeleton.
struct LocalCoordinator {
  explicit LocalCoordinator(const std::string& name) : co(name), monitor(co, registry) {
    register_builtin_filters(registry);
    spec::LoadResult loaded = spec::load_system(kSystem, registry);
    EXPECT_TRUE(loaded.ok());
    if (loaded.system) {
      auto r = spec::instantiate(*loaded.system, co, monitor, name);
      EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    }
  }
  FilterRegistry registry;
  Coordinator co;
  Monitor monitor;
};

spec::JsonValue parse(const std::string& text) {
  spec::JsonParse p = spec::parse_json(text, 64);
  EXPECT_TRUE(p.value.has_value()) << text;
  return p.value ? *p.value : spec::JsonValue{};
}

std::string str(const spec::JsonValue& object, std::string_view key) {
  const spec::JsonValue* v = object.find(key);
  return v != nullptr && v->is_string() ? v->string : "<" + std::string(key) + " missing>";
}

LiveRow* row(std::vector<LiveRow>& rows, std::string_view address) {
  for (LiveRow& r : rows) {
    if (r.address == address) return &r;
  }
  ADD_FAILURE() << "no row " << address;
  static LiveRow none;
  return &none;
}

TEST(ViewerLiveDiff, SkeletonRowsListEachLocalComponentThenItsMachinesAndServicesLikeStateList) {
  LocalCoordinator robot("robot");
  const std::vector<LiveRow> rows = skeleton_rows(robot.co);
  ASSERT_GE(rows.size(), 4u);
  EXPECT_EQ(rows[0], (LiveRow{"JR3", "component", State::Normal, ""}));
  EXPECT_EQ(rows[1], (LiveRow{"JR3.s_F", "s_F", State::Normal, ""}));
  EXPECT_EQ(rows[2], (LiveRow{"JR3.s_A", "s_A", State::Normal, ""}));
  std::vector<std::string> components;
  bool required = false, service = false;
  for (const LiveRow& r : rows) {
    if (r.kind == "component") components.push_back(r.address);
    required = required || (r.address == "CONTROL.s_R.ForceData" && r.kind == "s_R");
    service = service || (r.address == "JR3.s_S.ForceData" && r.kind == "s_S");
  }
  EXPECT_THAT(components, ElementsAre("JR3", "BMM", "CONTROL", "SERVO"));  // not PENDANT: the ui process
  EXPECT_TRUE(required);
  EXPECT_TRUE(service);
}

TEST(ViewerLiveDiff, PictureFromRowsHasTheShapeOfTheInProcessPicture) {
  InProcessOptions o;
  o.system = kSystem;
  o.log = nullptr;
  auto in_process = InProcessSource::open(o);
  ASSERT_TRUE(in_process.has_value()) << in_process.error().message;
  const SystemView whole = (*in_process)->view();
  for (const CoordinatorView& expected : whole.coordinators) {
    LocalCoordinator local(expected.name);
    const CoordinatorView got = coordinator_view(expected.name, skeleton_rows(local.co));
    EXPECT_EQ(got.name, expected.name);
    EXPECT_TRUE(got.status.empty());
    ASSERT_EQ(got.components.size(), expected.components.size()) << expected.name;
    for (std::size_t i = 0; i < got.components.size(); ++i) {
      const ComponentView& g = got.components[i];
      const ComponentView& e = expected.components[i];
      EXPECT_EQ(g.name, e.name);
      ASSERT_EQ(g.machines.size(), e.machines.size()) << e.name;
      for (std::size_t j = 0; j < g.machines.size(); ++j) {
        EXPECT_EQ(g.machines[j].address, e.machines[j].address);
        EXPECT_EQ(g.machines[j].kind, e.machines[j].kind) << e.machines[j].address;
        EXPECT_EQ(g.machines[j].name, e.machines[j].name) << e.machines[j].address;
      }
    }
  }
}

TEST(ViewerLiveDiff, PictureTakesTheWorstComponentStateAndSkipsRowsItCannotPlace) {
  const std::vector<LiveRow> rows = {
      {"JR3", "component", State::Error, "EVT_FORCE_ERROR"},
      {"JR3.s_A", "s_A", State::Error, "EVT_FORCE_ERROR"},
      {"JR3.s_X", "bogus", State::Warning, "E"},       // unknown kind
      {"BMM.s_F", "s_F", State::Warning, "E"},         // no BMM component row before it
      {"SERVO", "component", State::Warning, "EVT_W"},
      {"SERVO.s_S.Command", "s_S", State::Warning, ""},
  };
  const CoordinatorView v = coordinator_view("robot", rows);
  EXPECT_EQ(v.state, State::Error);
  ASSERT_EQ(v.components.size(), 2u);
  EXPECT_EQ(v.components[0].outstanding, "EVT_FORCE_ERROR");
  ASSERT_EQ(v.components[0].machines.size(), 1u);
  EXPECT_EQ(v.components[0].machines[0].name, "s_A");
  ASSERT_EQ(v.components[1].machines.size(), 1u);
  EXPECT_EQ(v.components[1].machines[0].kind, NodeKind::Service);
  EXPECT_EQ(v.components[1].machines[0].name, "Command");
  EXPECT_EQ(v.components[1].machines[0].state, State::Warning);
}

TEST(ViewerLiveDiff, UnchangedRowsGiveNoRecord) {
  LocalCoordinator robot("robot");
  const std::vector<LiveRow> rows = skeleton_rows(robot.co);
  EXPECT_TRUE(diff_records(rows, rows, 1.0).empty());
}

TEST(ViewerLiveDiff, ChangedStatesGiveTransitionRecordsInTheHistoryFormat) {
  LocalCoordinator robot("robot");
  const std::vector<LiveRow> before = skeleton_rows(robot.co);
  std::vector<LiveRow> after = before;
  *row(after, "JR3") = {"JR3", "component", State::Error, "EVT_FORCE_ERROR"};
  *row(after, "JR3.s_A") = {"JR3.s_A", "s_A", State::Error, "EVT_FORCE_ERROR"};
  *row(after, "JR3.s_S.ForceData") = {"JR3.s_S.ForceData", "s_S", State::Error, ""};
  const std::vector<std::string> records = diff_records(before, after, 12.5);
  ASSERT_EQ(records.size(), 3u);
  const spec::JsonValue component = parse(records[0]);
  EXPECT_EQ(str(component, "kind"), "component-transition");
  EXPECT_EQ(str(component, "component"), "JR3");
  EXPECT_EQ(component.find("machine"), nullptr);
  EXPECT_EQ(str(component, "event"), "EVT_FORCE_ERROR");
  EXPECT_EQ(str(component, "from"), "Normal");
  EXPECT_EQ(str(component, "to"), "Error");
  EXPECT_DOUBLE_EQ(component.find("t")->number, 12.5);
  const spec::JsonValue machine = parse(records[1]);
  EXPECT_EQ(str(machine, "kind"), "transition");
  EXPECT_EQ(str(machine, "component"), "JR3");
  EXPECT_EQ(str(machine, "machine"), "JR3.s_A");
  EXPECT_EQ(str(machine, "to"), "Error");
  const spec::JsonValue service = parse(records[2]);
  EXPECT_EQ(str(service, "machine"), "JR3.s_S.ForceData");
  EXPECT_EQ(service.find("event"), nullptr);
  for (const std::string& r : records) EXPECT_TRUE(listed_record(r)) << r;

  // Back to Normal: the record names the event that was outstanding.
  const std::vector<std::string> back = diff_records(after, before, 13.0);
  ASSERT_EQ(back.size(), 3u);
  const spec::JsonValue cleared = parse(back[1]);
  EXPECT_EQ(str(cleared, "from"), "Error");
  EXPECT_EQ(str(cleared, "to"), "Normal");
  EXPECT_EQ(str(cleared, "event"), "EVT_FORCE_ERROR");
}

TEST(ViewerLiveDiff, ANewOutstandingEventInTheSameStateGivesARecordAndVanishedRowsGoBackToNormal) {
  const std::vector<LiveRow> before = {{"JR3", "component", State::Error, "EVT_A"}, {"JR3.s_A", "s_A", State::Error, "EVT_A"},
                                       {"BMM", "component", State::Warning, "EVT_W"}};
  const std::vector<LiveRow> after = {{"JR3", "component", State::Error, "EVT_A"}, {"JR3.s_A", "s_A", State::Error, "EVT_B"}};
  const std::vector<std::string> records = diff_records(before, after, 2.0);
  ASSERT_EQ(records.size(), 2u);
  const spec::JsonValue same = parse(records[0]);
  EXPECT_EQ(str(same, "machine"), "JR3.s_A");
  EXPECT_EQ(str(same, "event"), "EVT_B");
  EXPECT_EQ(str(same, "from"), "Error");
  EXPECT_EQ(str(same, "to"), "Error");
  const spec::JsonValue gone = parse(records[1]);
  EXPECT_EQ(str(gone, "component"), "BMM");
  EXPECT_EQ(str(gone, "to"), "Normal");
}

TEST(ViewerLiveDiff, RowsOfARealTransitionInALocalCoordinatorGiveItsRecords) {
  LocalCoordinator robot("robot");
  const std::vector<LiveRow> before = skeleton_rows(robot.co);
  ASSERT_TRUE(robot.co.generate("EVT_FORCE_ERROR", "JR3.s_A").has_value());
  std::vector<LiveRow> after = skeleton_rows(robot.co);
  EXPECT_EQ(row(after, "JR3.s_A")->state, State::Error);
  EXPECT_EQ(row(after, "JR3.s_A")->outstanding, "EVT_FORCE_ERROR");
  EXPECT_EQ(row(after, "CONTROL")->state, State::Error);  // through the required interface, same process
  std::vector<std::string> addresses;
  for (const std::string& r : diff_records(before, after, 1.0)) {
    const spec::JsonValue v = parse(r);
    addresses.push_back(v.find("machine") != nullptr ? str(v, "machine") : str(v, "component"));
  }
  EXPECT_THAT(addresses, ::testing::IsSupersetOf({"JR3", "JR3.s_A", "JR3.s_S.ForceData", "CONTROL", "CONTROL.s_R.ForceData"}));
}

TEST(ViewerLiveDiff, CoordinatorRecordNamesTheCoordinatorAndIsListed) {
  const std::string r = coordinator_record("ui", "lost: coordinator 'ui' did not answer", 3.25);
  const spec::JsonValue v = parse(r);
  EXPECT_EQ(str(v, "kind"), "coordinator");
  EXPECT_EQ(str(v, "coordinator"), "ui");
  EXPECT_EQ(str(v, "text"), "lost: coordinator 'ui' did not answer");
  EXPECT_DOUBLE_EQ(v.find("t")->number, 3.25);
  EXPECT_TRUE(listed_record(r));
}

/// A source whose picture the test sets: one coordinator with one component.
class FakeSource final : public ViewSource {
public:
  void poll() override {}
  SystemView view() const override { return v; }
  double now() const override { return 1.0; }
  bool running() const override { return true; }
  std::vector<std::string> take_records() override {
    std::vector<std::string> out;
    out.swap(records);
    return out;
  }
  Expected<std::vector<Explanation>> explain(std::string_view) const override { return std::vector<Explanation>{}; }
  Expected<std::string> generate(std::string_view, std::string_view) override { return fail(ErrorCode::Denied, "no"); }
  Expected<std::string> broadcast(std::string_view) override { return fail(ErrorCode::Denied, "no"); }
  Expected<std::string> inject(const InjectRequest&) override { return fail(ErrorCode::Denied, "no"); }
  Expected<std::string> reset(std::string_view, std::string_view) override { return fail(ErrorCode::Denied, "no"); }

  SystemView v;
  std::vector<std::string> records;
};

TEST(ViewerLiveDiff, ProtocolShowsALiveCoordinatorsStatusInTheViewAndPushesItsChanges) {
  FakeSource source;
  source.v.system = "robodoc";
  source.v.coordinators.push_back(coordinator_view("ui", {{"PENDANT", "component", State::Normal, ""}}));
  source.v.coordinators.back().status = "unreachable";
  Protocol protocol(source, {});
  const spec::JsonValue view = parse(protocol.view_json());
  EXPECT_EQ(str(view.find("coordinators")->array.at(0), "status"), "unreachable");

  source.v.coordinators.back().status = "";
  source.records.push_back(coordinator_record("ui", "answering", 1.0));
  const std::string update = protocol.update(1000);
  EXPECT_THAT(update, HasSubstr("\"coordinator:ui\":[\"Normal\",\"\"]"));
  EXPECT_THAT(update, HasSubstr("\"kind\":\"coordinator\""));
  EXPECT_EQ(protocol.update(1001), "");  // nothing new
}

}  // namespace
}  // namespace safecass::viewer
