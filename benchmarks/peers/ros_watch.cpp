// The cost of watching, ROS's side (`make bench-peers`, item 2): diagnostic_aggregator (started
// by the harness, PID given) fed N component statuses that each change R times a second.
//
//   peer_ros_watch --watch-pid PID --out FILE [--components N] [--rate R] [--seconds S]
//
// R times a second this node publishes on /diagnostics one DiagnosticArray holding the status of
// every component C0..C{N-1} (what one diagnostic_updater with N tasks sends; what SAFECASS sends
// per publishing cycle is the same N statuses in one batch): "C<k>/Status", level ERROR with the
// root event, origin and onset time on one cycle, OK on the next, so each cycle changes all N.
// The aggregator's CPU time (user + system, /proc/PID/stat) is read when the feed starts and
// after it ends (plus 1.5 s: at its default pub_rate of 1 Hz it reads /diagnostics once a
// second); its RSS (/proc/PID/status) before the first status and at the end.
// Writes {"cpu_s", "updates", "cpu_s_per_10k_updates", "rss_bytes", "bytes_per_item", ...}.

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "measure.hpp"

using namespace std::chrono_literals;

int main(int argc, char** argv) {
  std::string out_path = "peer-ros-watch.json";
  int pid = 0, components = 1000;
  double rate = 10.0, seconds = 30.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--out")
      out_path = argv[i + 1];
    else if (key == "--watch-pid")
      pid = std::atoi(argv[i + 1]);
    else if (key == "--components")
      components = std::clamp(std::atoi(argv[i + 1]), 1, 100000);
    else if (key == "--rate")
      rate = std::clamp(std::atof(argv[i + 1]), 0.1, 1000.0);
    else if (key == "--seconds")
      seconds = std::max(1.0, std::atof(argv[i + 1]));
    else {
      std::fprintf(stderr, "peer_ros_watch: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (pid <= 0 || peers::cpu_seconds(pid) < 0) {
    std::fprintf(stderr, "peer_ros_watch: --watch-pid PID of a running diagnostic_aggregator is required\n");
    return 2;
  }
  ros::init(argc, argv, "peer_watch_feeder", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 100);
  for (int i = 0; i < 1000 && pub.getNumSubscribers() == 0; ++i) std::this_thread::sleep_for(10ms);
  if (pub.getNumSubscribers() == 0) {
    std::fprintf(stderr, "peer_ros_watch: the aggregator does not subscribe to /diagnostics\n");
    return 1;
  }
  std::this_thread::sleep_for(1500ms);
  const double rss_empty = peers::status_bytes(pid, "VmRSS");

  diagnostic_msgs::DiagnosticArray array;
  array.status.resize(static_cast<std::size_t>(components));
  bool raised = false;
  std::int64_t onset = 0;
  auto cycle = [&] {
    raised = !raised;
    if (raised) onset = peers::now_ns();
    for (int k = 0; k < components; ++k) {
      diagnostic_msgs::DiagnosticStatus& s = array.status[static_cast<std::size_t>(k)];
      const std::string c = "C" + std::to_string(k);
      s.name = c + "/Status";
      s.hardware_id = c + ".s_A";
      s.level = raised ? diagnostic_msgs::DiagnosticStatus::ERROR : diagnostic_msgs::DiagnosticStatus::OK;
      s.message = raised ? "EVT_FAULT" : "Normal";
      s.values.resize(1);
      s.values[0].key = "onset_ns";
      s.values[0].value = std::to_string(raised ? onset : 0);
    }
    array.header.stamp = ros::Time::now();
    pub.publish(array);
  };
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate));
  // Warm-up: the aggregator knows every item before the measurement.
  const auto warm_until = std::chrono::steady_clock::now() + 2s;
  for (auto next = std::chrono::steady_clock::now(); next < warm_until; next += period) {
    std::this_thread::sleep_until(next);
    cycle();
  }
  std::this_thread::sleep_for(1500ms);
  const double cpu0 = peers::cpu_seconds(pid);
  const std::int64_t t0 = peers::now_ns();
  std::uint64_t updates = 0;
  const auto start = std::chrono::steady_clock::now();
  const auto until =
      start + std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds));
  for (auto next = start; next < until; next += period) {
    std::this_thread::sleep_until(next);
    cycle();
    updates += static_cast<std::uint64_t>(components);
  }
  const double feed_wall = static_cast<double>(peers::now_ns() - t0) / 1e9;
  std::this_thread::sleep_for(1500ms);  // its next read of /diagnostics and the publication after it
  const double cpu1 = peers::cpu_seconds(pid);
  const double wall = static_cast<double>(peers::now_ns() - t0) / 1e9;
  const double rss = peers::status_bytes(pid, "VmRSS");
  const double hwm = peers::status_bytes(pid, "VmHWM");
  const double cpu = cpu1 - cpu0;
  char json[1024];
  std::snprintf(json, sizeof json,
                "{\n  \"components\": %d,\n  \"rate_hz\": %.1f,\n  \"seconds\": %.2f,\n  \"wall_s\": %.2f,\n"
                "  \"updates\": %llu,\n  \"cpu_s\": %.3f,\n  \"cpu_s_per_10k_updates\": %.5f,\n"
                "  \"cpu_percent_of_one_core\": %.2f,\n  \"rss_bytes\": %.0f,\n  \"rss_before_items_bytes\": %.0f,\n"
                "  \"hwm_bytes\": %.0f,\n  \"bytes_per_item\": %.0f,\n"
                "  \"watcher\": \"diagnostic_aggregator (Debian), defaults, one GenericAnalyzer\"\n}\n",
                components, rate, feed_wall, wall, static_cast<unsigned long long>(updates), cpu,
                updates > 0 ? cpu / static_cast<double>(updates) * 10000.0 : 0.0, wall > 0 ? 100.0 * cpu / wall : 0.0,
                rss, rss_empty, hwm, (rss - rss_empty) / components);
  std::ofstream(out_path) << json;
  std::printf("%s", json);
  ros::shutdown();
  return updates > 0 ? 0 : 1;
}
