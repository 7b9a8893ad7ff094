#pragma once
/// @file cdr.hpp
/// The numbers of a ROS 2 message from its serialised bytes, as a ROS 2 bag (rosbag2) stores them
/// and as they travel on DDS: plain CDR (XCDR1) with its 4-byte encapsulation header (00 00: big
/// endian, 00 01: little endian), members in the order of the .msg file, each aligned to its size
/// counted from the end of the header; a string is a uint32 length (with its NUL) and the bytes, a
/// sequence a uint32 count and the elements. Only the message types the mapping reads
/// (std_msgs/msg/Float64, geometry_msgs/msg/WrenchStamped, sensor_msgs/msg/JointState).
/// Plain C++17; every length is checked against the buffer: bad bytes are an error, never a read
/// outside them.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "safecass/ros_common/fields.hpp"

namespace safecass::ros_common {

/// What decode_cdr() fills: the numbers, and the storage its JointState arrays point into.
struct DecodedMessage {
  MessageNumbers numbers;
  std::vector<double> position, velocity, effort;
};

/// Decodes `size` bytes at `data` as a `type` message into `out`. False, with `error` saying where
/// and what ("byte 36: a string of 4000000000 bytes runs past the end (52 bytes)"), for bytes
/// that are not such a message.
bool decode_cdr(MessageType type, const std::uint8_t* data, std::size_t size, DecodedMessage& out, std::string& error);

}  // namespace safecass::ros_common
