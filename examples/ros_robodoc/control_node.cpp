// ROBODOC's CONTROL as a ROS node that embeds SAFECASS (paper §V-B on ROS 1).
//
// The safety features are the specifications of examples/robodoc, unchanged; mapping.json says
// which ROS node is which component and which topic carries which connection. This node adds
// only what the application knows: CONTROL's loop, split into run_normal / run_warning /
// run_error and chosen every cycle by dispatch() on CONTROL's extended state. It never checks the
// force itself: JR3's faults reach CONTROL through the ForceData connection.
//
// Usage: ros_robodoc_control [MAPPING.json]   (default: examples/ros_robodoc/mapping.json)

#include <cmath>
#include <cstdio>
#include <string>

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "safecass/filters/registry.hpp"
#include "safecass/ros1/bridge.hpp"

using namespace safecass;

namespace {

class ControlLoop {
public:
  ControlLoop(Coordinator& co, Signal* tracking, ros::Publisher command)
      : co_(co), id_(*co.structure().find_component("CONTROL")), tracking_(tracking), command_(std::move(command)) {}

  void operator()(Time now) {
    co_.dispatch(
        id_, [&] { run_normal(now); }, [&](const Event& e) { run_warning(now, e); },
        [&](const Event& e) { run_error(now, e); });
  }

private:
  void run_normal(Time now) {
    say("run_normal: cutting along the planned path");
    move(now, 1.0);
  }
  void run_warning(Time now, const Event& e) {
    say("run_warning (" + e.name + "): cutting at reduced feed rate");
    move(now, 0.3);
  }
  void run_error(Time now, const Event& e) {
    say("run_error (" + e.name + "): motion frozen, holding position");
    move(now, 0.0);
  }
  void move(Time now, double feed) {
    const double dt = last_ == Time{} ? 0.0 : to_seconds(now - last_);
    last_ = now;
    position_ += feed * 0.01 * dt;
    if (tracking_ != nullptr) tracking_->push(now, 0.05);  // the servo follows closely in this simulation
    sensor_msgs::JointState goal;
    goal.header.stamp = ros::Time::now();
    goal.name = {"cutter"};
    goal.position = {position_};
    goal.velocity = {feed * 0.01};
    command_.publish(goal);
  }
  void say(const std::string& mode) {
    if (mode == mode_) return;
    mode_ = mode;
    ROS_INFO("CONTROL loop -> %s", mode.c_str());
  }

  Coordinator& co_;
  ComponentId id_;
  Signal* tracking_;
  ros::Publisher command_;
  std::string mode_;
  Time last_{};
  double position_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "robodoc_control");
  const std::string mapping = argc > 1 ? argv[1] : "examples/ros_robodoc/mapping.json";
  const FilterRegistry& registry = builtin_filters();
  auto bridge = ros1::Bridge::create(mapping, registry);
  if (!bridge) {
    std::fprintf(stderr, "%s\n", bridge.error().message.c_str());
    return 2;
  }
  Coordinator& co = (*bridge)->coordinator();
  ros::NodeHandle nh;
  ControlLoop control(co, (*bridge)->monitor().signals().find("CONTROL.TrackingError"),
                      nh.advertise<sensor_msgs::JointState>("/robodoc/command", 10));
  if (auto r = (*bridge)->add_loop("CONTROL", std::chrono::milliseconds(10), [&control](Time now) { control(now); });
      !r) {
    std::fprintf(stderr, "%s\n", r.error().message.c_str());
    return 2;
  }
  // Every change of a component's state, with its root cause, in the node's log.
  co.subscribe([&co](const Record& r) {
    if (r.kind != RecordKind::ComponentTransition) return;
    std::string why;
    if (r.to > r.from && r.root.event != kNoEvent)
      why = "  because " + co.structure().address_of(r.root.origin) + ":" + co.structure().event(r.root.event).name;
    ROS_INFO("%s %s -> %s%s", std::string(co.structure().component_name(r.component)).c_str(),
             std::string(to_string(r.from)).c_str(), std::string(to_string(r.to)).c_str(), why.c_str());
  });
  if (auto r = (*bridge)->start(); !r) {
    std::fprintf(stderr, "ros_robodoc_control: %s\n", r.error().message.c_str());
    return 3;
  }
  ros::spin();
  (*bridge)->stop();
  return 0;
}
