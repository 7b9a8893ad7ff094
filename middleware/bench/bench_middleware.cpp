// Cross-process propagation through a real IceStorm (DESIGN §7: p99 ≤ 1 ms, ≥ 50k updates/s on
// loopback).
//
//   bench_middleware --ice HOST:PORT --out FILE [--samples N] [--seconds S] [--interfaces K]
//                    [--pause-us P] [--ca DIR]
//
// --ca DIR: the key directory whose CA the IceStorm admits (scripts/start-icestorm --keys DIR);
// the run's own keys are signed by it, and the bus runs over mutual TLS as deployed.
//   bench_middleware --make-keys DIR   makes such a directory (the benchmark system's keys, a CA
//                                      and IceStorm's certificate) and exits: what the scripts
//                                      start IceStorm with.
//
// Two processes: this one forks a provider ("sensor": JR3 provides ForceData) and runs the client
// ("robot": CONTROL requires JR3.ForceData through a remote provided interface). Both use the
// host's monotonic clock, so the root's onset time (stamped by the provider's coordinator) and the
// moment the client's CONTROL.s_R.ForceData changes state are on one time line.
//   1. latency: N onsets, each followed by its completion, 1 ms apart; latency = onset →
//      CONTROL.s_R.ForceData entering Error in the other process (its transition callback).
//   2. throughput: JR3 also provides K interfaces D0..D{K-1} (CONTROL requires each); for S
//      seconds the provider changes the root set of each s_P.Di in turn, as fast as it can (one
//      generate() = one state change of one interface; a pause of P µs, default 50, after each
//      round over the K interfaces). The client counts the interface updates it applied (each one a full
//      state that differed from the previous one sent); state changes the publisher coalesced
//      (a newer full state of the same interface superseded them before they were sent) are
//      reported as "superseded", and at the end the client must hold exactly the provider's
//      final state (every Di Normal).
//   3. followers (--follow-seconds F, 0: skipped): does a follower hold up the robot? A third
//      process ("sensor" again, alone) fires an event every 1 ms (an onset, then its completion)
//      and times each generate() call; the parent attaches 0, 1, then 3 followers of its records
//      (RemoteClient::follow: what the viewer, `console --ice watch` and the timeline use) for F
//      seconds each. Run twice: with a history ring of 8,192 records and of 2^20, each filled
//      before the process joins the bus.
// Writes {"p50_us", "p99_us", "max_us", "samples", "updates_per_s", ..., "followers": [...]} to
// FILE.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/spec/load.hpp"

using namespace safecass;

namespace {
std::string g_keys;  ///< the bus keys of the benchmark's system (a private temporary directory)
}  // namespace
using namespace std::chrono_literals;

namespace {

/// JR3 provides ForceData (latency) and D0..D{k-1} (throughput); CONTROL requires all of them.
std::string system_text(int k) {
  std::string provided = "\"ForceData\"", required = "\"ForceData\"";
  std::string connections = R"({ "required": "CONTROL.ForceData", "provided": "JR3.ForceData" })";
  // Di's service is s_P.Di alone: the latency phase's faults on JR3.s_A change ForceData only.
  std::string services = R"({ "name": "ForceData", "dependency": { "s_F": true, "s_A": true } })";
  for (int i = 0; i < k; ++i) {
    const std::string d = "D" + std::to_string(i);
    provided += ", \"" + d + "\"";
    required += ", \"" + d + "\"";
    connections += R"(, { "required": "CONTROL.)" + d + R"(", "provided": "JR3.)" + d + "\" }";
    services += R"(, { "name": ")" + d + R"(", "dependency": {} })";
  }
  return R"({
  "safecass": 1, "system": "bench",
  "components": [
    { "component": "JR3", "interfaces": { "provided": [)" +
         provided + R"(], "required": [] },
      "event": [ { "name": "EVT_FORCE_ERROR", "severity": 50, "state_transition": ["N2E", "W2E"] },
                 { "name": "/EVT_FORCE_ERROR", "severity": 50, "state_transition": ["E2N", "E2W"] },
                 { "name": "EVT_JR3_FAULT", "severity": 60, "state_transition": ["N2E", "W2E"] },
                 { "name": "/EVT_JR3_FAULT", "severity": 60, "state_transition": ["E2N", "E2W"] } ],
      "service": [ )" +
         services + R"( ] },
    { "component": "CONTROL", "interfaces": { "provided": [], "required": [)" +
         required + R"(] } } ],
  "connections": [ )" +
         connections + R"( ],
  "coordinators": { "sensor": ["JR3"], "robot": ["CONTROL"] } })";
}

struct Process {
  FilterRegistry registry;
  spec::SystemSpec system;
  middleware::HostClock clock;
  std::unique_ptr<Coordinator> co;
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<middleware::CoordinatorNode> node;

  /// `ring` (not 0): the history holds that many records, and is filled before the node starts.
  bool build(const std::string& name, const middleware::IceEndpoint& ice, int interfaces, std::size_t ring = 0) {
    register_builtin_filters(registry);
    auto load = spec::load_system_from_text(system_text(interfaces), "bench.json", registry);
    if (!load.ok()) return false;
    system = *load.system;
    CoordinatorOptions history;
    if (ring != 0) {
      history.history_records = ring;
      history.history_records_max = std::max(ring, history.history_records_max);
    }
    co = std::make_unique<Coordinator>(name, &clock, history);
    monitor = std::make_unique<Monitor>(*co, registry);
    if (!spec::instantiate(system, *co, *monitor, name)) return false;
    if (!middleware::connect_remote_providers(system, name, *co)) return false;
    if (ring != 0 && !fill_history()) return false;
    middleware::NodeOptions options;
    options.ice = ice;
    options.keys_dir = g_keys;
    options.log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    auto n = middleware::CoordinatorNode::create(*co, *monitor, registry, system, name, options);
    if (!n) return false;
    node = std::move(*n);
    return node->start().has_value();
  }
  /// Onsets and completions on JR3.s_A until the history has written over its whole ring: what a
  /// robot that has run for a while holds (made before the node publishes anything).
  bool fill_history() {
    const auto onset = co->structure().find_event("EVT_FORCE_ERROR");
    const auto completion = co->structure().find_event("/EVT_FORCE_ERROR");
    const auto target = co->structure().find_machine("JR3.s_A");
    if (!onset || !completion || !target) return false;
    const std::vector<Record> newest = co->history(Address{}, 1);
    const std::uint64_t first = newest.empty() ? 0 : newest.back().seq;
    // Written over once the record after `first` is no longer the oldest kept.
    const auto written_over = [&] {
      const std::vector<Record> oldest = co->records_since(first, 1);
      return !oldest.empty() && oldest.front().seq != first + 1;
    };
    while (!written_over()) {
      for (int i = 0; i < 1024; ++i) {
        co->generate(*onset, *target);
        co->generate(*completion, *target);
      }
    }
    return true;
  }
  bool wait_connected() {
    for (int i = 0; i < 500 && !node->stats().connected; ++i) std::this_thread::sleep_for(10ms);
    return node->stats().connected;
  }
};

void write_byte(int fd, char c) { (void)!::write(fd, &c, 1); }
char read_byte(int fd) {
  char c = 0;
  return ::read(fd, &c, 1) == 1 ? c : '\0';
}
void write_counts(int fd, const std::uint64_t (&v)[3]) { (void)!::write(fd, v, sizeof v); }
bool read_counts(int fd, std::uint64_t (&v)[3]) {
  std::size_t got = 0;
  auto* p = reinterpret_cast<char*>(v);
  while (got < sizeof v) {
    const ssize_t n = ::read(fd, p + got, sizeof v - got);
    if (n <= 0) return false;
    got += static_cast<std::size_t>(n);
  }
  return true;
}

/// The provider: waits for 'L' (latency phase) and 'T' (throughput phase), answers 'd' when done;
/// after 'T' it also sends {state changes made, updates published, Ice messages for them}.
int provider(const middleware::IceEndpoint& ice, int in, int out, int samples, double seconds, int interfaces,
             std::chrono::microseconds pause) {
  Process p;
  if (!p.build("sensor", ice, interfaces) || !p.wait_connected()) return 2;
  const EventId onset = *p.co->structure().find_event("EVT_FORCE_ERROR");
  const EventId completion = *p.co->structure().find_event("/EVT_FORCE_ERROR");
  const MachineId target = *p.co->structure().find_machine("JR3.s_A");
  write_byte(out, 'r');
  for (char c = read_byte(in); c == 'L' || c == 'T'; c = read_byte(in)) {
    std::uint64_t counts[3] = {0, 0, 0};
    if (c == 'L') {
      for (int i = 0; i < samples; ++i) {
        p.co->generate(onset, target);
        std::this_thread::sleep_for(1ms);
        p.co->generate(completion, target);
        std::this_thread::sleep_for(1ms);
      }
    } else {
      // Each Di's root set is never empty and differs after every step ({A}, {A,B}, {B}, {B,A'},
      // {A'}, ...): every generate() below is one state change of one interface.
      const EventId other = *p.co->structure().find_event("EVT_JR3_FAULT");
      const EventId other_done = *p.co->structure().find_event("/EVT_JR3_FAULT");
      const EventId steps[4] = {other, completion, onset, other_done};
      std::vector<MachineId> targets;
      for (int i = 0; i < interfaces; ++i)
        targets.push_back(*p.co->structure().find_machine("JR3.s_P.D" + std::to_string(i)));
      for (MachineId t : targets) p.co->generate(onset, t);
      std::this_thread::sleep_for(100ms);
      // The client counts from here: these first onsets are not part of the measurement.
      write_byte(out, 's');
      if (read_byte(in) != 'g') return 2;
      const auto before = p.node->stats();
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      std::uint64_t changes = 0;
      for (std::size_t step = 0; std::chrono::steady_clock::now() < until; step = (step + 1) % 4) {
        for (MachineId t : targets) p.co->generate(steps[step], t);
        changes += targets.size();
        if (pause.count() > 0) std::this_thread::sleep_for(pause);
      }
      std::this_thread::sleep_for(200ms);  // let the last updates out
      const auto after = p.node->stats();
      counts[0] = changes;
      counts[1] = after.updates_published - before.updates_published;
      counts[2] = after.state_messages_published - before.state_messages_published;
      write_byte(out, 'd');
      write_counts(out, counts);
      // Then back to Normal everywhere (the client checks that this final state arrives).
      for (MachineId t : targets) {
        p.co->generate(completion, t);
        p.co->generate(other_done, t);
      }
      continue;
    }
    std::this_thread::sleep_for(200ms);  // let the last updates out
    write_byte(out, 'd');
  }
  p.node->stop();
  return 0;
}

/// Percentiles of the generate() calls timed while followers were attached (µs).
struct GenerateTimes {
  double p50 = 0, p99 = 0, p999 = 0, max = 0, samples = 0;
};

double percentile(std::vector<double> v, double q);

/// The followers phase's provider: fills a history of `ring` records, joins the bus, answers 'r';
/// then for each 'F' fires an event every 1 ms for `seconds`, timing each generate() call, and
/// answers 'd' and the GenerateTimes.
int follower_provider(const middleware::IceEndpoint& ice, int in, int out, std::size_t ring, double seconds) {
  Process p;
  if (!p.build("sensor", ice, 1, ring) || !p.wait_connected()) return 2;
  const EventId events[2] = {*p.co->structure().find_event("EVT_FORCE_ERROR"),
                             *p.co->structure().find_event("/EVT_FORCE_ERROR")};
  const MachineId target = *p.co->structure().find_machine("JR3.s_A");
  write_byte(out, 'r');
  while (read_byte(in) == 'F') {
    std::vector<double> us;
    us.reserve(static_cast<std::size_t>(seconds * 1000) + 1);
    auto tick = std::chrono::steady_clock::now();
    const auto until = tick + std::chrono::duration<double>(seconds);
    for (std::size_t i = 0; tick < until; ++i) {
      tick += 1ms;
      std::this_thread::sleep_until(tick);
      const auto t0 = std::chrono::steady_clock::now();
      p.co->generate(events[i % 2], target);
      const auto t1 = std::chrono::steady_clock::now();
      us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    }
    const GenerateTimes t{percentile(us, 0.50), percentile(us, 0.99), percentile(us, 0.999),
                          *std::max_element(us.begin(), us.end()), static_cast<double>(us.size())};
    write_byte(out, 'd');
    (void)!::write(out, &t, sizeof t);
  }
  p.node->stop();
  return 0;
}

/// The followers phase for one ring: a provider process, and 0, 1 and 3 followers of its records
/// attached from this one. Appends one JSON object per count to `json`; false when it failed.
bool followers_phase(const middleware::IceEndpoint& ice, std::size_t ring, double seconds, std::string& json) {
  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return false;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(follower_provider(ice, to_child[0], to_parent[1], ring, seconds));
  }
  ::close(to_child[0]);
  ::close(to_parent[1]);
  struct Reap {
    pid_t pid;
    int in, out;
    ~Reap() {
      ::close(out);  // the provider reads end-of-file and stops
      for (int i = 0; i < 300 && ::waitpid(pid, nullptr, WNOHANG) != pid; ++i) std::this_thread::sleep_for(10ms);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, WNOHANG);
      ::close(in);
    }
  } reap{child, to_parent[0], to_child[1]};
  if (read_byte(to_parent[0]) != 'r') {
    std::fprintf(stderr, "bench_middleware: the followers' provider did not start\n");
    return false;
  }
  middleware::ClientOptions options;
  options.ice = ice;
  options.coordinator = "sensor";
  options.keys_dir = g_keys;
  std::vector<std::unique_ptr<middleware::RemoteClient>> clients;
  std::vector<std::unique_ptr<introspect::Subscription>> followers;
  std::atomic<std::uint64_t> delivered{0};
  for (const std::size_t count : {0, 1, 3}) {
    while (followers.size() < count) {
      std::unique_ptr<middleware::RemoteClient> client;
      for (int attempt = 0; attempt < 50 && !client; ++attempt) {
        auto c = middleware::RemoteClient::connect(options);
        if (c) client = std::move(*c);
      }
      if (!client) return false;
      auto follow = client->follow([&](const introspect::HistoryEntry&) { delivered.fetch_add(1); });
      if (!follow) return false;
      followers.push_back(std::move(*follow));
      clients.push_back(std::move(client));
    }
    const std::uint64_t before = delivered.load();
    write_byte(to_child[1], 'F');
    GenerateTimes t;
    if (read_byte(to_parent[0]) != 'd' || ::read(to_parent[0], &t, sizeof t) != sizeof t) return false;
    std::this_thread::sleep_for(100ms);  // the last records reach the followers
    char line[512];
    std::snprintf(line, sizeof line,
                  "%s\n    {\"ring\": %zu, \"followers\": %zu, \"generate_p50_us\": %.2f, \"generate_p99_us\": %.2f, "
                  "\"generate_p999_us\": %.2f, \"generate_max_us\": %.2f, \"samples\": %.0f, "
                  "\"records_delivered\": %llu}",
                  json.empty() ? "" : ",", ring, count, t.p50, t.p99, t.p999, t.max, t.samples,
                  static_cast<unsigned long long>(delivered.load() - before));
    json += line;
  }
  return true;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)));
  return v[std::min(i, v.size() - 1)];
}

/// The bus keys of the benchmark's system with `interfaces` interfaces in `dir`, signed by the CA
/// of `ca_dir` (empty: a CA of their own). Says why not on stderr.
bool make_keys(const std::string& dir, int interfaces, const std::string& ca_dir) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system_from_text(system_text(interfaces), "bench.json", registry);
  middleware::KeyOptions options = middleware::KeyOptions::replacing();
  options.ca_dir = ca_dir;
  auto made = load.ok() ? middleware::create_bus_keys(*load.system, dir, options)
                        : Expected<std::vector<std::string>>(fail(ErrorCode::Parse, "the system does not load"));
  if (!made) {
    std::fprintf(stderr, "bench_middleware: cannot create bus keys in %s: %s\n", dir.c_str(),
                 made.error().message.c_str());
  }
  return made.has_value();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--make-keys") return make_keys(argv[2], 1, {}) ? 0 : 2;
  std::string ice_text, out_path = "bench-middleware.json";
  int samples = 2000;
  double seconds = 2.0;
  int interfaces = 16;
  std::chrono::microseconds pause{50};
  double follow_seconds = 3.0;
  std::string ca_dir;  // --ca DIR: the key directory whose CA signs the run's keys
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--ice")
      ice_text = argv[i + 1];
    else if (key == "--out")
      out_path = argv[i + 1];
    else if (key == "--samples")
      samples = std::max(10, std::atoi(argv[i + 1]));
    else if (key == "--seconds")
      seconds = std::max(0.2, std::atof(argv[i + 1]));
    else if (key == "--interfaces")
      interfaces = std::clamp(std::atoi(argv[i + 1]), 1, 1000);
    else if (key == "--follow-seconds")
      follow_seconds = std::max(0.0, std::atof(argv[i + 1]));
    else if (key == "--ca")
      ca_dir = argv[i + 1];
    else if (key == "--pause-us")
      pause = std::chrono::microseconds(std::clamp(std::atoi(argv[i + 1]), 0, 1000000));
    else {
      std::fprintf(stderr, "bench_middleware: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  auto ice = middleware::parse_ice_endpoint(ice_text);
  if (!ice) {
    std::fprintf(stderr, "bench_middleware: %s\n", ice.error().message.c_str());
    return 2;
  }
  // The bus is authenticated: keys for the benchmark's system, in a private directory.
  char keys_template[] = "/tmp/safecass-bench-keys.XXXXXX";
  if (::mkdtemp(keys_template) == nullptr) return 2;
  g_keys = keys_template;
  if (!make_keys(g_keys, interfaces, ca_dir)) return 2;
  struct RemoveKeys {
    ~RemoveKeys() { std::filesystem::remove_all(g_keys); }
  } remove_keys;
  // The followers phase first: its provider is gone before the other phases' starts.
  std::string followers;
  if (follow_seconds > 0) {
    for (const std::size_t ring : {std::size_t{8192}, std::size_t{1} << 20}) {
      if (!followers_phase(*ice, ring, follow_seconds, followers)) {
        std::fprintf(stderr, "bench_middleware: the followers phase failed (ring %zu)\n", ring);
        return 1;
      }
    }
  }
  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return 2;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(provider(*ice, to_child[0], to_parent[1], samples, seconds, interfaces, pause));
  }
  ::close(to_child[0]);
  ::close(to_parent[1]);
  struct Reap {
    pid_t pid;
    int fd;
    ~Reap() {
      ::close(fd);  // the provider reads end-of-file and stops
      for (int i = 0; i < 300 && ::waitpid(pid, nullptr, WNOHANG) != pid; ++i) std::this_thread::sleep_for(10ms);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, WNOHANG);
    }
  } reap{child, to_child[1]};

  Process client;
  if (!client.build("robot", *ice, interfaces) || !client.wait_connected()) {
    std::fprintf(stderr, "bench_middleware: the client cannot join IceStorm at %s\n", ice_text.c_str());
    return 1;
  }
  std::mutex mutex;
  std::vector<double> latencies;
  std::atomic<bool> measuring{false};
  client.co->on_machine(
      *client.co->structure().find_machine("CONTROL.s_R.ForceData"),
      StateCallbacks{nullptr,
                     [&](const TransitionInfo& info) {
                       if (!measuring.load() || info.transition != Transition::N2E || info.root == nullptr) return;
                       const double us = static_cast<double>((client.clock.now() - info.root->time).count()) / 1000.0;
                       std::lock_guard lock(mutex);
                       latencies.push_back(us);
                     },
                     nullptr});
  if (read_byte(to_parent[0]) != 'r') {
    std::fprintf(stderr, "bench_middleware: the provider did not start\n");
    return 1;
  }
  std::this_thread::sleep_for(300ms);  // subscriptions settle, initial resync done

  measuring.store(true);
  write_byte(to_child[1], 'L');
  if (read_byte(to_parent[0]) != 'd') return 1;
  measuring.store(false);

  write_byte(to_child[1], 'T');
  if (read_byte(to_parent[0]) != 's') return 1;
  const auto before = client.node->stats();
  write_byte(to_child[1], 'g');
  std::uint64_t counts[3] = {0, 0, 0};
  if (read_byte(to_parent[0]) != 'd' || !read_counts(to_parent[0], counts)) return 1;
  // Applied while the provider was changing its roots (its last updates had 200 ms to arrive).
  const auto stats = client.node->stats();
  const std::uint64_t applied = stats.updates_applied - before.updates_applied;
  const double updates_per_s = static_cast<double>(applied) / seconds;
  const std::uint64_t changes = counts[0], published = counts[1], messages = counts[2];
  // The final state arrived: every Di back to Normal at the client.
  bool final_ok = true;
  for (int i = 0; i < interfaces; ++i) {
    const MachineId m = *client.co->structure().find_machine("CONTROL.s_R.D" + std::to_string(i));
    for (int wait = 0; wait < 200 && client.co->state(m) != State::Normal; ++wait) std::this_thread::sleep_for(5ms);
    final_ok = final_ok && client.co->state(m) == State::Normal;
  }

  std::vector<double> copy;
  {
    std::lock_guard lock(mutex);
    copy = latencies;
  }
  const double p50 = percentile(copy, 0.50), p99 = percentile(copy, 0.99);
  const double max = copy.empty() ? 0.0 : *std::max_element(copy.begin(), copy.end());
  char json[1024];
  std::snprintf(json, sizeof json,
                "{\n  \"p50_us\": %.1f,\n  \"p99_us\": %.1f,\n  \"max_us\": %.1f,\n  \"samples\": %zu,\n"
                "  \"onsets_sent\": %d,\n  \"updates_per_s\": %.0f,\n  \"interfaces\": %d,\n  \"pause_us\": %lld,\n"
                "  \"seconds\": %.2f,\n"
                "  \"state_changes\": %llu,\n  \"updates_published\": %llu,\n  \"updates_applied\": %llu,\n"
                "  \"superseded\": %llu,\n  \"state_messages\": %llu,\n  \"updates_missed\": %llu,\n"
                "  \"final_state_ok\": %s,\n"
                "  \"transport\": \"IceStorm (icebox) on loopback, two processes\"\n}\n",
                p50, p99, max, copy.size(), samples, updates_per_s, interfaces, static_cast<long long>(pause.count()),
                seconds, static_cast<unsigned long long>(changes), static_cast<unsigned long long>(published),
                static_cast<unsigned long long>(applied),
                static_cast<unsigned long long>(changes > published ? changes - published : 0),
                static_cast<unsigned long long>(messages), static_cast<unsigned long long>(stats.updates_missed),
                final_ok ? "true" : "false");
  std::string out = json;
  if (!followers.empty()) out.insert(out.rfind("\n}"), ",\n  \"followers\": [" + followers + "\n  ]");
  std::ofstream(out_path) << out;
  std::printf("%s", out.c_str());
  client.node->stop();
  return copy.size() >= static_cast<std::size_t>(samples) * 9 / 10 && final_ok ? 0 : 1;
}
