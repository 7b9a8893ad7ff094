#include <benchmark/benchmark.h>

#include "safecass/core/clock.hpp"

// Baseline: the cost of reading the simulated clock, the time source of every record.
static void BM_SimulatedClockNow(benchmark::State& state) {
  safecass::SimulatedClock clock;
  for (auto _ : state) benchmark::DoNotOptimize(clock.now());
}
BENCHMARK(BM_SimulatedClockNow);
