// Fault → remote visibility through ROS 1 (`make bench-peers`, item 1). Two processes on a
// running ROS master (ROS_MASTER_URI): a publisher with the fault and a subscriber that sees it.
//
//   peer_ros_visibility --mode raw  --out FILE [--samples N]
//   peer_ros_visibility --mode diag --out FILE [--seconds S] [--items K] [--on-ms A] [--off-ms B]
//                       [--period P] [--loop-hz H]
//   --dump FILE: also every latency in µs, one a line, in the order seen
//
// Every message carries what SAFECASS sends for a fault: a diagnostic_msgs/DiagnosticStatus named
// after the interface ("JR3/ForceData"), its level, the root event as message, the origin as
// hardware_id and the onset time (ns, the host's monotonic clock) as a value.
// - raw: a plain roscpp topic. One onset every 2 ms followed 1 ms later by its completion, as in
//   bench_middleware; each change published at once in a DiagnosticArray of that one status. The
//   subscriber asks for TCP_NODELAY (roscpp's advice for latency).
// - diag: the ROS diagnostics pipeline. The publisher's diagnostic_updater::Updater has one task
//   per item and publishes /diagnostics every `~diagnostic_period` (--period P; without it the
//   updater's default, 1 s), its update() called from a loop at H Hz (default 1000, a control
//   loop). diagnostic_aggregator (started by the harness with its own pub_rate) republishes on
//   /diagnostics_agg; the subscriber watches that. K items fault independently (off for B to
//   1.5·B ms, then on for A to 1.5·A ms, at random), so onsets fall at every phase of the
//   updater's and the aggregator's periods and K samples accrue in parallel.
// Latency: onset time → the subscriber's callback seeing that item at ERROR for that onset.
// Writes {"p50_us", "p99_us", "max_us", "samples", "onsets", ...} to FILE.

#include <diagnostic_msgs/DiagnosticArray.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "measure.hpp"

namespace {

using namespace std::chrono_literals;

struct Options {
  std::string mode = "raw";
  std::string out = "peer-ros-visibility.json";
  std::string dump;  ///< every latency (µs), one a line, in the order seen
  int samples = 2000;
  double seconds = 60.0;
  int items = 1;
  double on_ms = 2500, off_ms = 2500;
  double period = -1.0;  ///< < 0: the updater's default
  double loop_hz = 1000.0;
};

std::string item_name(int i) { return "peer_item_" + std::to_string(i); }

diagnostic_msgs::DiagnosticStatus status_of(const std::string& name, bool active, std::int64_t onset) {
  diagnostic_msgs::DiagnosticStatus s;
  s.name = name;
  s.hardware_id = "JR3.s_A";
  s.level = active ? diagnostic_msgs::DiagnosticStatus::ERROR : diagnostic_msgs::DiagnosticStatus::OK;
  s.message = active ? "EVT_FORCE_ERROR" : "Normal";
  diagnostic_msgs::KeyValue kv;
  kv.key = "onset_ns";
  kv.value = std::to_string(onset);
  s.values.push_back(kv);
  return s;
}

void write_text(int fd, const std::string& text) { (void)!::write(fd, text.data(), text.size()); }
std::string read_line(int fd) {
  std::string line;
  char c = 0;
  while (::read(fd, &c, 1) == 1 && c != '\n') line += c;
  return line;
}

/// The publisher process. Answers "r\n" when ready, waits for "g", publishes, then writes
/// "<onsets>\n" and waits for its input to close.
int publisher(const Options& o, int in, int out) {
  int argc = 1;
  char name[] = "peer_publisher";
  char* argv[] = {name, nullptr};
  ros::init(argc, argv, o.mode == "raw" ? "peer_raw_publisher" : "peer_diag_publisher",
            ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  std::uint64_t onsets = 0;
  if (o.mode == "raw") {
    ros::Publisher pub = nh.advertise<diagnostic_msgs::DiagnosticArray>("/peer_fault", 100);
    for (int i = 0; i < 1000 && pub.getNumSubscribers() == 0; ++i) std::this_thread::sleep_for(10ms);
    write_text(out, "r\n");
    char go = 0;
    if (::read(in, &go, 1) != 1) return 2;
    diagnostic_msgs::DiagnosticArray array;
    for (int i = 0; i < o.samples; ++i) {
      const std::int64_t t = peers::now_ns();
      array.status = {status_of("JR3/ForceData", true, t)};
      pub.publish(array);
      ++onsets;
      std::this_thread::sleep_for(1ms);
      array.status = {status_of("JR3/ForceData", false, t)};
      pub.publish(array);
      std::this_thread::sleep_for(1ms);
    }
    std::this_thread::sleep_for(300ms);
  } else {
    ros::NodeHandle private_nh("~");
    if (o.period >= 0) private_nh.setParam("diagnostic_period", o.period);
    diagnostic_updater::Updater updater;
    updater.setHardwareID("none");
    struct Item {
      bool active = false;
      std::int64_t onset = 0;
      std::int64_t next = 0;  ///< next toggle
    };
    std::vector<Item> items(static_cast<std::size_t>(o.items));
    std::mutex mutex;
    for (int i = 0; i < o.items; ++i) {
      updater.add(item_name(i), [&items, &mutex, i](diagnostic_updater::DiagnosticStatusWrapper& stat) {
        std::lock_guard lock(mutex);
        const Item& it = items[static_cast<std::size_t>(i)];
        const auto s = status_of(item_name(i), it.active, it.onset);
        stat.summary(s.level, s.message);
        stat.add("onset_ns", s.values[0].value);
      });
    }
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> jitter(1.0, 1.5);
    std::uniform_real_distribution<double> phase(0.0, 1.0);
    // Let the aggregator see every item once before faults start.
    updater.force_update();
    write_text(out, "r\n");
    char go = 0;
    if (::read(in, &go, 1) != 1) return 2;
    // The first onsets spread over one off time from now: every phase of the periods.
    const std::int64_t start = peers::now_ns();
    for (Item& it : items) it.next = start + static_cast<std::int64_t>(o.off_ms * 1e6 * phase(rng));
    const std::int64_t stop_onsets = peers::now_ns() + static_cast<std::int64_t>(o.seconds * 1e9);
    const auto tick = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / o.loop_hz));
    // Every item ends off; the last onsets have on_ms to be seen.
    const std::int64_t stop_all = stop_onsets + static_cast<std::int64_t>(o.on_ms * 1.5e6) + 500'000'000;
    for (auto next = std::chrono::steady_clock::now(); peers::now_ns() < stop_all; next += tick) {
      std::this_thread::sleep_until(next);
      const std::int64_t now = peers::now_ns();
      {
        std::lock_guard lock(mutex);
        for (Item& it : items) {
          if (now < it.next) continue;
          if (it.active) {
            it.active = false;
            it.next = now + static_cast<std::int64_t>(o.off_ms * 1e6 * jitter(rng));
          } else if (now < stop_onsets) {
            it.active = true;
            it.onset = now;
            ++onsets;
            it.next = now + static_cast<std::int64_t>(o.on_ms * 1e6 * jitter(rng));
          }
        }
      }
      updater.update();
    }
  }
  write_text(out, std::to_string(onsets) + "\n");
  char c = 0;
  while (::read(in, &c, 1) == 1) {
  }
  spinner.stop();
  ros::shutdown();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* v = argv[i + 1];
    if (key == "--mode")
      o.mode = v;
    else if (key == "--out")
      o.out = v;
    else if (key == "--dump")
      o.dump = v;
    else if (key == "--samples")
      o.samples = std::max(10, std::atoi(v));
    else if (key == "--seconds")
      o.seconds = std::max(1.0, std::atof(v));
    else if (key == "--items")
      o.items = std::clamp(std::atoi(v), 1, 10000);
    else if (key == "--on-ms")
      o.on_ms = std::max(1.0, std::atof(v));
    else if (key == "--off-ms")
      o.off_ms = std::max(1.0, std::atof(v));
    else if (key == "--period")
      o.period = std::atof(v);
    else if (key == "--loop-hz")
      o.loop_hz = std::clamp(std::atof(v), 1.0, 10000.0);
    else {
      std::fprintf(stderr, "peer_ros_visibility: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (o.mode != "raw" && o.mode != "diag") {
    std::fprintf(stderr, "peer_ros_visibility: --mode is raw or diag\n");
    return 2;
  }
  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return 2;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(publisher(o, to_child[0], to_parent[1]));
  }
  ::close(to_child[0]);
  ::close(to_parent[1]);
  int child_in = to_child[1];
  struct Reap {
    pid_t pid;
    int* fd;
    ~Reap() {
      if (*fd >= 0) ::close(*fd);
      for (int i = 0; i < 300 && ::waitpid(pid, nullptr, WNOHANG) != pid; ++i) std::this_thread::sleep_for(10ms);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, WNOHANG);
    }
  } reap{child, &child_in};

  ros::init(argc, argv, o.mode == "raw" ? "peer_raw_subscriber" : "peer_diag_subscriber",
            ros::init_options::NoSigintHandler | ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  std::mutex mutex;
  std::vector<double> latencies;
  std::map<std::string, std::int64_t> seen;  ///< last onset seen per item
  std::atomic<bool> measuring{false};
  auto on_array = [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
    const std::int64_t at = peers::now_ns();
    if (!measuring.load()) return;
    for (const auto& s : array->status) {
      if (s.level != diagnostic_msgs::DiagnosticStatus::ERROR) continue;
      std::int64_t onset = 0;
      for (const auto& kv : s.values) {
        if (kv.key == "onset_ns") onset = std::atoll(kv.value.c_str());
      }
      if (onset == 0) continue;
      std::lock_guard lock(mutex);
      std::int64_t& last = seen[s.name];
      if (onset == last) continue;
      last = onset;
      latencies.push_back(static_cast<double>(at - onset) / 1000.0);
    }
  };
  ros::Subscriber sub = o.mode == "raw"
                            ? nh.subscribe<diagnostic_msgs::DiagnosticArray>(
                                  "/peer_fault", 100, on_array, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay())
                            : nh.subscribe<diagnostic_msgs::DiagnosticArray>("/diagnostics_agg", 100, on_array);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  if (read_line(to_parent[0]) != "r") {
    std::fprintf(stderr, "peer_ros_visibility: the publisher did not start\n");
    return 1;
  }
  // The subscription settles (and, for diag, the aggregator has seen every item).
  std::this_thread::sleep_for(o.mode == "raw" ? 300ms : 3000ms);
  measuring.store(true);
  write_text(child_in, "g");
  const std::string onsets_text = read_line(to_parent[0]);
  std::this_thread::sleep_for(o.mode == "raw" ? 100ms : 500ms);
  measuring.store(false);
  ::close(child_in);
  child_in = -1;
  spinner.stop();
  std::vector<double> copy;
  {
    std::lock_guard lock(mutex);
    copy = latencies;
  }
  const long long onsets = std::atoll(onsets_text.c_str());
  if (!o.dump.empty()) {
    std::ofstream dump(o.dump);
    for (double us : copy) dump << us << "\n";
  }
  char json[1024];
  std::snprintf(json, sizeof json,
                "{\n  %s,\n  \"onsets\": %lld,\n  \"missed\": %lld,\n  \"mode\": \"%s\",\n  \"items\": %d,\n"
                "  \"updater_period_s\": %.4f,\n  \"loop_hz\": %.0f,\n"
                "  \"transport\": \"%s\"\n}\n",
                peers::latency_members(copy).c_str(), onsets, onsets - static_cast<long long>(copy.size()),
                o.mode.c_str(), o.mode == "raw" ? 1 : o.items, o.mode == "raw" ? 0.0 : (o.period >= 0 ? o.period : 1.0),
                o.loop_hz,
                o.mode == "raw" ? "roscpp topic (TCPROS, TCP_NODELAY) on loopback, two processes"
                                : "diagnostic_updater -> /diagnostics -> diagnostic_aggregator -> /diagnostics_agg");
  std::ofstream(o.out) << json;
  std::printf("%s", json);
  ros::shutdown();
  return !copy.empty() ? 0 : 1;
}
