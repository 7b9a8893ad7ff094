#pragma once
/// @file source.hpp
/// The replay's own input sources (the interface is record/input_source.hpp): a SAFECASS input
/// recording, a CSV file, a ROS 1 bag (rosbag1_source.hpp) and a ROS 2 bag (rosbag2_source.hpp).

#include <memory>
#include <string>

#include "safecass/core/expected.hpp"
#include "safecass/record/input_source.hpp"

namespace safecass::replay {

std::unique_ptr<InputSource> open_recording(std::unique_ptr<InputLogReader> reader);
/// A CSV log: a header naming a time column ("time" or "t", seconds) and one column per scalar
/// signal ("Component.signal") or per element of a vector ("Component.signal[i]"); one row per
/// time. An empty cell is no sample of that signal in that row. Errors: Io.
[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_csv(const std::string& path);

}  // namespace safecass::replay
