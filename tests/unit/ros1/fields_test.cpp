#include <gtest/gtest.h>

#include <cmath>

#include <diagnostic_msgs/DiagnosticStatus.h>

#include "safecass/ros1/messages.hpp"
#include "safecass/ros_common/fields.hpp"

using namespace safecass;
using namespace safecass::ros1;
using namespace safecass::ros_common;

namespace {

FieldPath path(MessageType t, const char* text) {
  auto p = parse_field_path(t, text);
  EXPECT_TRUE(p) << (p ? "" : p.error().message);
  return p ? *p : FieldPath{};
}

geometry_msgs::WrenchStamped wrench() {
  geometry_msgs::WrenchStamped m;
  m.wrench.force.x = 1;
  m.wrench.force.y = 2;
  m.wrench.force.z = 3;
  m.wrench.torque.x = 4;
  m.wrench.torque.y = 5;
  m.wrench.torque.z = 6;
  return m;
}

}  // namespace

TEST(Ros1Fields, MessageTypesParseByTheirRosNamesAndUnknownOnesListTheSupported) {
  EXPECT_EQ(*parse_message_type("std_msgs/Float64"), MessageType::Float64);
  EXPECT_EQ(*parse_message_type("geometry_msgs/WrenchStamped"), MessageType::WrenchStamped);
  EXPECT_EQ(*parse_message_type("sensor_msgs/JointState"), MessageType::JointState);
  auto bad = parse_message_type("geometry_msgs/Twist");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("geometry_msgs/Twist"), std::string::npos);
  EXPECT_NE(bad.error().message.find("sensor_msgs/JointState"), std::string::npos);
}

TEST(Ros1Fields, PathWidthsFollowTheMessageStructure) {
  EXPECT_EQ(path(MessageType::Float64, "data").width(), 1u);
  EXPECT_EQ(path(MessageType::WrenchStamped, "wrench").width(), 6u);
  EXPECT_EQ(path(MessageType::WrenchStamped, "wrench.force").width(), 3u);
  EXPECT_EQ(path(MessageType::WrenchStamped, "wrench.torque").width(), 3u);
  EXPECT_EQ(path(MessageType::WrenchStamped, "wrench.force.z").width(), 1u);
  EXPECT_EQ(path(MessageType::WrenchStamped, "wrench.torque[1]").width(), 1u);
  EXPECT_EQ(path(MessageType::JointState, "position").width(), 0u);  // the signal's size
  EXPECT_EQ(path(MessageType::JointState, "position[2]").width(), 1u);
}

TEST(Ros1Fields, MalformedPathsAreErrorsThatNameThePathAndWhatIsAccepted) {
  struct Case {
    MessageType type;
    const char* path;
    const char* says;
  };
  const Case cases[] = {{MessageType::Float64, "value", "expected 'data'"},
                        {MessageType::WrenchStamped, "wrench.forc", "expected force, torque"},
                        {MessageType::WrenchStamped, "wrench.force.w", "expected x, y, z"},
                        {MessageType::WrenchStamped, "wrench.force[3]", "out of range"},
                        {MessageType::WrenchStamped, "wrench.force[1].x", "no field"},
                        {MessageType::WrenchStamped, "wrench..force", "empty part"},
                        {MessageType::WrenchStamped, "force", "unknown field 'force'"},
                        {MessageType::JointState, "position[a]", "malformed index"},
                        {MessageType::JointState, "position[", "malformed index"},
                        {MessageType::JointState, "name", "not numeric"},
                        {MessageType::JointState, "position.x", "no members"},
                        {MessageType::JointState, "", "empty part"}};
  for (const Case& c : cases) {
    auto p = parse_field_path(c.type, c.path);
    ASSERT_FALSE(p) << c.path;
    EXPECT_NE(p.error().message.find(c.says), std::string::npos) << p.error().message;
    EXPECT_NE(p.error().message.find(std::string("'") + c.path + "'"), std::string::npos) << p.error().message;
  }
}

TEST(Ros1Fields, WrenchPathsExtractTheNamedNumbers) {
  const auto m = wrench();
  std::string error;
  double out[6] = {};
  ASSERT_TRUE(ros1::extract(path(MessageType::WrenchStamped, "wrench"), m, out, 6, error));
  for (int i = 0; i < 6; ++i) EXPECT_EQ(out[i], i + 1);
  ASSERT_TRUE(ros1::extract(path(MessageType::WrenchStamped, "wrench.torque"), m, out, 3, error));
  EXPECT_EQ(out[0], 4);
  EXPECT_EQ(out[2], 6);
  ASSERT_TRUE(ros1::extract(path(MessageType::WrenchStamped, "wrench.force.y"), m, out, 1, error));
  EXPECT_EQ(out[0], 2);
  ASSERT_TRUE(ros1::extract(path(MessageType::WrenchStamped, "wrench.torque[2]"), m, out, 1, error));
  EXPECT_EQ(out[0], 6);
}

TEST(Ros1Fields, Float64DataIsExtractedEvenWhenNotFiniteSoTheFiltersCanFlagIt) {
  std_msgs::Float64 m;
  m.data = std::nan("");
  std::string error;
  double out = 0;
  ASSERT_TRUE(ros1::extract(path(MessageType::Float64, "data"), m, &out, 1, error));
  EXPECT_TRUE(std::isnan(out));
}

TEST(Ros1Fields, JointStateArraysMustHaveTheSignalsLengthAndIndicesMustExist) {
  sensor_msgs::JointState m;
  m.position = {0.1, 0.2, 0.3};
  m.effort = {7, 8, 9};
  std::string error;
  double out[3] = {};
  ASSERT_TRUE(ros1::extract(path(MessageType::JointState, "position"), m, out, 3, error));
  EXPECT_EQ(out[1], 0.2);
  ASSERT_TRUE(ros1::extract(path(MessageType::JointState, "effort[2]"), m, out, 1, error));
  EXPECT_EQ(out[0], 9);

  out[0] = -1;
  EXPECT_FALSE(ros1::extract(path(MessageType::JointState, "position"), m, out, 6, error));
  EXPECT_NE(error.find("has 3 elements, the signal expects 6"), std::string::npos) << error;
  EXPECT_FALSE(ros1::extract(path(MessageType::JointState, "velocity[0]"), m, out, 1, error));
  EXPECT_NE(error.find("velocity has 0 elements"), std::string::npos) << error;
  EXPECT_EQ(out[0], -1);  // nothing written on failure
}

TEST(Ros1Fields, APathOfAnotherMessageTypeIsRefused) {
  std::string error;
  double out[3] = {};
  EXPECT_FALSE(ros1::extract(path(MessageType::JointState, "position[0]"), wrench(), out, 1, error));
  EXPECT_FALSE(ros1::extract(path(MessageType::WrenchStamped, "wrench.force"), std_msgs::Float64(), out, 1, error));
}

TEST(Ros1Levels, GcmStatesMapToTheDiagnosticStatusLevelBytes) {
  using diagnostic_msgs::DiagnosticStatus;
  EXPECT_EQ(static_cast<int>(to_diagnostic_level(State::Normal)), DiagnosticStatus::OK);
  EXPECT_EQ(static_cast<int>(to_diagnostic_level(State::Warning)), DiagnosticStatus::WARN);
  EXPECT_EQ(static_cast<int>(to_diagnostic_level(State::Error)), DiagnosticStatus::ERROR);
  EXPECT_EQ(to_string(DiagnosticLevel::Stale), "STALE");
}

TEST(Ros1Levels, ReceivedBytesAreLevelsOnlyFromZeroToThree) {
  using diagnostic_msgs::DiagnosticStatus;
  EXPECT_EQ(diagnostic_level_from_byte(DiagnosticStatus::OK), DiagnosticLevel::Ok);
  EXPECT_EQ(diagnostic_level_from_byte(DiagnosticStatus::WARN), DiagnosticLevel::Warn);
  EXPECT_EQ(diagnostic_level_from_byte(DiagnosticStatus::ERROR), DiagnosticLevel::Error);
  EXPECT_EQ(diagnostic_level_from_byte(DiagnosticStatus::STALE), DiagnosticLevel::Stale);
  EXPECT_FALSE(diagnostic_level_from_byte(4));
  EXPECT_FALSE(diagnostic_level_from_byte(255));
  EXPECT_FALSE(diagnostic_level_from_byte(-1));
}
