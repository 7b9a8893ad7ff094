// Fault → visibility through SAFECASS on ROS 2 over DDS (`make bench-peers`, beside the ROS 1
// figures): from the driver's sample that crosses the limit to a ROS 2 tool's /diagnostics
// reader seeing the ERROR. Two processes on this host's loopback, in one DDS domain:
// - the node: a forked child running safecass::dds::Bridge with examples/dds_robodoc/mapping.json
//   and the robodoc specs (what safecass_dds_node runs);
// - the driver and the tool: this process writes geometry_msgs/msg/WrenchStamped on rt/jr3/wrench
//   at 500 Hz (Fz 5 N) and reads rt/diagnostics with diagnostic_aggregator's QoS.
// Each onset writes Fz = 40 N (JR3's limit is 30 N) and stamps the write; the latency is the time
// until the reader sees "safecass: JR3.s_A" at ERROR. Then Fz returns to 5 N, the status clears,
// and the next onset follows 20–40 ms later, at random.
//
//   peer_dds_visibility --out FILE [--samples N] [--domain D] [--dump FILE]
// Writes {"p50_us", "p99_us", "max_us", "samples", ...} to FILE.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "measure.hpp"
#include "ros2_msgs.h"
#include "safecass/dds/bridge.hpp"
#include "safecass/dds/ros2.hpp"
#include "safecass/filters/registry.hpp"

namespace {

namespace ros2 = safecass::dds;
using namespace std::chrono_literals;

/// The node: the bridge until SIGTERM.
int run_node(int domain) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  safecass::FilterRegistry registry;
  safecass::register_builtin_filters(registry);
  safecass::dds::BridgeOptions o;
  o.domain = domain;
  auto bridge = safecass::dds::Bridge::create("examples/dds_robodoc/mapping.json", registry, nullptr, o);
  if (!bridge) {
    std::fprintf(stderr, "node: %s\n", bridge.error().message.c_str());
    return 2;
  }
  if (auto r = (*bridge)->start(); !r) {
    std::fprintf(stderr, "node: %s\n", r.error().message.c_str());
    return 3;
  }
  int sig = 0;
  sigwait(&set, &sig);
  (*bridge)->stop();
  return 0;
}

/// The level the tool last saw for "safecass: JR3.s_A" (-1: none yet), and when.
std::atomic<int> g_level{-1};
std::atomic<std::int64_t> g_seen_ns{0};

void read_diagnostics(dds_entity_t reader, dds_entity_t waitset, const std::atomic<bool>& stop) {
  while (!stop) {
    dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
    void* samples[8] = {};
    dds_sample_info_t infos[8];
    dds_return_t n;
    while ((n = dds_take(reader, samples, infos, 8, 8)) > 0) {
      const std::int64_t now = peers::now_ns();
      for (dds_return_t k = 0; k < n; ++k) {
        if (!infos[k].valid_data) continue;
        const auto* a = static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[k]);
        for (std::uint32_t s = 0; s < a->status_._length; ++s) {
          if (std::strcmp(a->status_._buffer[s].name_, "safecass: JR3.s_A") != 0) continue;
          const int level = a->status_._buffer[s].level_;
          if (level != g_level.load()) g_seen_ns.store(now);
          g_level.store(level);
        }
      }
      dds_return_loan(reader, samples, n);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "peer-dds-visibility.json", dump;
  int samples = 2000;
  int domain = 90 + static_cast<int>(::getpid() % 100);
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--out") {
      out = argv[i + 1];
    } else if (a == "--samples") {
      samples = std::atoi(argv[i + 1]);
    } else if (a == "--domain") {
      domain = std::atoi(argv[i + 1]);
    } else if (a == "--dump") {
      dump = argv[i + 1];
    } else {
      std::fprintf(stderr, "usage: peer_dds_visibility --out FILE [--samples N] [--domain D] [--dump FILE]\n");
      return 2;
    }
  }
  // Fork before any DDS call: the child is the node.
  const pid_t node = ::fork();
  if (node == 0) return run_node(domain);

  auto joined = ros2::join(domain);
  if (!joined) {
    std::fprintf(stderr, "peer_dds_visibility: %s\n", joined.error().message.c_str());
    return 3;
  }
  const dds_entity_t pp = joined->participant;
  dds_qos_t* q = ros2::qos();
  const dds_entity_t wt = dds_create_topic(pp, &geometry_msgs_msg_dds__WrenchStamped__desc,
                                           ros2::dds_topic("/jr3/wrench").c_str(), nullptr, nullptr);
  const dds_entity_t writer = dds_create_writer(pp, wt, q, nullptr);
  dds_delete_qos(q);
  q = ros2::qos(ros2::kDiagnosticsReaderDepth);
  const dds_entity_t dt = dds_create_topic(pp, &diagnostic_msgs_msg_dds__DiagnosticArray__desc,
                                           ros2::dds_topic("/diagnostics").c_str(), nullptr, nullptr);
  const dds_entity_t reader = dds_create_reader(pp, dt, q, nullptr);
  dds_delete_qos(q);
  const dds_entity_t waitset = dds_create_waitset(pp);
  dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(waitset, reader, 0);
  std::atomic<bool> stop{false};
  std::thread tool([&] { read_diagnostics(reader, waitset, stop); });

  char frame[] = "jr3";
  auto write = [&](double fz) {
    geometry_msgs_msg_dds__WrenchStamped_ m{};
    m.header_.frame_id_ = frame;
    m.wrench_.force_ = {0.0, 0.0, fz};
    dds_write(writer, &m);
  };
  // The driver's 500 Hz loop; `until` says when the current phase is over.
  auto drive = [&](double fz, auto until, std::chrono::steady_clock::duration limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    auto next = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() < end) {
      write(fz);
      if (until()) return true;
      next += 2ms;
      std::this_thread::sleep_until(next);
    }
    return false;
  };
  std::vector<double> latencies;
  int code = 0;
  std::mt19937 random(7);
  std::uniform_int_distribution<int> pause_ms(20, 40);
  if (!drive(
          5.0, [] { return g_level.load() == 0; }, 30s)) {
    std::fprintf(stderr, "peer_dds_visibility: the node's /diagnostics never showed JR3.s_A OK\n");
    code = 1;
  }
  while (code == 0 && static_cast<int>(latencies.size()) < samples) {
    const auto pause_end = std::chrono::steady_clock::now() + std::chrono::milliseconds(pause_ms(random));
    drive(
        5.0, [&] { return std::chrono::steady_clock::now() >= pause_end; }, 1s);
    const std::int64_t onset = peers::now_ns();
    write(40.0);
    if (!drive(
            40.0, [] { return g_level.load() == 2; }, 5s)) {
      std::fprintf(stderr, "peer_dds_visibility: no ERROR within 5 s of an onset\n");
      code = 1;
      break;
    }
    latencies.push_back(static_cast<double>(g_seen_ns.load() - onset) / 1000.0);
    if (!drive(
            5.0, [] { return g_level.load() == 0; }, 5s)) {
      std::fprintf(stderr, "peer_dds_visibility: the ERROR did not clear within 5 s\n");
      code = 1;
    }
  }
  stop = true;
  tool.join();
  dds_delete(pp);
  ::kill(node, SIGTERM);
  int status = 0;
  ::waitpid(node, &status, 0);
  if (!dump.empty()) {
    std::ofstream d(dump);
    for (double us : latencies) d << us << "\n";
  }
  std::ofstream f(out);
  f << "{" << peers::latency_members(latencies)
    << ", \"what\": \"driver's sample over the limit -> /diagnostics reader sees ERROR (safecass_dds_node, Cyclone "
       "DDS, loopback)\"}\n";
  std::printf("dds visibility: %zu samples, p50 %.0f us, p99 %.0f us\n", latencies.size(),
              peers::percentile(latencies, 0.5), peers::percentile(latencies, 0.99));
  return code;
}
