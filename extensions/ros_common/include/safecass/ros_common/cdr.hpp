#pragma once
/// @file cdr.hpp
/// The numbers of a ROS message from its serialised bytes, in the two encodings of the logs that
/// `safecass replay` reads:
/// - ROS 2 (a rosbag2 store, DDS): plain CDR (XCDR1) with its 4-byte encapsulation header (00 00:
///   big endian, 00 01: little endian), members in the order of the .msg file, each aligned to its
///   size counted from the end of the header; a string is a uint32 length (with its NUL) and the
///   bytes, a sequence a uint32 count and the elements;
/// - ROS 1 (a bag): the same members little endian and packed, with no header and no alignment; a
///   string's length does not count a NUL, and std_msgs/Header starts with a uint32 seq.
/// Only the message types the mapping reads (std_msgs Float64, geometry_msgs WrenchStamped,
/// sensor_msgs JointState). Plain C++17; every length is checked against the buffer: bad bytes
/// are an error, never a read outside them (nor an allocation they cannot fill).

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

/// As decode_cdr(), for the ROS 1 serialisation of a message (the data of a bag's message record).
bool decode_ros1(MessageType type, const std::uint8_t* data, std::size_t size, DecodedMessage& out, std::string& error);

}  // namespace safecass::ros_common
