// Scale out (`make bench-scale-out`, docs/scaling.md): N coordinator processes of K components
// each, through a (replicated) IceStorm, watched by the supervisor and by one more coordinator.
//
//   bench_scale_out --ice ICE --ca DIR --out FILE --coordinators N [--components K] [--rate R]
//                   [--seconds S] [--broker PID,PID,...]
//
// ICE is what every process gives to --ice (`locator:HOST:PORT` for a replicated IceStorm); DIR
// the key directory whose CA the broker admits (the run's own keys are signed by it); --broker
// the PIDs of the broker's processes (IceBoxes, IceGrid node), whose CPU and memory are read.
//
// Processes, all forked from this one: the supervisor (middleware::Supervisor, with event
// records, as `safecass supervisor` runs); N providers P0..P{N-1}, each a coordinator of K
// components PiC0..PiC{K-1} providing Status (its service state follows s_A); and, here, the
// watcher, a coordinator whose one component W requires every provider's every Status. R times a
// second each provider raises or clears a fault on its next component in turn (one state change:
// one state update and its observer records). Latency is a raise's onset (stamped by the
// provider's coordinator, host monotonic clock) → W's required interface entering Error here.
// CPU (user + system) of the supervisor and of the broker's processes over the measured S seconds;
// their RSS at the end; messages per second published (the providers' state and event messages,
// and every member's heartbeats, which IceStorm delivers to every member).
// Writes one JSON object to FILE.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
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

std::string component(int provider, int k) { return "P" + std::to_string(provider) + "C" + std::to_string(k); }

std::string system_text(int n, int k) {
  std::string components, coordinators, required, connections;
  for (int p = 0; p < n; ++p) {
    std::string members;
    for (int c = 0; c < k; ++c) {
      const std::string name = component(p, c);
      components += R"({ "component": ")" + name + R"(", "interfaces": { "provided": ["Status"], "required": [] })";
      if (p == 0 && c == 0) {
        components += R"(, "event": [ { "name": "EVT_FAULT", "severity": 50, "state_transition": ["N2E"] },
                                      { "name": "/EVT_FAULT", "severity": 50, "state_transition": ["E2N"] } ])";
      }
      components += R"(, "service": [ { "name": "Status", "dependency": { "s_F": true, "s_A": true } } ] },)"
                    "\n";
      members += (c ? ", \"" : "\"") + name + "\"";
      required += (required.empty() ? "\"" : ", \"") + name + "\"";
      connections += std::string(connections.empty() ? "" : ",\n") + R"({ "required": "W.)" + name +
                     R"(", "provided": ")" + name + R"(.Status" })";
    }
    coordinators += "\"P" + std::to_string(p) + "\": [" + members + "], ";
  }
  return R"({ "safecass": 1, "system": "scale", "components": [)" + components +
         R"({ "component": "W", "interfaces": { "provided": [], "required": [)" + required + R"(] } } ],
  "connections": [)" +
         connections +
         R"(],
  "coordinators": { )" +
         coordinators + R"("watch": ["W"] } })";
}

void write_text(int fd, const std::string& text) { (void)!::write(fd, text.data(), text.size()); }
char read_byte(int fd) {
  char c = 0;
  return ::read(fd, &c, 1) == 1 ? c : '\0';
}
std::string read_line(int fd) {
  std::string out;
  for (char c = read_byte(fd); c != '\0' && c != '\n'; c = read_byte(fd)) out += c;
  return out;
}

/// A coordinator process of `system` joined to the bus.
struct Member {
  FilterRegistry registry;
  middleware::HostClock clock;
  std::unique_ptr<Coordinator> co;
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<middleware::CoordinatorNode> node;

  bool join(const spec::SystemSpec& system, const std::string& name, const middleware::IceEndpoint& ice,
            const std::string& keys) {
    register_builtin_filters(registry);
    co = std::make_unique<Coordinator>(name, &clock);
    monitor = std::make_unique<Monitor>(*co, registry);
    if (!spec::instantiate(system, *co, *monitor, name)) return false;
    if (!middleware::connect_remote_providers(system, name, *co)) return false;
    middleware::NodeOptions options;
    options.ice = ice;
    options.keys_dir = keys;
    options.log = [name](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    auto n = middleware::CoordinatorNode::create(*co, *monitor, registry, system, name, options);
    if (!n || !(*n)->start()) return false;
    node = std::move(*n);
    for (int i = 0; i < 3000 && !node->stats().connected; ++i) std::this_thread::sleep_for(10ms);
    return node->stats().connected;
  }
};

/// Provider Pi: 'r' when joined; on 'g' changes one component's state R times a second for S
/// seconds, then writes "changes raises state_messages event_messages\n"; stops at end of input.
int provider(const spec::SystemSpec& system, int index, int k, double rate, double seconds,
             const middleware::IceEndpoint& ice, const std::string& keys, int in, int out) {
  Member m;
  if (!m.join(system, "P" + std::to_string(index), ice, keys)) return 2;
  std::vector<MachineId> targets;
  for (int c = 0; c < k; ++c) targets.push_back(*m.co->structure().find_machine(component(index, c) + ".s_A"));
  const EventId onset = *m.co->structure().find_event("EVT_FAULT");
  const EventId completion = *m.co->structure().find_event("/EVT_FAULT");
  write_text(out, "r");
  if (read_byte(in) != 'g') return 0;
  const auto before = m.node->stats();
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate));
  // Providers start at different phases, as independent machines would.
  auto next =
      std::chrono::steady_clock::now() + period * index / std::max(1, static_cast<int>(system.coordinators.size()));
  const auto until =
      next + std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds));
  std::uint64_t changes = 0, raises = 0;
  for (std::size_t tick = 0; next < until; ++tick, next += period) {
    std::this_thread::sleep_until(next);
    const bool raise = (tick / targets.size()) % 2 == 0;
    m.co->generate(raise ? onset : completion, targets[tick % targets.size()]);
    ++changes;
    raises += raise ? 1 : 0;
  }
  std::this_thread::sleep_for(300ms);
  const auto after = m.node->stats();
  write_text(out, std::to_string(changes) + " " + std::to_string(raises) + " " +
                      std::to_string(after.state_messages_published - before.state_messages_published) + " " +
                      std::to_string(after.event_messages_published - before.event_messages_published) + "\n");
  while (read_byte(in) != '\0') {
  }
  m.node->stop();
  return 0;
}

/// The supervisor: 'r' when started; at end of input writes "rows refused lost\n".
int supervisor(const spec::SystemSpec& system, const middleware::IceEndpoint& ice, const std::string& keys, int in,
               int out) {
  middleware::SupervisorOptions options;
  options.ice = ice;
  options.keys_dir = keys;
  std::atomic<std::uint64_t> notices{0};
  options.output = [&notices](const middleware::SupervisorLine& line) {
    if (line.kind() == middleware::SupervisorLine::Kind::Notice) {
      notices.fetch_add(1, std::memory_order_relaxed);
      std::fprintf(stderr, "%s\n", line.text().c_str());
    }
  };
  auto sup = middleware::Supervisor::create(system, options);
  if (!sup || !(*sup)->start()) return 2;
  write_text(out, "r");
  while (read_byte(in) != '\0') {
  }
  const std::size_t rows = (*sup)->view().size();
  const std::uint64_t refused = (*sup)->messages_refused();
  (*sup)->stop();
  write_text(out, std::to_string(rows) + " " + std::to_string(refused) + " " + std::to_string(notices.load()) + "\n");
  return 0;
}

struct Child {
  pid_t pid = -1;
  int in = -1;   ///< to the child
  int out = -1;  ///< from the child
};

/// Forks `body(in, out)`; the child closes the pipe ends of the `others` forked before it, so
/// that each child sees its own input end when the parent closes it.
template <class F>
Child spawn(const std::vector<Child>& others, F body) {
  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    for (const Child& c : others) {
      ::close(c.in);
      ::close(c.out);
    }
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(body(to_child[0], to_parent[1]));
  }
  ::close(to_child[0]);
  ::close(to_parent[1]);
  return Child{pid, to_child[1], to_parent[0]};
}

double broker_cpu(const std::vector<int>& pids) {
  double sum = 0;
  for (int p : pids) sum += std::max(0.0, peers::cpu_seconds(p));
  return sum;
}
double broker_rss(const std::vector<int>& pids) {
  double sum = 0;
  for (int p : pids) sum += std::max(0.0, peers::status_bytes(p, "VmRSS"));
  return sum;
}

struct Options {
  std::string ice_text, out_path = "bench-scale-out.json", ca_dir;
  int n = 10, k = 20;
  double rate = 10.0, seconds = 10.0;
  std::vector<int> broker;
};

/// The command line (see the file comment); false, said on stderr, for an unknown option.
bool parse_options(int argc, char** argv, Options& o) {
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const std::string value = argv[i + 1];
    if (key == "--ice") {
      o.ice_text = value;
    } else if (key == "--out") {
      o.out_path = value;
    } else if (key == "--ca") {
      o.ca_dir = value;
    } else if (key == "--coordinators") {
      o.n = std::clamp(std::atoi(value.c_str()), 1, 500);
    } else if (key == "--components") {
      o.k = std::clamp(std::atoi(value.c_str()), 1, 1000);
    } else if (key == "--rate") {
      o.rate = std::clamp(std::atof(value.c_str()), 0.1, 1000.0);
    } else if (key == "--seconds") {
      o.seconds = std::max(1.0, std::atof(value.c_str()));
    } else if (key == "--broker") {
      std::istringstream list(value);
      for (std::string pid; std::getline(list, pid, ',');) o.broker.push_back(std::atoi(pid.c_str()));
    } else {
      std::fprintf(stderr, "bench_scale_out: unknown option %s\n", key.c_str());
      return false;
    }
  }
  return true;
}

/// The watcher's latencies: a provider's raise (a remote root entering Error on W's required
/// interface) → now, each raise counted once (a provider declared lost and back shows its active
/// roots again).
class Latencies {
public:
  void watch(Member& watcher, int n, int k) {
    for (int p = 0; p < n; ++p) {
      for (int c = 0; c < k; ++c) {
        watcher.co->on_machine(
            *watcher.co->structure().find_machine("W.s_R." + component(p, c)),
            StateCallbacks{nullptr,
                           [this, &watcher](const TransitionInfo& info) {
                             // A loss the watcher raises itself has a local root.
                             if (!measuring.load() || info.transition != Transition::N2E || info.root == nullptr ||
                                 info.root->remote == kNone)
                               return;
                             const double us =
                                 static_cast<double>((watcher.clock.now() - info.root->time).count()) / 1000.0;
                             std::lock_guard lock(mutex_);
                             if (seen_.emplace(info.root->remote_origin, info.root->time.count()).second)
                               us_.push_back(us);
                           },
                           nullptr});
      }
    }
  }
  std::vector<double> taken() const {
    std::lock_guard lock(mutex_);
    return us_;
  }
  std::atomic<bool> measuring{false};

private:
  mutable std::mutex mutex_;
  std::vector<double> us_;
  std::set<std::pair<NameId, std::int64_t>> seen_;  ///< (origin, onset) of the raises seen
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse_options(argc, argv, o)) return 2;
  const int n = o.n, k = o.k;
  const double rate = o.rate, seconds = o.seconds;
  const std::vector<int>& broker = o.broker;
  auto ice = middleware::parse_ice_endpoint(o.ice_text);
  if (!ice) {
    std::fprintf(stderr, "bench_scale_out: %s\n", ice.error().message.c_str());
    return 2;
  }
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system_from_text(system_text(n, k), "scale.json", registry);
  if (!load.ok()) {
    std::fprintf(stderr, "bench_scale_out: the generated system does not load\n");
    return 2;
  }
  const spec::SystemSpec system = *load.system;
  char keys_template[] = "/tmp/safecass-scale-keys.XXXXXX";
  if (::mkdtemp(keys_template) == nullptr) return 2;
  const std::string keys = keys_template;
  struct RemoveKeys {
    std::string dir;
    ~RemoveKeys() { std::filesystem::remove_all(dir); }
  } remove_keys{keys};
  middleware::KeyOptions key_options = middleware::KeyOptions::replacing();
  key_options.ca_dir = o.ca_dir;
  if (auto made = middleware::create_bus_keys(system, keys, key_options); !made) {
    std::fprintf(stderr, "bench_scale_out: %s\n", made.error().message.c_str());
    return 2;
  }

  std::vector<Child> children;
  struct Reap {
    std::vector<Child>& children;
    ~Reap() {
      for (Child& c : children) ::close(c.in);
      for (Child& c : children) {
        for (int i = 0; i < 500 && ::waitpid(c.pid, nullptr, WNOHANG) != c.pid; ++i) std::this_thread::sleep_for(10ms);
        ::kill(c.pid, SIGKILL);
        ::waitpid(c.pid, nullptr, WNOHANG);
      }
    }
  } reap{children};
  children.push_back(spawn(children, [&](int in, int out) { return supervisor(system, *ice, keys, in, out); }));
  for (int p = 0; p < n; ++p)
    children.push_back(spawn(
        children, [&, p](int in, int out) { return provider(system, p, k, rate, seconds, *ice, keys, in, out); }));
  for (Child& c : children) {
    if (c.pid <= 0 || read_byte(c.out) != 'r') {
      std::fprintf(stderr, "bench_scale_out: a process did not join the bus\n");
      return 1;
    }
  }
  Member watcher;
  if (!watcher.join(system, "watch", *ice, keys)) {
    std::fprintf(stderr, "bench_scale_out: the watcher did not join the bus\n");
    return 1;
  }
  Latencies latencies;
  latencies.watch(watcher, n, k);
  // The measurement starts from a settled system: the watcher holds every provider proven alive.
  const MachineId w = *watcher.co->structure().find_machine("W");
  for (int i = 0; i < 3000 && watcher.co->state(w) != State::Normal; ++i) std::this_thread::sleep_for(10ms);
  const bool settled = watcher.co->state(w) == State::Normal;
  if (!settled) std::fprintf(stderr, "bench_scale_out: the watcher did not hear every provider within 30 s\n");
  std::this_thread::sleep_for(500ms);

  const pid_t supervisor_pid = children.front().pid;
  const double sup_cpu0 = peers::cpu_seconds(supervisor_pid), broker_cpu0 = broker_cpu(broker);
  const auto watch_before = watcher.node->stats();
  const std::int64_t t0 = peers::now_ns();
  latencies.measuring.store(true);
  for (std::size_t i = 1; i < children.size(); ++i) write_text(children[i].in, "g");
  std::uint64_t changes = 0, raises = 0, state_messages = 0, event_messages = 0;
  for (std::size_t i = 1; i < children.size(); ++i) {
    std::istringstream counts(read_line(children[i].out));
    std::uint64_t c = 0, r = 0, s = 0, e = 0;
    counts >> c >> r >> s >> e;
    changes += c;
    raises += r;
    state_messages += s;
    event_messages += e;
  }
  const double elapsed = static_cast<double>(peers::now_ns() - t0) / 1e9;
  latencies.measuring.store(false);
  const double sup_cpu = peers::cpu_seconds(supervisor_pid) - sup_cpu0;
  const double brk_cpu = broker_cpu(broker) - broker_cpu0;
  const double sup_rss = peers::status_bytes(supervisor_pid, "VmRSS");
  const double brk_rss = broker_rss(broker);
  const auto watch_after = watcher.node->stats();
  ::close(children.front().in);
  children.front().in = -1;
  std::istringstream sup_report(read_line(children.front().out));
  std::size_t rows = 0;
  std::uint64_t refused = 0, notices = 0;
  sup_report >> rows >> refused >> notices;

  const std::vector<double> copy = latencies.taken();
  const double heartbeats_per_s = (n + 2) * 10.0;  // every member and the supervisor, every 100 ms
  const double published_per_s = static_cast<double>(state_messages + event_messages) / elapsed + heartbeats_per_s;
  char json[2048];
  std::snprintf(
      json, sizeof json,
      "{\"coordinators\": %d, \"components_each\": %d, \"rate_hz_each\": %.1f, \"seconds\": %.2f, %s,\n"
      " \"state_changes\": %llu, \"raises\": %llu, \"raises_seen_by_watcher\": %zu, \"watcher_updates_missed\": %llu,\n"
      " \"messages_published_per_s\": %.0f,\n"
      " \"supervisor_cpu_percent\": %.1f, \"supervisor_rss_bytes\": %.0f, \"supervisor_rows\": %zu,\n"
      " \"supervisor_refused\": %llu, \"supervisor_notices\": %llu,\n"
      " \"broker_cpu_percent\": %.1f, \"broker_rss_bytes\": %.0f, \"broker_processes\": %zu, \"settled_at_start\": "
      "%s}\n",
      n, k, rate, elapsed, peers::latency_members(copy).c_str(), static_cast<unsigned long long>(changes),
      static_cast<unsigned long long>(raises), copy.size(),
      static_cast<unsigned long long>(watch_after.updates_missed - watch_before.updates_missed), published_per_s,
      100.0 * sup_cpu / elapsed, sup_rss, rows, static_cast<unsigned long long>(refused),
      static_cast<unsigned long long>(notices), 100.0 * brk_cpu / elapsed, brk_rss, broker.size(),
      settled ? "true" : "false");
  std::ofstream(o.out_path) << json;
  std::printf("%s", json);
  watcher.node->stop();
  // Every raise should reach the watcher; a shortfall (the processes could not keep up and raised
  // losses instead) is part of the result, and said.
  if (copy.size() < raises) {
    std::fprintf(stderr, "bench_scale_out: the watcher saw %zu of %llu raises\n", copy.size(),
                 static_cast<unsigned long long>(raises));
  }
  return 0;
}
