#pragma once
/// @file rosbag2_source.hpp
/// A ROS 2 bag (rosbag2's sqlite3 storage) as a replay source, built with SQLite. A bag is a
/// directory (metadata.yaml and its .db3 files, read in name order) or one .db3 file. Its messages
/// are the CDR bytes of the wire (ros_common::decode_cdr); the ROS extensions' mapping file says
/// which topic's fields feed which signals, with the live bridges' field paths, so a bag recorded
/// with `ros2 bag record` replays through the same specs unchanged. Times are the bag's receive
/// times, counted from its first message. Mapped signals the replayed system does not have are not
/// fed, and said.

#include <memory>
#include <string>

#include "safecass/replay/source.hpp"

namespace safecass::replay {

/// Opens `bag` with `mapping`. Errors: Io (cannot read), Parse (the mapping's diagnostics; a file
/// that is not a rosbag2 sqlite3 store, with SQLite's reason).
[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_rosbag2(const std::string& bag, const std::string& mapping);

}  // namespace safecass::replay
