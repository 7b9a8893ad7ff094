// /diagnostics as a ROS 2 tool sees it, written from the same IDL: a plain Cyclone DDS reader of
// diagnostic_msgs/msg/DiagnosticArray on rt/diagnostics with diagnostic_aggregator's QoS. It prints
// one line per status whose level or message changed: "t=1.23s ERROR safecass: JR3: Error: ...".
//
// Usage: dds_diagnostics_echo [--prefix TEXT] [--seconds S] [--domain N]
//   --prefix   only statuses whose name starts with TEXT
//   --seconds  stop after S seconds (default: until SIGINT/SIGTERM)

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "ros2_msgs.h"
#include "safecass/dds/ros2.hpp"

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

const char* level_name(unsigned level) {
  switch (level) {
    case 0: return "OK";
    case 1: return "WARN";
    case 2: return "ERROR";
    case 3: return "STALE";
    default: return "?";
  }
}

}  // namespace

int main(int argc, char** argv) {
  namespace ros2 = safecass::dds;
  std::string prefix;
  double seconds = 0.0;
  int domain = -1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--prefix") {
      prefix = argv[i + 1];
    } else if (a == "--seconds") {
      seconds = std::atof(argv[i + 1]);
    } else if (a == "--domain") {
      domain = std::atoi(argv[i + 1]);
    } else {
      std::fprintf(stderr, "usage: dds_diagnostics_echo [--prefix TEXT] [--seconds S] [--domain N]\n");
      return 2;
    }
  }
  auto id = ros2::domain_id(domain);
  if (!id) {
    std::fprintf(stderr, "dds_diagnostics_echo: %s\n", id.error().message.c_str());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  auto joined = ros2::join(domain);
  if (!joined) {
    std::fprintf(stderr, "%s: %s\n", "dds_diagnostics_echo", joined.error().message.c_str());
    return 3;
  }
  const dds_entity_t pp = joined->participant;
  const std::string name = ros2::dds_topic("/diagnostics");
  const dds_entity_t topic =
      dds_create_topic(pp, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, name.c_str(), nullptr, nullptr);
  dds_qos_t* qos = ros2::qos(ros2::kDiagnosticsReaderDepth);
  const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
  dds_delete_qos(qos);
  const dds_entity_t ws = dds_create_waitset(pp);
  dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(ws, reader, 0);

  const auto start = std::chrono::steady_clock::now();
  std::map<std::string, std::string> last;  // status name → "LEVEL message"
  while (!g_stop) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > 0 && t >= seconds) break;
    dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(100));
    void* samples[8] = {};
    dds_sample_info_t infos[8];
    dds_return_t n;
    while ((n = dds_take(reader, samples, infos, 8, 8)) > 0) {
      for (dds_return_t k = 0; k < n; ++k) {
        if (!infos[k].valid_data) continue;
        const auto* a = static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[k]);
        for (std::uint32_t s = 0; s < a->status_._length; ++s) {
          const auto& st = a->status_._buffer[s];
          const std::string status_name = st.name_ != nullptr ? st.name_ : "";
          if (status_name.compare(0, prefix.size(), prefix) != 0) continue;
          std::string line = std::string(level_name(st.level_)) + " " + (st.message_ != nullptr ? st.message_ : "");
          if (last[status_name] == line) continue;
          last[status_name] = line;
          const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          std::printf("t=%.2fs %-5s %s: %s\n", now, level_name(st.level_), status_name.c_str(),
                      st.message_ != nullptr ? st.message_ : "");
        }
      }
      dds_return_loan(reader, samples, n);
      std::fflush(stdout);
    }
  }
  dds_delete(pp);
  return 0;
}
