#pragma once
/// @file messages.hpp
/// The numbers of a ROS 1 message as field paths see them, for the bridge and for readers of ROS 1
/// bags (includes the ROS message headers: C++17). The reading itself is ros_common::extract(),
/// shared with every framework.

#include <geometry_msgs/WrenchStamped.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include "safecass/ros_common/fields.hpp"

namespace safecass::ros1 {

inline ros_common::MessageNumbers numbers_of(const std_msgs::Float64& msg) {
  ros_common::MessageNumbers n;
  n.data = msg.data;
  return n;
}

inline ros_common::MessageNumbers numbers_of(const geometry_msgs::WrenchStamped& msg) {
  const geometry_msgs::Vector3& f = msg.wrench.force;
  const geometry_msgs::Vector3& t = msg.wrench.torque;
  ros_common::MessageNumbers n;
  n.wrench[0] = f.x;
  n.wrench[1] = f.y;
  n.wrench[2] = f.z;
  n.wrench[3] = t.x;
  n.wrench[4] = t.y;
  n.wrench[5] = t.z;
  return n;
}

inline ros_common::MessageNumbers numbers_of(const sensor_msgs::JointState& msg) {
  ros_common::MessageNumbers n;
  n.position = msg.position.data();
  n.position_size = msg.position.size();
  n.velocity = msg.velocity.data();
  n.velocity_size = msg.velocity.size();
  n.effort = msg.effort.data();
  n.effort_size = msg.effort.size();
  return n;
}

/// Writes `width` doubles of `msg` at `path` into `out`; false, with `error` set, when the message
/// does not have them.
template <class Message>
bool extract(const ros_common::FieldPath& path, const Message& msg, double* out, std::size_t width,
             std::string& error) {
  return ros_common::extract(path, numbers_of(msg), out, width, error);
}

}  // namespace safecass::ros1
