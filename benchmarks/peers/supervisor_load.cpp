// The cost of watching, SAFECASS's side (`make bench-peers`, item 2): the supervisor fed N
// component statuses that each change R times a second, through a real IceStorm.
//
//   peer_supervisor_load --ice HOST:PORT --out FILE [--components N] [--rate R] [--seconds S]
//                        [--states-only 1] [--ca DIR]
//
// --ca DIR: the key directory whose CA the IceStorm admits (scripts/start-icestorm --keys DIR);
// the run's own keys are signed by it, and the bus runs over mutual TLS as deployed.
//
// Two processes. The child hosts the supervisor (middleware::Supervisor, the one `safecass
// supervisor` runs; its output lines are counted, not formatted nor written, as the ROS
// aggregator writes none). With --states-only 1 it follows the service states only
// (`safecass supervisor --states-only`: no event records), the same content the aggregator gets. The parent is one
// coordinator of N components C0..C{N-1}, each providing Status (its service state follows the component's s_A); R
// times a second it raises (then clears) a fault on every component's s_A, so each cycle changes all N statuses: N
// state updates (batched per publishing cycle, signed) and the observer records of those transitions, as a deployed
// node sends them. The supervisor's CPU time (user + system, /proc/PID/stat) is read when the feed starts and after it
// ends (plus 300 ms to drain), and its RSS (/proc/PID/status) at the end. Writes {"cpu_s", "updates",
// "cpu_s_per_10k_updates", "rss_bytes", ...} to FILE.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "measure.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/supervisor.hpp"
#include "safecass/spec/load.hpp"

using namespace safecass;
using namespace std::chrono_literals;

namespace {

std::string system_text(int n) {
  std::string s = R"({ "safecass": 1, "system": "watch", "components": [)";
  std::string members;
  for (int k = 0; k < n; ++k) {
    const std::string c = "C" + std::to_string(k);
    s += k ? ",\n" : "\n";
    s += R"({ "component": ")" + c + R"(", "interfaces": { "provided": ["Status"], "required": [] })";
    if (k == 0) {
      s += R"(, "event": [ { "name": "EVT_FAULT", "severity": 50, "state_transition": ["N2E"] },
                           { "name": "/EVT_FAULT", "severity": 50, "state_transition": ["E2N"] } ])";
    }
    s += R"(, "service": [ { "name": "Status", "dependency": { "s_F": true, "s_A": true } } ] })";
    members += (k ? ", \"" : "\"") + c + "\"";
  }
  s += "],\n\"connections\": [],\n\"coordinators\": { \"feeder\": [" + members + "] } }";
  return s;
}

void write_text(int fd, const std::string& text) { (void)!::write(fd, text.data(), text.size()); }
char read_byte(int fd) {
  char c = 0;
  return ::read(fd, &c, 1) == 1 ? c : '\0';
}

/// The supervisor process: runs until its input closes, then writes "lines rows refused\n".
int supervisor(const spec::SystemSpec& system, const middleware::IceEndpoint& ice, const std::string& keys,
               bool states_only, int in, int out) {
  std::atomic<std::uint64_t> lines{0};
  middleware::SupervisorOptions options;
  options.ice = ice;
  options.keys_dir = keys;
  options.records = !states_only;
  options.output = [&lines](const middleware::SupervisorLine& line) {
    lines.fetch_add(1, std::memory_order_relaxed);
    // Its own notices (refusals, missed records, lost peers) go to the part's log: a failed run says why.
    if (line.kind() == middleware::SupervisorLine::Kind::Notice) std::fprintf(stderr, "%s\n", line.text().c_str());
  };
  auto sup = middleware::Supervisor::create(system, options);
  if (!sup || !(*sup)->start()) return 2;
  write_text(out, "r");
  while (read_byte(in) != '\0') {
  }
  const std::size_t rows = (*sup)->view().size();
  const std::uint64_t refused = (*sup)->messages_refused();
  (*sup)->stop();
  write_text(out, std::to_string(lines.load()) + " " + std::to_string(rows) + " " + std::to_string(refused) + "\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string ice_text, out_path = "peer-supervisor-load.json";
  int components = 1000;
  double rate = 10.0, seconds = 30.0;
  bool states_only = false;
  middleware::KeyOptions key_options = middleware::KeyOptions::replacing();
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--ice")
      ice_text = argv[i + 1];
    else if (key == "--out")
      out_path = argv[i + 1];
    else if (key == "--components")
      components = std::clamp(std::atoi(argv[i + 1]), 1, 100000);
    else if (key == "--rate")
      rate = std::clamp(std::atof(argv[i + 1]), 0.1, 1000.0);
    else if (key == "--seconds")
      seconds = std::max(1.0, std::atof(argv[i + 1]));
    else if (key == "--states-only")
      states_only = std::atoi(argv[i + 1]) != 0;
    else if (key == "--ca")
      key_options.ca_dir = argv[i + 1];
    else {
      std::fprintf(stderr, "peer_supervisor_load: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  auto ice = middleware::parse_ice_endpoint(ice_text);
  if (!ice) {
    std::fprintf(stderr, "peer_supervisor_load: %s\n", ice.error().message.c_str());
    return 2;
  }
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system_from_text(system_text(components), "watch.json", registry);
  if (!load.ok()) {
    std::fprintf(stderr, "peer_supervisor_load: the generated system does not load\n");
    return 2;
  }
  const spec::SystemSpec system = *load.system;
  char keys_template[] = "/tmp/safecass-peers-keys.XXXXXX";
  if (::mkdtemp(keys_template) == nullptr) return 2;
  const std::string keys = keys_template;
  struct RemoveKeys {
    std::string dir;
    ~RemoveKeys() { std::filesystem::remove_all(dir); }
  } remove_keys{keys};
  if (auto made = middleware::create_bus_keys(system, keys, key_options); !made) {
    std::fprintf(stderr, "peer_supervisor_load: %s\n", made.error().message.c_str());
    return 2;
  }

  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return 2;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(supervisor(system, *ice, keys, states_only, to_child[0], to_parent[1]));
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
  if (read_byte(to_parent[0]) != 'r') {
    std::fprintf(stderr, "peer_supervisor_load: the supervisor did not start\n");
    return 1;
  }

  // The feeder: one coordinator with every component.
  middleware::HostClock clock;
  Coordinator co("feeder", &clock);
  Monitor monitor(co, registry);
  if (!spec::instantiate(system, co, monitor, "feeder")) return 2;
  middleware::NodeOptions options;
  options.ice = *ice;
  options.keys_dir = keys;
  options.log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  auto node = middleware::CoordinatorNode::create(co, monitor, registry, system, "feeder", options);
  if (!node || !(*node)->start()) return 2;
  for (int i = 0; i < 500 && !(*node)->stats().connected; ++i) std::this_thread::sleep_for(10ms);
  if (!(*node)->stats().connected) {
    std::fprintf(stderr, "peer_supervisor_load: the feeder cannot join IceStorm at %s\n", ice_text.c_str());
    return 1;
  }
  std::vector<MachineId> targets;
  for (int k = 0; k < components; ++k)
    targets.push_back(*co.structure().find_machine("C" + std::to_string(k) + ".s_A"));
  const EventId onset = *co.structure().find_event("EVT_FAULT");
  const EventId completion = *co.structure().find_event("/EVT_FAULT");
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate));
  bool raised = false;
  auto cycle = [&] {
    raised = !raised;
    for (MachineId t : targets) co.generate(raised ? onset : completion, t);
  };
  // Warm-up: the supervisor sees every status once before the measurement.
  const auto warm_until = std::chrono::steady_clock::now() + 2s;
  for (auto next = std::chrono::steady_clock::now(); next < warm_until; next += period) {
    std::this_thread::sleep_until(next);
    cycle();
  }
  std::this_thread::sleep_for(300ms);
  const double rss_before = peers::status_bytes(child, "VmRSS");
  const auto before = (*node)->stats();
  const double cpu0 = peers::cpu_seconds(child);
  const std::int64_t t0 = peers::now_ns();
  std::uint64_t changes = 0;
  const auto start = std::chrono::steady_clock::now();
  const auto until =
      start + std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds));
  for (auto next = start; next < until; next += period) {
    std::this_thread::sleep_until(next);
    cycle();
    changes += targets.size();
  }
  std::this_thread::sleep_for(300ms);  // the last cycle reaches the supervisor
  const double cpu1 = peers::cpu_seconds(child);
  const double wall = static_cast<double>(peers::now_ns() - t0) / 1e9;
  const auto after = (*node)->stats();
  const double rss = peers::status_bytes(child, "VmRSS");
  const double hwm = peers::status_bytes(child, "VmHWM");
  const double feeder_cpu = peers::cpu_seconds(::getpid());
  (*node)->stop();

  ::close(child_in);
  child_in = -1;
  std::string report;
  for (char c = read_byte(to_parent[0]); c != '\0' && c != '\n'; c = read_byte(to_parent[0])) report += c;
  unsigned long long lines = 0, rows = 0, refused = 0;
  std::sscanf(report.c_str(), "%llu %llu %llu", &lines, &rows, &refused);

  const std::uint64_t updates = after.updates_published - before.updates_published;
  const std::uint64_t records = after.events_published - before.events_published;
  const double cpu = cpu1 - cpu0;
  const double per_10k = updates > 0 ? cpu / static_cast<double>(updates) * 10000.0 : 0.0;
  char json[1400];
  std::snprintf(
      json, sizeof json,
      "{\n  \"components\": %d,\n  \"rate_hz\": %.1f,\n  \"seconds\": %.2f,\n  \"wall_s\": %.2f,\n"
      "  \"status_changes\": %llu,\n  \"updates\": %llu,\n  \"state_messages\": %llu,\n"
      "  \"event_records\": %llu,\n  \"cpu_s\": %.3f,\n  \"cpu_s_per_10k_updates\": %.5f,\n"
      "  \"cpu_percent_of_one_core\": %.2f,\n  \"rss_bytes\": %.0f,\n  \"rss_before_feed_bytes\": %.0f,\n"
      "  \"hwm_bytes\": %.0f,\n  \"output_lines\": %llu,\n  \"view_rows\": %llu,\n  \"messages_refused\": %llu,\n"
      "  \"updates_missed\": %llu,\n  \"events_dropped\": %llu,\n  \"feeder_cpu_s_total\": %.3f,\n"
      "  \"records_followed\": %s,\n"
      "  \"watcher\": \"SAFECASS supervisor, one process, fed by one coordinator through IceStorm\"\n}\n",
      components, rate, seconds, wall, static_cast<unsigned long long>(changes),
      static_cast<unsigned long long>(updates),
      static_cast<unsigned long long>(after.state_messages_published - before.state_messages_published),
      static_cast<unsigned long long>(records), cpu, per_10k, wall > 0 ? 100.0 * cpu / wall : 0.0, rss, rss_before, hwm,
      lines, rows, refused, static_cast<unsigned long long>(after.updates_missed),
      static_cast<unsigned long long>(after.events_dropped), feeder_cpu, states_only ? "false" : "true");
  std::ofstream(out_path) << json;
  std::printf("%s", json);
  return updates > 0 && rows >= static_cast<unsigned long long>(components) && refused == 0 ? 0 : 1;
}
