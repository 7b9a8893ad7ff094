#pragma once
/// @file recording.hpp
/// `--record HISTORY.jsonl` of a ROS node (ROS 1 or ROS 2): the history of the shadow's coordinator
/// goes to HISTORY.jsonl and the samples fed to the spec's signals next to it (HISTORY.inputs,
/// docs/record-format.md), which `safecass replay` feeds through the spec again. The inputs are the
/// signals of the system spec, not the bridge's own topic rates and ages, so the spec alone
/// replays them.

#include <memory>
#include <string>
#include <vector>

#include "safecass/record/input_recorder.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/ros_common/shadow.hpp"

namespace safecass::ros_common {

class NodeRecording {
public:
  /// Opens both files before anything runs. Errors: Io (path and reason).
  [[nodiscard]] static Expected<std::unique_ptr<NodeRecording>> open(Shadow& shadow, const std::string& history_path,
                                                                     FileLimits limits = {});
  /// Closes both files; the losses, one line each (empty: the recording is complete).
  std::vector<std::string> close();
  /// Closes `recording`, when there is one, and prints its losses on stderr: the node's exit status
  /// (0, or 2 for an incomplete recording).
  static int finish(std::unique_ptr<NodeRecording>& recording);

private:
  NodeRecording() = default;
  std::unique_ptr<Recorder> history_;
  std::unique_ptr<InputRecorder> inputs_;
};

}  // namespace safecass::ros_common
