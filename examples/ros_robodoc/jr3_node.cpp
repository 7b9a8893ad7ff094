// A simulated JR3 force sensor as a plain ROS node (it knows nothing of SAFECASS): it publishes
// geometry_msgs/WrenchStamped on /jr3/wrench and, like a driver using diagnostic_updater, its own
// health on /diagnostics ("jr3_sim: saturation" is WARN above 38 N, near the end of its range).
//
// Usage: ros_robodoc_jr3 [--rate HZ] [--fz NEWTON] [--profile T:FZ,T:FZ,...]
//   --profile  Fz over time (seconds since start), linear between points, held after the last.
// The force can also be set at run time: `rostopic pub /jr3_sim/set_fz std_msgs/Float64 40`.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>

#include "force_profile.hpp"

namespace {

struct Options {
  double rate = 200.0;
  double fz = 5.0;
  robodoc::ForceProfile profile;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "jr3_sim");
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--rate" && has_value) {
      o.rate = std::atof(argv[++i]);
    } else if (a == "--fz" && has_value) {
      o.fz = std::atof(argv[++i]);
    } else if (a == "--profile" && has_value) {
      if (!robodoc::parse_force_profile(argv[++i], o.profile)) {
        std::fprintf(stderr, "ros_robodoc_jr3: --profile wants T:FZ,T:FZ,... with increasing times\n");
        return 2;
      }
    } else {
      std::fprintf(stderr, "usage: ros_robodoc_jr3 [--rate HZ] [--fz NEWTON] [--profile T:FZ,...]\n");
      return 2;
    }
  }
  if (!(o.rate > 0 && o.rate <= 10000)) {
    std::fprintf(stderr, "ros_robodoc_jr3: --rate must be in (0, 10000] Hz\n");
    return 2;
  }

  ros::NodeHandle nh;
  ros::Publisher wrench = nh.advertise<geometry_msgs::WrenchStamped>("/jr3/wrench", 50);
  ros::Publisher diagnostics = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
  bool overridden = false;
  double fz = o.fz;
  ros::Subscriber set =
      nh.subscribe<std_msgs::Float64>("/jr3_sim/set_fz", 10, [&](const std_msgs::Float64::ConstPtr& m) {
        overridden = true;
        fz = m->data;
        ROS_INFO("jr3_sim: Fz set to %.1f N", fz);
      });

  const ros::WallTime start = ros::WallTime::now();
  ros::WallTime next_diagnostics = start;
  ros::Rate rate(o.rate);
  std::uint32_t seq = 0;
  while (ros::ok()) {
    ros::spinOnce();
    const double t = (ros::WallTime::now() - start).toSec();
    if (!overridden && !o.profile.empty()) fz = robodoc::force_at(o.profile, t);
    geometry_msgs::WrenchStamped m;
    m.header.seq = seq++;
    m.header.stamp = ros::Time::now();
    m.header.frame_id = "jr3";
    m.wrench.force.x = 0.2 * std::sin(t);
    m.wrench.force.y = 0.2 * std::cos(t);
    m.wrench.force.z = fz;
    m.wrench.torque.z = 0.01 * fz;
    wrench.publish(m);

    if (ros::WallTime::now() >= next_diagnostics) {
      next_diagnostics += ros::WallDuration(0.5);
      diagnostic_msgs::DiagnosticArray a;
      a.header.stamp = ros::Time::now();
      diagnostic_msgs::DiagnosticStatus s;
      s.name = "jr3_sim: saturation";
      s.hardware_id = "jr3";
      const double norm =
          std::sqrt(m.wrench.force.x * m.wrench.force.x + m.wrench.force.y * m.wrench.force.y + fz * fz);
      s.level = norm > robodoc::kSaturationWarning ? diagnostic_msgs::DiagnosticStatus::WARN
                                                   : diagnostic_msgs::DiagnosticStatus::OK;
      s.message = norm > robodoc::kSaturationWarning ? "force near the end of the measuring range" : "within range";
      diagnostic_msgs::KeyValue kv;
      kv.key = "force norm";
      kv.value = std::to_string(norm);
      s.values.push_back(kv);
      a.status.push_back(s);
      diagnostics.publish(a);
    }
    rate.sleep();
  }
  return 0;
}
