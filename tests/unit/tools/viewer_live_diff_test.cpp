// The network-free part of `safecass viewer --ice` (safecass/viewer/live_diff.hpp): the rows of a
// coordinator's state list (the read model's), the picture built from them, and how the protocol
// pushes a live coordinator's status. The live system itself is
// tested in tests/integration/viewer_ice/.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/json/read.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/live_diff.hpp"
#include "safecass/viewer/protocol.hpp"
#include "viewer_test_support.hpp"

namespace safecass::viewer {
namespace {

using test::kSystem;
using test::parse;
using test::str;

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

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

/// The read model's rows of a locally built coordinator (what a live one answers to state list).
std::vector<introspect::StateRow> rows_of(LocalCoordinator& local) {
  introspect::LocalQuery query(local.co, local.monitor, local.registry);
  auto rows = query.state_list();
  EXPECT_TRUE(rows.has_value());
  return rows ? *rows : std::vector<introspect::StateRow>{};
}

TEST(ViewerLiveDiff, TheRowsOfACoordinatorListEachLocalComponentThenItsMachinesAndServicesLikeStateList) {
  LocalCoordinator robot("robot");
  const std::vector<introspect::StateRow> rows = rows_of(robot);
  ASSERT_GE(rows.size(), 4u);
  using introspect::RowKind;
  EXPECT_EQ(rows[0], (introspect::StateRow{"SYSTEM", RowKind::System, State::Normal, ""}));
  EXPECT_EQ(rows[1], (introspect::StateRow{"JR3", RowKind::Component, State::Normal, ""}));
  EXPECT_EQ(rows[2], (introspect::StateRow{"JR3.s_F", RowKind::Framework, State::Normal, ""}));
  EXPECT_EQ(rows[3], (introspect::StateRow{"JR3.s_A", RowKind::Application, State::Normal, ""}));
  std::vector<std::string> components;
  bool required = false, service = false;
  for (const introspect::StateRow& r : rows) {
    if (r.kind == RowKind::Component) components.push_back(r.address);
    required = required || (r.address == "CONTROL.s_R.ForceData" && r.kind == RowKind::Required);
    service = service || (r.address == "JR3.s_S.ForceData" && r.kind == RowKind::Service);
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
    const CoordinatorView got = coordinator_view(expected.name, rows_of(local));
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
  using introspect::RowKind;
  const std::vector<introspect::StateRow> rows = {
      {"SYSTEM", RowKind::System, State::Error, ""},  // not a component
      {"JR3", RowKind::Component, State::Error, "EVT_FORCE_ERROR"},
      {"JR3.s_A", RowKind::Application, State::Error, "EVT_FORCE_ERROR"},
      {"BMM.s_F", RowKind::Framework, State::Warning, "E"},  // no BMM component row before it
      {"SERVO", RowKind::Component, State::Warning, "EVT_W"},
      {"SERVO.s_S.Command", RowKind::Service, State::Warning, ""},
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

TEST(ViewerLiveDiff, CoordinatorRecordNamesTheCoordinatorAndIsListed) {
  const std::string r = coordinator_record("ui", "lost: coordinator 'ui' did not answer", 3.25);
  const json::JsonValue v = parse(r);
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
  introspect::CoverageNow coverage() const override { return {}; }  // a system without hazards
  [[nodiscard]] Expected<std::vector<Explanation>> explain(std::string_view) const override {
    return std::vector<Explanation>{};
  }
  [[nodiscard]] Expected<std::string> apply(const introspect::Action&) override {
    return fail(ErrorCode::Denied, "no");
  }

  std::uint64_t view_version() const override { return version; }

  SystemView v;
  std::vector<std::string> records;
  std::uint64_t version = 0;
};

TEST(ViewerLiveDiff, ProtocolShowsALiveCoordinatorsStatusInTheViewAndPushesItsChanges) {
  FakeSource source;
  source.v.system = "robodoc";
  source.v.coordinators.push_back(
      coordinator_view("ui", {{"PENDANT", introspect::RowKind::Component, State::Normal, ""}}));
  source.v.coordinators.back().status = "unreachable";
  Protocol protocol(source, {});
  const json::JsonValue view = parse(protocol.view_json());
  EXPECT_EQ(str(view.find("coordinators")->array.at(0), "status"), "unreachable");

  source.v.coordinators.back().status = "";
  source.records.push_back(coordinator_record("ui", "answering", 1.0));
  const std::string update = protocol.update(1000);
  EXPECT_THAT(update, HasSubstr("\"coordinator:ui\":[\"Normal\",\"\"]"));
  EXPECT_THAT(update, HasSubstr("\"kind\":\"coordinator\""));
  EXPECT_EQ(protocol.update(1001), "");  // nothing new
}

// A live system's records announce a change before the state list that shows it is fetched: the
// poll that takes the records can still see the old states, and the next one the new states with
// no record. The page must get them then (once the viewer_ice test saw PENDANT stay Error).
TEST(ViewerLiveDiff, ProtocolPushesStatesThatArriveInALaterPollThanTheirRecords) {
  FakeSource source;
  source.v.coordinators.push_back(
      coordinator_view("ui", {{"PENDANT", introspect::RowKind::Component, State::Error, "EVT_SERVICE_FAILURE"}}));
  Protocol protocol(source, {});
  (void)protocol.view_json();

  source.records.push_back(coordinator_record("ui", "PENDANT Error -> Normal", 1.0));
  const std::string with_record = protocol.update(1000);  // the state list is not fetched yet
  EXPECT_THAT(with_record, Not(HasSubstr("\"PENDANT\":[\"Normal\"")));

  source.v.coordinators.back() =
      coordinator_view("ui", {{"PENDANT", introspect::RowKind::Component, State::Normal, ""}});
  ++source.version;  // the state list arrived, with no record in this poll
  EXPECT_THAT(protocol.update(1010), HasSubstr("\"PENDANT\":[\"Normal\",\"\"]"));
  EXPECT_EQ(protocol.update(1020), "");  // nothing new
}

}  // namespace
}  // namespace safecass::viewer
