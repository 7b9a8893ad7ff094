// Writes a ROS 1 bag of the ros_robodoc example's force topic with the rosbag C++ API, for the
// bag replay tests (bag_replay_test.sh): write_bag OUT.bag [good|wrong_type|short_joint_state].
//   good:              /jr3/wrench at 500 Hz for 1.2 s: the force on the cutter rises from 5 N to
//                      40 N (0.2 .. 0.6 s) and falls back (0.6 .. 1.0 s); /robodoc/command at 50 Hz
//   wrong_type:        the same, with message 100 on /jr3/wrench a std_msgs/Float64 (written on the
//                      topic's WrenchStamped connection: its bytes are too short for one)
//   short_joint_state: the same, with a /robodoc/command whose position array is empty

#include <cstdio>
#include <string>

#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_bag OUT.bag good|wrong_type|short_joint_state\n");
    return 2;
  }
  const std::string variant = argv[2];
  rosbag::Bag bag;
  bag.open(argv[1], rosbag::bagmode::Write);
  const ros::Time begin(1700000000, 0);
  int wrench = 0;
  for (int i = 0; i <= 600; ++i) {  // every 2 ms
    const double t = i * 0.002;
    const ros::Time stamp = begin + ros::Duration(t);
    double fz = 5.0;
    if (t >= 0.2 && t < 0.6) fz = 5.0 + 35.0 * (t - 0.2) / 0.4;
    if (t >= 0.6 && t < 1.0) fz = 40.0 - 35.0 * (t - 0.6) / 0.4;
    ++wrench;
    if (variant == "wrong_type" && wrench == 100) {
      std_msgs::Float64 bad;
      bad.data = fz;
      bag.write("/jr3/wrench", stamp, bad);
    } else {
      geometry_msgs::WrenchStamped w;
      w.header.stamp = stamp;
      w.wrench.force.z = fz;
      bag.write("/jr3/wrench", stamp, w);
    }
    if (i % 10 == 0) {
      sensor_msgs::JointState js;
      js.header.stamp = stamp;
      if (!(variant == "short_joint_state" && i == 300)) js.position.push_back(0.1 * t);
      bag.write("/robodoc/command", stamp, js);
    }
  }
  bag.close();
  return 0;
}
