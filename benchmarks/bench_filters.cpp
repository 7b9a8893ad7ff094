// Filter hot paths (DESIGN §7): a sample that causes no event takes no lock and allocates nothing.

#include <benchmark/benchmark.h>

#include <string>

#include "safecass/filters/monitor.hpp"

namespace safecass {
namespace {

struct FilterBench {
  SimulatedClock clock;
  Coordinator co{"bench", &clock};
  FilterRegistry registry;
  Monitor monitor;
  ComponentId component{0};

  /// `banks` false: every filter runs as an object (to measure what a bank saves).
  explicit FilterBench(bool banks = true) : monitor(co, registry, Monitor::kDefaultSignalHistory, banks) {
    register_builtin_filters(registry);
    component = *co.add_component("C");
    (void)co.add_event(EventDef{"EVT_X", 50, {Transition::N2E}, "", false, "", ""});
    (void)co.add_event(EventDef{"/EVT_X", 50, {Transition::E2N}, "", false, "", ""});
  }
  Filter* add(std::string type, Params p, ExecutionMode mode = ExecutionMode::Active) {
    FilterConfig c;
    c.type = std::move(type);
    c.target.component = "C";
    c.execution = mode;
    c.params = std::move(p);
    return *monitor.add_filter(std::move(c));
  }
};

// One new scalar sample below the threshold: written, read, judged; no event.
void BM_ThresholdNoEvent(benchmark::State& state) {
  FilterBench b;
  Signal* x = *b.monitor.add_signal("C.x");
  Filter* f = b.add("Threshold",
                    {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  std::int64_t t = 0;
  for (auto _ : state) {
    x->push(Time{++t}, 1.0);
    f->run(Time{t});
  }
  if (b.co.coordinator_state() != State::Normal) state.SkipWithError("unexpected event");
}
BENCHMARK(BM_ThresholdNoEvent);

// Norm of a 3-vector → moving average (window 10) → threshold, one new sample, no event.
void BM_Pipeline3(benchmark::State& state) {
  FilterBench b;
  Signal* force = *b.monitor.add_signal("C.force", 3);
  b.add("Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}});
  b.add("MovingAverage",
        {{"input_signal", std::string("norm")}, {"output_signal", std::string("avg")}, {"window", 10.0}});
  b.add("Threshold",
        {{"input_signal", std::string("avg")}, {"threshold", 30.0}, {"event_onset", std::string("EVT_X")}});
  const double sample[] = {1.0, 2.0, 3.0};
  std::int64_t t = 0;
  for (auto _ : state) {
    force->push(Time{++t}, sample);
    b.monitor.run_active(b.component, Time{t});
  }
  if (b.co.coordinator_state() != State::Normal) state.SkipWithError("unexpected event");
}
BENCHMARK(BM_Pipeline3);

// One monitor tick over N passive thresholds (10 signals, each read by N/10 filters, each with a
// new sample per tick); no event.
void BM_MonitorTick(benchmark::State& state) {
  FilterBench b;
  const auto n = static_cast<int>(state.range(0));
  std::vector<Signal*> signals;
  for (int s = 0; s < 10; ++s) signals.push_back(*b.monitor.add_signal("C.s" + std::to_string(s)));
  for (int i = 0; i < n; ++i) {
    b.add("Threshold",
          {{"input_signal", "s" + std::to_string(i % 10)}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}},
          ExecutionMode::Passive);
  }
  std::int64_t t = 0;
  for (auto _ : state) {
    ++t;
    for (Signal* s : signals) s->push(Time{t}, 1.0);
    b.monitor.tick(Time{t});
  }
  state.SetItemsProcessed(state.iterations() * n);
  if (b.co.coordinator_state() != State::Normal) state.SkipWithError("unexpected event");
}
BENCHMARK(BM_MonitorTick)->Arg(1000);

// One cycle of the control loop of `make bench-peers` item 4, without its real-time wait: N
// signals each get a new sample, then the component's ACTIVE filters run (a Threshold, a
// Watchdog and a MovingAverage per signal); no event. Its time per iteration over the 1 ms
// period is the CPU share of detection that the filters and signals cost, without the loop's
// sleep and wake-up (peer_detection measures those too, in real time).
void BM_DetectionCycle(benchmark::State& state) {
  FilterBench b;
  const auto n = static_cast<int>(state.range(0));
  std::vector<Signal*> signals;
  for (int i = 0; i < n; ++i) {
    const std::string s = "s" + std::to_string(i);
    signals.push_back(*b.monitor.add_signal("C." + s));
    b.add("Threshold",
          {{"input_signal", s}, {"threshold", 10.0}, {"hysteresis", 1.0}, {"event_onset", std::string("EVT_X")}});
    b.add("Watchdog", {{"input_signal", s}, {"timeout", 0.05}});
    b.add("MovingAverage", {{"input_signal", s}, {"window", 10.0}, {"output_signal", s + "_mean"}});
  }
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 1'000'000;  // 1 ms
    for (Signal* s : signals) s->push(Time{t}, 1.0);
    b.monitor.run_active(b.component, Time{t});
  }
  state.SetItemsProcessed(state.iterations() * n * 3);
  if (b.co.coordinator_state() != State::Normal) state.SkipWithError("unexpected event");
}
BENCHMARK(BM_DetectionCycle)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

// The floor of BM_DetectionCycle: N signals each get a new sample, and one cursor per signal reads
// it; nothing is judged. What any detection cycle over N signals costs in memory alone.
void BM_SignalCycle(benchmark::State& state) {
  FilterBench b;
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Signal*> signals;
  std::vector<SignalCursor> cursors;
  for (std::size_t i = 0; i < n; ++i) {
    signals.push_back(*b.monitor.add_signal("C.s" + std::to_string(i)));
    cursors.emplace_back(signals.back());
  }
  std::int64_t t = 0;
  double sum = 0.0;
  for (auto _ : state) {
    t += 1'000'000;  // 1 ms
    for (Signal* s : signals) s->push(Time{t}, 1.0);
    for (SignalCursor& c : cursors) {
      Time when{};
      double x = 0.0;
      if (c.take_single(when, &x)) sum += x;
    }
  }
  benchmark::DoNotOptimize(sum);
  if (sum != static_cast<double>(state.iterations() * static_cast<std::int64_t>(n))) {
    state.SkipWithError("a sample was not read");
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_SignalCycle)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

// One cycle of N timed tasks: each task's start and end checkpoints get a sample (the end 0.2 ms
// after the start), then one Deadline per task (2 ms) runs; no event. The second argument is 1
// when the Deadlines run in banks, 0 when they run as objects.
void BM_DeadlineCycle(benchmark::State& state) {
  FilterBench b(state.range(1) != 0);
  const auto n = static_cast<int>(state.range(0));
  std::vector<Signal*> starts;
  std::vector<Signal*> ends;
  for (int i = 0; i < n; ++i) {
    const std::string task = "task" + std::to_string(i);
    starts.push_back(*b.monitor.add_signal("C." + task + "_start"));
    ends.push_back(*b.monitor.add_signal("C." + task + "_end"));
    b.add("Deadline", {{"input_signals", std::vector<std::string>{task + "_start", task + "_end"}},
                       {"deadline", 0.002},
                       {"event_onset", std::string("EVT_X")}});
  }
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 1'000'000;  // 1 ms
    for (int i = 0; i < n; ++i) {
      starts[static_cast<std::size_t>(i)]->push(Time{t}, 1.0);
      ends[static_cast<std::size_t>(i)]->push(Time{t + 200'000}, 1.0);
    }
    b.monitor.run_active(b.component, Time{t + 300'000});
  }
  state.SetItemsProcessed(state.iterations() * n);
  if (b.co.coordinator_state() != State::Normal) state.SkipWithError("unexpected event");
}
BENCHMARK(BM_DeadlineCycle)->Args({100, 0})->Args({100, 1})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace safecass
