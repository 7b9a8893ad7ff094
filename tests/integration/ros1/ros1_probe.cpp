// A small ROS client for the integration tests: waits for a diagnostic status, publishes a value.
//
//   ros1_probe wait TOPIC NAME LEVEL TEXT TIMEOUT   a status on TOPIC whose name ends with NAME,
//                                                   with LEVEL (0-3) and TEXT in its message
//   ros1_probe float TOPIC VALUE                     publishes one std_msgs/Float64
//   ros1_probe joints TOPIC N                        publishes one sensor_msgs/JointState, N positions
//   ros1_probe status TOPIC NAME LEVEL               publishes one DiagnosticArray with that status
// Exit status: 0 success, 1 timeout (the last status seen with that name is printed), 2 usage.

#include <cstdio>
#include <cstdlib>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

void print(const diagnostic_msgs::DiagnosticStatus& s) {
  std::printf("%s level=%d message=\"%s\"\n", s.name.c_str(), static_cast<int>(s.level), s.message.c_str());
  for (const auto& kv : s.values) std::printf("    %s: %s\n", kv.key.c_str(), kv.value.c_str());
}

template <class M>
int publish_one(const std::string& topic, const M& msg) {
  ros::NodeHandle nh;
  ros::Publisher p = nh.advertise<M>(topic, 1, true);
  const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(10.0);
  while (p.getNumSubscribers() == 0 && ros::WallTime::now() < until) ros::WallDuration(0.02).sleep();
  if (p.getNumSubscribers() == 0) {
    std::fprintf(stderr, "ros1_probe: nobody subscribes to %s\n", topic.c_str());
    return 1;
  }
  p.publish(msg);
  ros::WallDuration(0.3).sleep();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "ros1_probe", ros::init_options::AnonymousName);
  ros::start();
  const std::string cmd = argc > 1 ? argv[1] : "";
  if (cmd == "wait" && argc == 7) {
    const std::string name = argv[3], text = argv[5];
    const int level = std::atoi(argv[4]);
    const double timeout = std::atof(argv[6]);
    bool found = false;
    diagnostic_msgs::DiagnosticStatus last;
    bool seen = false;
    ros::NodeHandle nh;
    ros::Subscriber s = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        argv[2], 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
          for (const auto& st : a->status) {
            if (!ends_with(st.name, name)) continue;
            last = st;
            seen = true;
            if (st.level == level && st.message.find(text) != std::string::npos) found = true;
          }
        });
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(timeout);
    while (!found && ros::ok() && ros::WallTime::now() < until) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
    if (found) {
      print(last);
      return 0;
    }
    std::printf("timeout: no status '%s' with level %d and '%s' on %s within %.1f s\n", name.c_str(), level,
                text.c_str(), argv[2], timeout);
    if (seen) {
      std::printf("last seen: ");
      print(last);
    }
    return 1;
  }
  if (cmd == "float" && argc == 4) {
    std_msgs::Float64 m;
    m.data = std::atof(argv[3]);
    return publish_one(argv[2], m);
  }
  if (cmd == "joints" && argc == 4) {
    sensor_msgs::JointState m;
    m.position.assign(static_cast<std::size_t>(std::atoi(argv[3])), 0.5);
    return publish_one(argv[2], m);
  }
  if (cmd == "status" && argc == 5) {
    diagnostic_msgs::DiagnosticArray a;
    a.header.stamp = ros::Time::now();
    diagnostic_msgs::DiagnosticStatus st;
    st.name = argv[3];
    st.level = static_cast<std::uint8_t>(std::atoi(argv[4]));
    st.message = "set by ros1_probe";
    a.status.push_back(st);
    return publish_one(argv[2], a);
  }
  std::fprintf(stderr,
               "usage: ros1_probe wait TOPIC NAME LEVEL TEXT TIMEOUT | float TOPIC VALUE | joints TOPIC N | status "
               "TOPIC NAME LEVEL\n");
  return 2;
}
