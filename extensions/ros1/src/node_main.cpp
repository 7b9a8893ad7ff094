// safecass_ros1_node MAPPING.json [--record HISTORY.jsonl] [--max-bytes N] [ROS remappings...]
//
// A SAFECASS node for a ROS 1 graph: it shadows the nodes named in the mapping file with the
// Generic Component Model of the system spec, feeds their topics into signals, publishes the GCM
// states on /diagnostics and turns other nodes' diagnostics into events. With --record, the history
// goes to HISTORY.jsonl and the samples fed to the spec's signals next to it (HISTORY.inputs,
// docs/record-format.md), which `safecass replay` feeds through the spec again. Exit status: 0 after
// a normal shutdown, 2 for a bad mapping or spec or an incomplete recording, 3 when no master can
// be reached.

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <ros/ros.h>

#include "safecass/filters/registry.hpp"
#include "safecass/ros1/bridge.hpp"
#include "safecass/ros_common/recording.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "safecass");
  if (argc < 2) {
    std::fprintf(stderr, "usage: safecass_ros1_node MAPPING.json\n");
    return 2;
  }
  const safecass::FilterRegistry& registry = safecass::builtin_filters();
  std::string record;
  safecass::FileLimits limits;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--record") {
      record = argv[i + 1];
    } else if (flag == "--max-bytes") {
      limits.max_bytes = std::strtoull(argv[i + 1], nullptr, 10);
    } else {
      std::fprintf(stderr, "safecass_ros1_node: unknown option '%s'\n", argv[i]);
      return 2;
    }
  }
  auto bridge = safecass::ros1::Bridge::create(argv[1], registry);
  if (!bridge) {
    std::fprintf(stderr, "%s\n", bridge.error().message.c_str());
    return 2;
  }
  // The history and the inputs, opened before anything runs.
  std::unique_ptr<safecass::ros_common::NodeRecording> recording;
  if (!record.empty()) {
    auto r = safecass::ros_common::NodeRecording::open((*bridge)->shadow(), record, limits);
    if (!r) {
      std::fprintf(stderr, "safecass_ros1_node: %s\n", r.error().message.c_str());
      return 2;
    }
    recording = std::move(*r);
  }
  if (auto r = (*bridge)->start(); !r) {
    std::fprintf(stderr, "safecass_ros1_node: %s\n", r.error().message.c_str());
    return 3;
  }
  ROS_INFO("safecass: %zu components of '%s' on the ROS graph", (*bridge)->coordinator().structure().component_count(),
           std::string((*bridge)->coordinator().structure().name()).c_str());
  ros::spin();
  (*bridge)->stop();
  return safecass::ros_common::NodeRecording::finish(recording);
}
