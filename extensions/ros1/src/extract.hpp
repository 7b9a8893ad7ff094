#pragma once
/// @file extract.hpp
/// Reads the numbers a field path names out of a ROS message (private: includes ROS headers).

#include <cstddef>
#include <string>
#include <vector>

#include <geometry_msgs/WrenchStamped.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include "safecass/ros1/fields.hpp"

namespace safecass::ros1::detail {

/// Writes `width` doubles of `msg` at `path` into `out`. False, with `error` set, when the message
/// does not have them (a JointState array shorter than needed). Never throws, never allocates on
/// success.
inline bool extract(const FieldPath& path, const std_msgs::Float64& msg, double* out, std::size_t width,
                    std::string& error) {
  if (path.type != MessageType::Float64 || width != 1) {
    error = "path '" + path.text + "' does not read a std_msgs/Float64";
    return false;
  }
  out[0] = msg.data;
  return true;
}

inline bool extract(const FieldPath& path, const geometry_msgs::WrenchStamped& msg, double* out, std::size_t width,
                    std::string& error) {
  if (path.type != MessageType::WrenchStamped || width != path.width()) {
    error = "path '" + path.text + "' does not read " + std::to_string(width) + " doubles of a WrenchStamped";
    return false;
  }
  const geometry_msgs::Vector3& f = msg.wrench.force;
  const geometry_msgs::Vector3& t = msg.wrench.torque;
  const double all[6] = {f.x, f.y, f.z, t.x, t.y, t.z};
  std::size_t first = 0;
  switch (path.field) {
    case FieldPath::Field::Wrench: first = 0; break;
    case FieldPath::Field::Force: first = 0; break;
    case FieldPath::Field::Torque: first = 3; break;
    default: error = "path '" + path.text + "' does not read a WrenchStamped"; return false;
  }
  if (path.index >= 0) first += static_cast<std::size_t>(path.index);
  for (std::size_t i = 0; i < width; ++i) out[i] = all[first + i];
  return true;
}

inline bool extract(const FieldPath& path, const sensor_msgs::JointState& msg, double* out, std::size_t width,
                    std::string& error) {
  const std::vector<double>* array = nullptr;
  const char* name = "";
  switch (path.field) {
    case FieldPath::Field::Position:
      array = &msg.position;
      name = "position";
      break;
    case FieldPath::Field::Velocity:
      array = &msg.velocity;
      name = "velocity";
      break;
    case FieldPath::Field::Effort:
      array = &msg.effort;
      name = "effort";
      break;
    default: break;
  }
  if (path.type != MessageType::JointState || array == nullptr) {
    error = "path '" + path.text + "' does not read a JointState";
    return false;
  }
  if (path.index >= 0) {
    if (width != 1 || static_cast<std::size_t>(path.index) >= array->size()) {
      error = std::string(name) + " has " + std::to_string(array->size()) + " elements, no [" +
              std::to_string(path.index) + "]";
      return false;
    }
    out[0] = (*array)[static_cast<std::size_t>(path.index)];
    return true;
  }
  if (array->size() != width) {
    error = std::string(name) + " has " + std::to_string(array->size()) + " elements, the signal expects " +
            std::to_string(width);
    return false;
  }
  for (std::size_t i = 0; i < width; ++i) out[i] = (*array)[i];
  return true;
}

}  // namespace safecass::ros1::detail
