// `safecass trace` at scale (docs/trace.md, "Speed"): 100 scenarios of robodoc's size, run with the
// normal runner and traced (matrix, gaps, coverage). Target: at most 5 s for the 100.

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "safecass/filters/registry.hpp"
#include "safecass/trace/trace.hpp"

namespace {

void BM_Trace100Scenarios(benchmark::State& state) {
  safecass::FilterRegistry registry;
  safecass::register_builtin_filters(registry);
  const std::string dir = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/";
  safecass::trace::TraceOptions options;
  options.system = dir + "robodoc.json";
  // robodoc's four scenarios in turn: the 2 s story, the fault injection, the warnings, the overload.
  const std::vector<std::string> kinds{dir + "story.json", dir + "injection.json", dir + "warnings.json",
                                       dir + "overload.json"};
  for (int k = 0; k < 100; ++k) options.scenarios.push_back(kinds[static_cast<std::size_t>(k) % kinds.size()]);
  for (auto _ : state) {
    auto trace = safecass::trace::build_trace(options, registry);
    if (!trace) {
      state.SkipWithError("the robodoc trace failed");
      return;
    }
    benchmark::DoNotOptimize(trace->gaps.size());
  }
  state.counters["scenarios"] = 100;
}
BENCHMARK(BM_Trace100Scenarios)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
