#pragma once
/// @file rosbag1_source.hpp
/// A ROS 1 bag (format 2.0, every bag since ROS C Turtle) as a replay source, read by SAFECASS
/// itself with bzip2 and LZ4 for compressed chunks: no ROS installation is needed. Every length and
/// place that the file states is checked against the file, its chunks and their records before it
/// is used; a damaged bag is refused with the byte or the message where it is damaged. The ROS
/// extensions' mapping file says which topic's fields feed which signals, with the live bridge's
/// field paths, so a bag recorded from the ROS graph replays through the same specs unchanged.
/// Messages replay in the order of their receive times (the bag's index), counted from the bag's
/// first message. Mapped signals the replayed system does not have are not fed, and said.

#include <memory>
#include <string>

#include "safecass/replay/source.hpp"

namespace safecass::replay {

/// Opens `bag` with `mapping`. Errors: Io (cannot read), Parse (the mapping's diagnostics; a file
/// that is not a ROS 1 bag of format 2.0, or one whose records are damaged or cut, or that has no
/// index, with where and why).
[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_rosbag1(const std::string& bag, const std::string& mapping);

}  // namespace safecass::replay
