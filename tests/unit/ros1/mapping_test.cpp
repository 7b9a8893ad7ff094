#include <gtest/gtest.h>

#include "safecass/filters/registry.hpp"
#include "safecass/ros1/bridge.hpp"
#include "safecass/ros_common/mapping.hpp"

using namespace safecass;
using namespace safecass::ros1;
using namespace safecass::ros_common;

namespace {

std::string all_messages(const MappingLoad& m) {
  std::string out;
  for (const auto& d : m.diagnostics) out += spec::format(d) + "\n";
  return out;
}

}  // namespace

TEST(Ros1Mapping, TheExampleMappingLoadsWithItsTopicsFieldsAndRules) {
  MappingLoad m = load_mapping("examples/ros_robodoc/mapping.json");
  ASSERT_TRUE(m.mapping) << all_messages(m);
  EXPECT_EQ(m.mapping->system, "examples/ros_robodoc/../robodoc/robodoc.json");
  EXPECT_EQ(m.mapping->coordinator, "robot");
  ASSERT_EQ(m.mapping->topics.size(), 2u);
  const TopicMapping& t = m.mapping->topics[0];
  EXPECT_EQ(t.type, MessageType::WrenchStamped);
  EXPECT_EQ(t.provided, "JR3.ForceData");
  ASSERT_EQ(t.signals.size(), 4u);
  EXPECT_EQ(t.signals[2].signal, "JR3.Fz");
  EXPECT_EQ(t.signals[2].path.index, 2);
  ASSERT_TRUE(t.watchdog);
  EXPECT_EQ(t.watchdog->event, "EVT_WRENCH_TOPIC_STALE");
  ASSERT_TRUE(t.frequency);
  EXPECT_EQ(t.frequency->event, "EVT_ROS_TOPIC_RATE");
  ASSERT_EQ(m.mapping->ingest.size(), 1u);
  EXPECT_TRUE(m.mapping->ingest[0].matches("jr3_sim: saturation"));
  EXPECT_FALSE(m.mapping->ingest[0].matches("other: jr3_sim"));
  EXPECT_EQ(*m.mapping->node_of("JR3"), "/jr3_sim");
  EXPECT_EQ(m.mapping->node_of("BMM"), nullptr);
}

TEST(Ros1Mapping, EveryProblemIsReportedAtOnceWithLineAndColumn) {
  const char* text = R"({
  "safecass_ros1": 1,
  "system": "x.json",
  "nodes": { "JR3": "jr3" },
  "topics": [
    { "topic": "/a", "type": "geometry_msgs/Twist" },
    { "topic": "b", "type": "std_msgs/Float64", "signals": { "X.y": "value" } },
    { "topic": "/c", "type": "sensor_msgs/JointState", "signals": { "noDot": "position" }, "frequency": { "target": "X.s_F" } },
    { "topic": "/d", "type": "std_msgs/Float64", "watchdog": { "timeout": 1, "target": "X.s_F" } }
  ],
  "typo": 3
})";
  MappingLoad m = load_mapping_from_text(text, "m.json");
  EXPECT_FALSE(m.mapping);
  const std::string all = all_messages(m);
  EXPECT_NE(all.find("m.json:4:21: error: node 'jr3' must be a global name"), std::string::npos) << all;
  EXPECT_NE(all.find("m.json:6:30: error: unsupported message type 'geometry_msgs/Twist'"), std::string::npos) << all;
  EXPECT_NE(all.find("topic 'b' must be a global name"), std::string::npos) << all;
  EXPECT_NE(all.find("field path 'value' of std_msgs/Float64: expected 'data'"), std::string::npos) << all;
  EXPECT_NE(all.find("signal 'noDot' must be written Component.name"), std::string::npos) << all;
  EXPECT_NE(all.find("a frequency check needs 'min_rate' or 'max_rate'"), std::string::npos) << all;
  EXPECT_NE(all.find("name a 'rate_signal'"), std::string::npos) << all;
  EXPECT_NE(all.find("m.json:11:3: error: unknown key 'typo'"), std::string::npos) << all;
}

TEST(Ros1Mapping, MalformedJsonAndAMissingFileAreErrorsNotCrashes) {
  EXPECT_FALSE(load_mapping_from_text("{ \"safecass_ros1\": 1, ", "m.json").mapping);
  EXPECT_FALSE(load_mapping_from_text("[]", "m.json").mapping);
  EXPECT_FALSE(load_mapping_from_text("{\"system\": \"s.json\"}", "m.json").mapping);  // no version
  MappingLoad missing = load_mapping("tests/unit/ros1/no_such_mapping.json");
  ASSERT_EQ(missing.diagnostics.size(), 1u);
  EXPECT_NE(missing.diagnostics[0].where.file.find("no_such_mapping.json"), std::string::npos);
}

TEST(Ros1Bridge, TheExampleBuildsTheRobotCoordinatorWithTopicSignalsAndTimingFilters) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto bridge = Bridge::create("examples/ros_robodoc/mapping.json", registry);
  ASSERT_TRUE(bridge) << bridge.error().message;
  Coordinator& co = (*bridge)->coordinator();
  EXPECT_EQ(co.structure().name(), "robot");
  EXPECT_TRUE(co.structure().find_component("CONTROL"));
  EXPECT_FALSE(co.structure().find_component("PENDANT"));  // the "ui" coordinator's
  Monitor& mon = (*bridge)->monitor();
  ASSERT_NE(mon.signals().find("JR3.Torque"), nullptr);
  EXPECT_EQ(mon.signals().find("JR3.Torque")->size(), 3u);
  EXPECT_NE(mon.signals().find("JR3.WrenchRate"), nullptr);
  EXPECT_NE(mon.signals().find("JR3.WrenchAge"), nullptr);
  EXPECT_NE(mon.signals().find("SERVO.Goal"), nullptr);
  ASSERT_NE(mon.find_filter("ros/jr3/wrench:watchdog"), nullptr);
  EXPECT_EQ(mon.find_filter("ros/jr3/wrench:watchdog")->type(), "Watchdog");
  ASSERT_NE(mon.find_filter("ros/jr3/wrench:frequency"), nullptr);
  for (const char* e :
       {"EVT_ROS_DIAG_WARN", "/EVT_ROS_DIAG_ERROR", "EVT_ROS_GRAPH_MISSING", "EVT_WRENCH_TOPIC_STALE"}) {
    EXPECT_TRUE(co.structure().find_event(e)) << e;
  }
  EXPECT_EQ((*bridge)->status_name("JR3.s_A"), "safecass: JR3.s_A");
}

TEST(Ros1Bridge, AddLoopChecksTheComponentAndPeriod) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto bridge = Bridge::create("examples/ros_robodoc/mapping.json", registry);
  ASSERT_TRUE(bridge) << bridge.error().message;
  EXPECT_TRUE((*bridge)->add_loop("CONTROL", std::chrono::milliseconds(10), [](Time) {}));
  EXPECT_EQ((*bridge)->add_loop("CONTROL", std::chrono::milliseconds(10), [](Time) {}).error().code,
            ErrorCode::InvalidArgument);
  EXPECT_EQ((*bridge)->add_loop("NOPE", std::chrono::milliseconds(10), [](Time) {}).error().code, ErrorCode::NotFound);
  EXPECT_EQ((*bridge)->add_loop("JR3", Time{0}, [](Time) {}).error().code, ErrorCode::InvalidArgument);
  // start() without ros::init() is refused, not a crash.
  EXPECT_EQ((*bridge)->start().error().code, ErrorCode::InvalidState);
}

TEST(Ros1Bridge, MappingsThatDisagreeWithTheSystemAreRefusedWithTheReason) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  struct Case {
    const char* file;
    const char* says;
  };
  const Case cases[] = {
      {"tests/unit/ros1/data/no_connection.json", "has no connection between them"},
      {"tests/unit/ros1/data/size_mismatch.json", "gives 3 doubles but signal 'JR3.Fx' has 1"},
      {"tests/unit/ros1/data/unknown_event.json", "no event 'EVT_NOPE'"},
      {"tests/unit/ros1/data/unknown_component.json", "has no component 'ARM'"},
      {"tests/unit/ros1/data/whole_array.json", "declare the signal in the spec"},
  };
  for (const Case& c : cases) {
    auto bridge = Bridge::create(c.file, registry);
    ASSERT_FALSE(bridge) << c.file;
    EXPECT_NE(bridge.error().message.find(c.says), std::string::npos) << c.file << ": " << bridge.error().message;
  }
}
