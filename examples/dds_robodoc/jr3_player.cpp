// A simulated JR3 force sensor as a ROS 2 driver would put it on the wire (it knows nothing of
// SAFECASS): geometry_msgs/msg/WrenchStamped on /jr3/wrench (DDS topic rt/jr3/wrench) and, like a
// driver using diagnostic_updater, its own health on /diagnostics ("jr3_sim: saturation" is WARN
// above 38 N). Plain Cyclone DDS with the IDL of extensions/dds, ROS 2's QoS.
//
// Usage: dds_robodoc_jr3 [--rate HZ] [--fz NEWTON] [--profile T:FZ,...] [--seconds S]
//                        [--domain N] [--as-float64]
//   --profile     Fz over time (seconds since start), linear between points, held after the last.
//   --seconds     stop after S seconds (default: until SIGINT/SIGTERM).
//   --as-float64  publish std_msgs/msg/Float64 (Fz) on the same topic: a topic of the wrong type.
// The domain is --domain, else ROS_DOMAIN_ID, else 0; the participant stays on 127.0.0.1 unless
// CYCLONEDDS_URI configures Cyclone DDS.

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "force_profile.hpp"
#include "ros2_msgs.h"
#include "safecass/dds/ros2.hpp"

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

builtin_interfaces_msg_dds__Time_ wall_time() {
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  return {static_cast<std::int32_t>(ns / 1000000000), static_cast<std::uint32_t>(ns % 1000000000)};
}

int usage(const char* why) {
  std::fprintf(stderr,
               "dds_robodoc_jr3: %s\nusage: dds_robodoc_jr3 [--rate HZ] [--fz NEWTON] [--profile T:FZ,...] "
               "[--seconds S] [--domain N] [--as-float64]\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  namespace ros2 = safecass::dds;
  double rate = 200.0, fz = 5.0, seconds = 0.0;
  int domain = -1;
  bool as_float64 = false;
  robodoc::ForceProfile profile;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--as-float64") {
      as_float64 = true;
    } else if (a == "--rate" && has_value) {
      rate = std::atof(argv[++i]);
    } else if (a == "--fz" && has_value) {
      fz = std::atof(argv[++i]);
    } else if (a == "--seconds" && has_value) {
      seconds = std::atof(argv[++i]);
    } else if (a == "--domain" && has_value) {
      domain = std::atoi(argv[++i]);
    } else if (a == "--profile" && has_value) {
      if (!robodoc::parse_force_profile(argv[++i], profile))
        return usage("--profile wants T:FZ,... with increasing times");
    } else {
      return usage(("unknown or incomplete option '" + a + "'").c_str());
    }
  }
  if (!(rate > 0 && rate <= 10000)) return usage("--rate must be in (0, 10000] Hz");
  auto id = ros2::domain_id(domain);
  if (!id) return usage(id.error().message.c_str());
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  auto joined = ros2::join(domain);
  if (!joined) {
    std::fprintf(stderr, "%s: %s\n", "dds_robodoc_jr3", joined.error().message.c_str());
    return 3;
  }
  const dds_entity_t pp = joined->participant;
  dds_qos_t* qos = ros2::qos();
  const std::string wrench_name = ros2::dds_topic("/jr3/wrench");
  const dds_entity_t wrench_topic =
      dds_create_topic(pp, as_float64 ? &std_msgs_msg_dds__Float64__desc : &geometry_msgs_msg_dds__WrenchStamped__desc,
                       wrench_name.c_str(), nullptr, nullptr);
  const dds_entity_t wrench = dds_create_writer(pp, wrench_topic, qos, nullptr);
  dds_delete_qos(qos);
  qos = ros2::qos(ros2::kDiagnosticsWriterDepth);
  const std::string diag_name = ros2::dds_topic("/diagnostics");
  const dds_entity_t diag_topic =
      dds_create_topic(pp, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, diag_name.c_str(), nullptr, nullptr);
  const dds_entity_t diagnostics = dds_create_writer(pp, diag_topic, qos, nullptr);
  dds_delete_qos(qos);
  if (wrench < 0 || diagnostics < 0) {
    std::fprintf(stderr, "dds_robodoc_jr3: DDS writer: %s\n", dds_strretcode(wrench < 0 ? wrench : diagnostics));
    dds_delete(pp);
    return 3;
  }

  using Steady = std::chrono::steady_clock;
  const auto start = Steady::now();
  const auto period = std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(1.0 / rate));
  auto next = start;
  auto next_diagnostics = start;
  char frame[] = "jr3";
  while (!g_stop) {
    const double t = std::chrono::duration<double>(Steady::now() - start).count();
    if (seconds > 0 && t >= seconds) break;
    const double force = profile.empty() ? fz : robodoc::force_at(profile, t);
    const double fx = 0.2 * std::sin(t), fy = 0.2 * std::cos(t);
    if (as_float64) {
      const std_msgs_msg_dds__Float64_ m{force};
      dds_write(wrench, &m);
    } else {
      geometry_msgs_msg_dds__WrenchStamped_ m{};
      m.header_.stamp_ = wall_time();
      m.header_.frame_id_ = frame;
      m.wrench_.force_ = {fx, fy, force};
      m.wrench_.torque_ = {0.0, 0.0, 0.01 * force};
      dds_write(wrench, &m);
    }
    if (Steady::now() >= next_diagnostics) {
      next_diagnostics += std::chrono::milliseconds(500);
      const double norm = std::sqrt(fx * fx + fy * fy + force * force);
      const bool warn = norm > robodoc::kSaturationWarning;
      std::string norm_text = std::to_string(norm);
      char key[] = "force norm", name[] = "jr3_sim: saturation", hw[] = "jr3";
      char ok_text[] = "within range", warn_text[] = "force near the end of the measuring range";
      diagnostic_msgs_msg_dds__KeyValue_ kv{key, norm_text.data()};
      diagnostic_msgs_msg_dds__DiagnosticStatus_ s{};
      s.level_ = warn ? 1 : 0;
      s.name_ = name;
      s.message_ = warn ? warn_text : ok_text;
      s.hardware_id_ = hw;
      s.values_ = {1, 1, &kv, false};
      diagnostic_msgs_msg_dds__DiagnosticArray_ a{};
      a.header_.stamp_ = wall_time();
      a.header_.frame_id_ = frame;
      a.status_ = {1, 1, &s, false};
      dds_write(diagnostics, &a);
    }
    next += period;
    std::this_thread::sleep_until(next);
  }
  dds_delete(pp);
  return 0;
}
