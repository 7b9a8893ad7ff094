// safecass_dds_node SYSTEM --mapping FILE [--domain N] [--network] [--record HISTORY.jsonl]
//                   [--max-bytes N]
//
// The ROS 2 counterpart of safecass_ros1_node, on Cyclone DDS without rclcpp: it shadows the ROS 2
// nodes named in the mapping file with the Generic Component Model of SYSTEM, feeds their topics
// (rt/...) into signals, publishes the GCM states on rt/diagnostics as
// diagnostic_msgs/msg/DiagnosticArray and turns other nodes' diagnostics into events. The mapping
// file is the ROS 1 extension's format (docs/frameworks.md); SYSTEM replaces its "system".
// The domain is --domain, else ROS_DOMAIN_ID, else 0. The participant stays on 127.0.0.1 unless
// CYCLONEDDS_URI configures Cyclone DDS or --network asks for Cyclone's defaults.
// --record: the history and the inputs, for `safecass replay` (as safecass_ros1_node).
// Runs until SIGINT or SIGTERM. Exit status: 0 after a normal shutdown, 2 for bad arguments, a bad
// mapping or spec or an incomplete recording, 3 when DDS refuses to start.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "safecass/dds/bridge.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/ros_common/recording.hpp"

namespace {

int usage(const char* why) {
  std::fprintf(stderr,
               "safecass_dds_node: %s\n"
               "usage: safecass_dds_node SYSTEM --mapping FILE [--domain N] [--network] [--record HISTORY.jsonl] "
               "[--max-bytes N]\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return usage("the first argument is the system spec");
  safecass::dds::BridgeOptions options;
  options.system = argv[1];
  std::string mapping, record;
  safecass::FileLimits limits;
  for (int i = 2; i < argc; ++i) {
    const std::string flag = argv[i];
    const bool has_value = i + 1 < argc;
    if (flag == "--network") {
      options.loopback = false;
    } else if (!has_value) {
      return usage(("'" + flag + "' needs a value or is unknown").c_str());
    } else if (flag == "--mapping") {
      mapping = argv[++i];
    } else if (flag == "--record") {
      record = argv[++i];
    } else if (flag == "--domain") {
      const char* text = argv[++i];
      char* end = nullptr;
      const long d = std::strtol(text, &end, 10);
      if (*text == '\0' || *end != '\0' || d < 0 || d > 232) return usage("--domain takes an integer in [0, 232]");
      options.domain = static_cast<int>(d);
    } else if (flag == "--max-bytes") {
      const std::string text = argv[++i];
      if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
        return usage("--max-bytes takes a number of bytes");
      limits.max_bytes = std::strtoull(text.c_str(), nullptr, 10);
    } else {
      return usage(("unknown option '" + flag + "'").c_str());
    }
  }
  if (mapping.empty()) return usage("--mapping FILE is required");

  // SIGINT/SIGTERM are waited for below; block them before any thread starts so no thread takes them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  const safecass::FilterRegistry& registry = safecass::builtin_filters();
  auto bridge = safecass::dds::Bridge::create(mapping, registry, nullptr, options);
  if (!bridge) {
    std::fprintf(stderr, "%s\n", bridge.error().message.c_str());
    return 2;
  }
  std::unique_ptr<safecass::ros_common::NodeRecording> recording;
  if (!record.empty()) {
    auto r = safecass::ros_common::NodeRecording::open((*bridge)->shadow(), record, limits);
    if (!r) {
      std::fprintf(stderr, "safecass_dds_node: %s\n", r.error().message.c_str());
      return 2;
    }
    recording = std::move(*r);
  }
  if (auto r = (*bridge)->start(); !r) {
    std::fprintf(stderr, "safecass_dds_node: %s\n", r.error().message.c_str());
    return 3;
  }
  std::fprintf(stderr, "safecass_dds_node: %zu components of '%s' on ROS 2 domain %d\n",
               (*bridge)->coordinator().structure().component_count(),
               std::string((*bridge)->coordinator().structure().name()).c_str(), (*bridge)->domain());
  int signal = 0;
  sigwait(&stop_signals, &signal);
  (*bridge)->stop();
  return safecass::ros_common::NodeRecording::finish(recording);
}
