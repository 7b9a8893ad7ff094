// `safecass analyze` (docs/analyze.md): the FMEA, the fault trees (SCRAM included) and the safety
// case of robodoc, and the FMEA and fault trees of a generated system of 1,000 components (the
// verify benchmark's tree: the read model's scale shape, with a hazard per component). Targets
// (docs/benchmarks.md): robodoc <= 2 s; 1,000 components <= 30 s and <= 1 GB (peak_rss_mb, the
// process's peak resident memory after the run), cut sets up to order 3.

#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "hazard_tree.hpp"
#include "safecass/analyze/analyze.hpp"
#include "safecass/filters/registry.hpp"

namespace {

void analyze(benchmark::State& state, const std::string& system) {
  safecass::FilterRegistry registry;
  safecass::register_builtin_filters(registry);
  safecass::analyze::AnalyzeOptions options;
  options.system = system;
  options.order = 3;
  std::size_t modes = 0, cut_sets = 0;
  for (auto _ : state) {
    auto a = safecass::analyze::build_analysis(options, registry);
    if (!a) {
      state.SkipWithError(("the analysis failed: " + a.error().front().message).c_str());
      return;
    }
    modes = a->modes.size();
    cut_sets = 0;
    for (const auto& t : a->trees.tops) cut_sets += t.cut_sets.size();
    benchmark::DoNotOptimize(a->safety_case.nodes.size());
  }
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  state.counters["failure_modes"] = static_cast<double>(modes);
  state.counters["cut_sets"] = static_cast<double>(cut_sets);
  state.counters["peak_rss_mb"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void BM_AnalyzeRobodoc(benchmark::State& state) {
  analyze(state, std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json");
}
BENCHMARK(BM_AnalyzeRobodoc)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Analyze1000Components(benchmark::State& state) {
  const std::string path = "/tmp/safecass-bench-analyze-" + std::to_string(::getpid()) + ".json";
  std::ofstream(path) << safecass::bench::hazard_tree(1000) << "\n";
  analyze(state, path);
  std::remove(path.c_str());
}
BENCHMARK(BM_Analyze1000Components)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
