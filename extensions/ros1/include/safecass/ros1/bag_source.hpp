#pragma once
/// @file bag_source.hpp
/// A ROS 1 bag as an input source of `safecass replay` (record/input_source.hpp; built with
/// SAFECASS_WITH_ROS1 when Debian's rosbag C++ library is found: target safecass::ros1_bag). The ROS extension's
/// mapping file says which topic's message fields feed which signals, with the same field paths as the live bridge
/// (extensions/ros1, docs/frameworks.md), so a bag recorded from the ROS graph replays through the same specs
/// unchanged. Times are the bag's receive times, counted from the bag's first message. Mapped signals the replayed
/// system does not have (the bridge's own rate and age signals, for example) are not fed, and said.

#include <memory>
#include <string>

#include "safecass/record/input_source.hpp"

namespace safecass::ros1 {

/// Opens `bag` with `mapping`. Errors: Io (cannot read), Parse (the mapping's diagnostics; a bag
/// rosbag cannot open, such as a truncated one, with rosbag's reason).
[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_bag(const std::string& bag, const std::string& mapping);

}  // namespace safecass::ros1
