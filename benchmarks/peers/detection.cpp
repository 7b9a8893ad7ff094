// Detection at control-loop scale (`make bench-peers`, item 4): N signals written at R Hz by a
// control loop, each watched by a Threshold, a Watchdog and a MovingAverage (ACTIVE filters),
// run by the native runtime in real time.
//
//   peer_detection --out FILE [--signals N] [--rate R] [--seconds S] [--components K]
//                  [--history H] [--order after-body|before-body]
//
// K components (default 1: one control loop) share the N signals. Each component's task runs at
// R Hz: its body writes a new sample of each of its signals (the control loop's measurements) and
// the native runtime runs its ACTIVE filters right after (native::FilterOrder::AfterBody), so each
// sample is judged in the cycle that wrote it. Every 10 ms one signal, in turn, crosses its
// threshold for 5 ms. Latency: the crossing sample's time → the N2E transition of its component's
// s_A that the Threshold causes (observer on the coordinator's stream, same clock): the loop's
// writes and the filters' run. With --order before-body (the filters first, then the body) a
// sample waits for the next cycle: one period more. CPU: the process's user + system time over the run
// (getrusage) / wall time, in % of one core; it includes writing the samples.
// Writes {"cpu_percent", "p50_us", "p99_us", "max_us", "samples", ...} to FILE.

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "measure.hpp"
#include "safecass/native/runtime.hpp"
#include "safecass/spec/load.hpp"

using namespace safecass;
using namespace std::chrono_literals;

namespace {

constexpr double kThreshold = 10.0;

std::string system_text(int signals, int components) {
  std::string s = R"({ "safecass": 1, "system": "detection", "components": [)";
  for (int c = 0; c < components; ++c) {
    const std::string comp = "LOOP" + std::to_string(c);
    s += c ? ",\n" : "\n";
    s += R"({ "component": ")" + comp + R"(", "interfaces": { "provided": ["Out"], "required": [] }, "signals": [)";
    std::string filters;
    bool first = true;
    for (int i = c; i < signals; i += components) {
      const std::string sig = "S" + std::to_string(i);
      s += first ? "" : ", ";
      s += R"({ "name": ")" + sig + R"(" })";
      filters += first ? "\n" : ",\n";
      filters += R"({ "name": "limit_)" + sig + R"(", "class_name": "Threshold", "type": "ACTIVE",
          "argument": { "input_signal": ")" +
                 sig + R"(", "threshold": 10.0, "hysteresis": 1.0,
                        "event_onset": "EVT_LIMIT", "event_completion": "/EVT_LIMIT" } },
        { "name": "stale_)" +
                 sig + R"(", "class_name": "Watchdog", "type": "ACTIVE", "target": { "type": "s_F" },
          "argument": { "input_signal": ")" +
                 sig + R"(", "timeout": 0.05 } },
        { "name": "mean_)" +
                 sig + R"(", "class_name": "MovingAverage", "type": "ACTIVE",
          "argument": { "input_signal": ")" +
                 sig + R"(", "window": 10, "output_signal": ")" + sig + R"(_mean" } })";
      first = false;
    }
    s += "]";
    if (c == 0) {
      s += R"(, "event": [ { "name": "EVT_LIMIT", "severity": 50, "state_transition": ["N2E", "W2E"] },
                           { "name": "/EVT_LIMIT", "severity": 50, "state_transition": ["E2N", "E2W"] } ])";
    }
    s += R"(, "filter": [)" + filters + "] }";
  }
  s += "],\n\"connections\": [] }";
  return s;
}

double process_cpu_seconds() {
  struct rusage u {};
  ::getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "peer-detection.json";
  int signals = 1000, components = 1;
  std::size_t history = 1024;  // samples each signal's history buffer keeps (the Monitor's default)
  double rate = 1000.0, seconds = 30.0;
  native::FilterOrder order = native::FilterOrder::AfterBody;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--out")
      out_path = argv[i + 1];
    else if (key == "--signals")
      signals = std::clamp(std::atoi(argv[i + 1]), 1, 100000);
    else if (key == "--components")
      components = std::clamp(std::atoi(argv[i + 1]), 1, 100);
    else if (key == "--rate")
      rate = std::clamp(std::atof(argv[i + 1]), 1.0, 10000.0);
    else if (key == "--history")
      history = static_cast<std::size_t>(std::clamp(std::atoi(argv[i + 1]), 2, 1 << 20));
    else if (key == "--order" &&
             (std::string(argv[i + 1]) == "after-body" || std::string(argv[i + 1]) == "before-body"))
      order =
          std::string(argv[i + 1]) == "after-body" ? native::FilterOrder::AfterBody : native::FilterOrder::BeforeBody;
    else if (key == "--seconds")
      seconds = std::max(1.0, std::atof(argv[i + 1]));
    else {
      std::fprintf(stderr, "peer_detection: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  components = std::min(components, signals);
  FilterRegistry registry;
  register_builtin_filters(registry);
  spec::LoadResult load = spec::load_system_from_text(system_text(signals, components), "detection.json", registry);
  for (const auto& d : load.diagnostics) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
  if (!load.ok()) return 2;
  Coordinator co("detection");  // steady_clock, as deployed
  Monitor monitor(co, registry, history);
  if (auto built = spec::instantiate(*load.system, co, monitor); !built) {
    std::fprintf(stderr, "peer_detection: %s\n", built.error().message.c_str());
    return 2;
  }

  struct Loop {
    ComponentId component;
    std::vector<std::pair<int, Signal*>> signals;  ///< (index, signal)
  };
  std::vector<Loop> loops;
  for (int c = 0; c < components; ++c) {
    Loop loop{*co.structure().find_component("LOOP" + std::to_string(c)), {}};
    for (int i = c; i < signals; i += components) {
      loop.signals.emplace_back(i, monitor.signals().find("LOOP" + std::to_string(c) + ".S" + std::to_string(i)));
    }
    loops.push_back(std::move(loop));
  }

  // The crossing: signal `crossing` reads 20 (threshold 10) while it is set, else 1.
  std::atomic<int> crossing{-1};
  std::atomic<bool> measuring{false};
  std::mutex mutex;
  std::vector<double> latencies;
  std::atomic<std::uint64_t> unexpected{0};
  std::vector<MachineId> watched;
  for (const Loop& l : loops) watched.push_back(co.structure().application_machine(l.component));
  co.subscribe([&](const Record& r) {
    if (r.kind != RecordKind::Transition) return;
    if (r.to == State::Normal) return;
    if (std::find(watched.begin(), watched.end(), r.machine) == watched.end()) {
      unexpected.fetch_add(1);  // a Watchdog (s_F) or an overrun: reported
      return;
    }
    if (!measuring.load(std::memory_order_relaxed) || r.root.sample.sample_time.count() == 0) return;
    const double us = static_cast<double>((co.clock().now() - r.root.sample.sample_time).count()) / 1000.0;
    std::lock_guard lock(mutex);
    latencies.push_back(us);
  });

  native::Runtime runtime(monitor);
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate));
  for (Loop& loop : loops) {
    (void)runtime.add_task(
        loop.component, period,
        [&loop, &crossing](Time now) {
          const int hot = crossing.load(std::memory_order_relaxed);
          for (const auto& [index, signal] : loop.signals) signal->push(now, index == hot ? 20.0 : 1.0);
        },
        order);
  }
  runtime.start();
  std::this_thread::sleep_for(500ms);  // warm-up: condition vectors grown, caches warm

  const double cpu0 = process_cpu_seconds();
  const std::int64_t t0 = peers::now_ns();
  measuring.store(true);
  const auto start = std::chrono::steady_clock::now();
  const auto until =
      start + std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds));
  int crossings = 0;
  for (auto next = start; next < until; next += 10ms) {
    std::this_thread::sleep_until(next);
    crossing.store(crossings % signals, std::memory_order_relaxed);
    std::this_thread::sleep_until(next + 5ms);
    crossing.store(-1, std::memory_order_relaxed);
    ++crossings;
  }
  std::this_thread::sleep_for(20ms);
  measuring.store(false);
  const double cpu = process_cpu_seconds() - cpu0;
  const double wall = static_cast<double>(peers::now_ns() - t0) / 1e9;
  runtime.stop();

  std::vector<double> copy;
  {
    std::lock_guard lock(mutex);
    copy = latencies;
  }
  const double cpu_percent = wall > 0 ? 100.0 * cpu / wall : 0.0;
  const double period_us = 1e6 / rate;
  char json[1200];
  std::snprintf(json, sizeof json,
                "{\n  \"signals\": %d,\n  \"filters\": %d,\n  \"components\": %d,\n  \"rate_hz\": %.0f,\n"
                "  \"seconds\": %.2f,\n  \"cpu_s\": %.3f,\n  \"cpu_percent\": %.2f,\n  %s,\n"
                "  \"crossings\": %d,\n  \"period_us\": %.0f,\n  \"other_transitions\": %llu,\n"
                "  \"signal_history\": %zu,\n  \"filter_order\": \"%s\",\n"
                "  \"runtime\": \"native runtime, real time, ACTIVE filters in the component's task\"\n}\n",
                signals, 3 * signals, components, rate, wall, cpu, cpu_percent, peers::latency_members(copy).c_str(),
                crossings, period_us, static_cast<unsigned long long>(unexpected.load()), history,
                order == native::FilterOrder::AfterBody ? "after-body" : "before-body");
  std::ofstream(out_path) << json;
  std::printf("%s", json);
  return copy.size() >= static_cast<std::size_t>(crossings) * 9 / 10 ? 0 : 1;
}
