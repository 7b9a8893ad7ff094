// safecass_ros1_node MAPPING.json [ROS remappings...]
//
// A SAFECASS node for a ROS 1 graph: it shadows the nodes named in the mapping file with the
// Generic Component Model of the system spec, feeds their topics into signals, publishes the GCM
// states on /diagnostics and turns other nodes' diagnostics into events. Exit status: 0 after a
// normal shutdown, 2 for a bad mapping or spec, 3 when no master can be reached.

#include <cstdio>

#include <ros/ros.h>

#include "safecass/filters/registry.hpp"
#include "safecass/ros1/bridge.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "safecass");
  if (argc < 2) {
    std::fprintf(stderr, "usage: safecass_ros1_node MAPPING.json\n");
    return 2;
  }
  safecass::FilterRegistry registry;
  safecass::register_builtin_filters(registry);
  auto bridge = safecass::ros1::Bridge::create(argv[1], registry);
  if (!bridge) {
    std::fprintf(stderr, "%s\n", bridge.error().message.c_str());
    return 2;
  }
  if (auto r = (*bridge)->start(); !r) {
    std::fprintf(stderr, "safecass_ros1_node: %s\n", r.error().message.c_str());
    return 3;
  }
  ROS_INFO("safecass: %zu components of '%s' on the ROS graph", (*bridge)->coordinator().component_count(),
           std::string((*bridge)->coordinator().name()).c_str());
  ros::spin();
  (*bridge)->stop();
  return 0;
}
