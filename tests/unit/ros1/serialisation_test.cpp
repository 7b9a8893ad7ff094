// ros_common::decode_ros1 (what `safecass replay` reads from a ROS 1 bag's message records)
// against the bytes roscpp itself serialises for each mapped type.

#include <gtest/gtest.h>

#include <geometry_msgs/WrenchStamped.h>
#include <ros/serialization.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include <vector>

#include "safecass/ros_common/cdr.hpp"

namespace {

using safecass::ros_common::DecodedMessage;
using safecass::ros_common::MessageType;

template <class M>
std::vector<std::uint8_t> serialise(const M& m) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(m));
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(out, m);
  return bytes;
}

TEST(Ros1Serialisation, EveryMappedTypeDecodesFromTheBytesRoscppWrites) {
  DecodedMessage m;
  std::string error;
  std_msgs::Float64 f;
  f.data = -2.5;
  auto bytes = serialise(f);
  ASSERT_TRUE(safecass::ros_common::decode_ros1(MessageType::Float64, bytes.data(), bytes.size(), m, error)) << error;
  EXPECT_EQ(m.numbers.data, -2.5);

  geometry_msgs::WrenchStamped w;
  w.header.seq = 7;
  w.header.frame_id = "jr3_sensor";
  w.wrench.force.x = 1;
  w.wrench.force.y = 2;
  w.wrench.force.z = 3;
  w.wrench.torque.z = 6;
  bytes = serialise(w);
  ASSERT_TRUE(safecass::ros_common::decode_ros1(MessageType::WrenchStamped, bytes.data(), bytes.size(), m, error))
      << error;
  EXPECT_EQ(m.numbers.wrench[0], 1);
  EXPECT_EQ(m.numbers.wrench[2], 3);
  EXPECT_EQ(m.numbers.wrench[5], 6);

  sensor_msgs::JointState js;
  js.name = {"a", "bc"};
  js.position = {0.5, 1.5};
  js.effort = {9};
  bytes = serialise(js);
  ASSERT_TRUE(safecass::ros_common::decode_ros1(MessageType::JointState, bytes.data(), bytes.size(), m, error))
      << error;
  EXPECT_EQ(m.position, (std::vector<double>{0.5, 1.5}));
  EXPECT_TRUE(m.velocity.empty());
  EXPECT_EQ(m.effort, (std::vector<double>{9}));
  EXPECT_EQ(m.numbers.position_size, 2u);
}

TEST(Ros1Serialisation, BytesCutShortAreRefusedWithWhereAndWhat) {
  sensor_msgs::JointState js;
  js.position = {0.5, 1.5};
  const auto bytes = serialise(js);
  DecodedMessage m;
  std::string error;
  // seq, stamp, an empty frame_id and no names take 20 bytes; the positions' count 4, their values 16.
  ASSERT_EQ(bytes.size(), 48u);
  EXPECT_FALSE(safecass::ros_common::decode_ros1(MessageType::JointState, bytes.data(), 39, m, error));
  EXPECT_EQ(error, "byte 24: a sequence of 2 doubles runs past the end (39 bytes)");
}

}  // namespace
