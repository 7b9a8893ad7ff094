// `make bench-verify`: how long `safecass verify` takes and how much memory it needs, on robodoc
// and on a generated 50-component system (the scale benchmark's tree, with hazards). Writes one
// JSON file (default build/bench-verify.json). Targets (docs/benchmarks.md): robodoc <= 10 s, the
// 50-component tree <= 120 s, memory <= 4 GB. Wall-clock times: they include compiling SPIN's
// verifiers with the system's C compiler, and depend on the machine's load.
//
// Usage: bench_verify [OUT.json] [--components N] [--write-tree FILE]
// (--write-tree writes the generated system file and exits, to run `safecass verify` on it.)

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "hazard_tree.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/bus.hpp"
#include "safecass/verify/verify.hpp"

namespace {

using namespace safecass;

struct Figures {
  double seconds = 0;
  double max_pan_mb = 0;
  std::uint64_t max_states = 0;
  std::size_t properties = 0;
  std::size_t holds = 0;
  std::size_t onsets = 0;
  int exit = 0;
};

Figures run(const spec::SystemSpec& system, const FilterRegistry& registry) {
  Figures f;
  const auto start = std::chrono::steady_clock::now();
  auto report = verify::verify(system, registry, verify::Options{});
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!report) {
    std::fprintf(stderr, "bench_verify: %s\n", report.error().message.c_str());
    f.exit = 2;
    return f;
  }
  f.exit = report->exit_code();
  for (const verify::PropertyResult& p : report->properties) {
    if (p.structural) continue;
    ++f.properties;
    if (p.verdict == verify::PropertyResult::Verdict::Holds) ++f.holds;
    f.max_pan_mb = std::max(f.max_pan_mb, p.memory_mb);
    f.max_states = std::max(f.max_states, p.states);
    f.onsets = p.onsets_total;
  }
  return f;
}

std::string json(const char* name, const Figures& f, double target_s) {
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "    { \"name\": \"%s\", \"seconds\": %.3f, \"target_seconds\": %.0f, \"properties\": %zu, \"holds\": %zu, "
      "\"onsets\": %zu, \"max_states\": %llu, \"max_pan_memory_mb\": %.1f, \"exit\": %d }",
      name, f.seconds, target_s, f.properties, f.holds, f.onsets, static_cast<unsigned long long>(f.max_states),
      f.max_pan_mb, f.exit);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "build/bench-verify.json";
  int n = 50;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--components") == 0 && i + 1 < argc) {
      n = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--write-tree") == 0 && i + 1 < argc) {
      std::ofstream(argv[++i]) << bench::hazard_tree(n) << "\n";
      return 0;
    } else {
      out = argv[i];
    }
  }
  FilterRegistry registry;
  register_builtin_filters(registry);
  const spec::LoadResult robodoc = spec::load_system("examples/robodoc/robodoc.json", registry);
  if (!robodoc.ok()) {
    std::fprintf(stderr, "bench_verify: run from the source root (examples/robodoc/robodoc.json)\n");
    return 2;
  }
  const Figures r = run(*robodoc.system, registry);
  std::printf("robodoc: %.2f s, %zu/%zu properties hold, at most %.1f MB in SPIN (target 10 s)\n", r.seconds, r.holds,
              r.properties, r.max_pan_mb);
  const spec::LoadResult tree = spec::load_system_from_text(bench::hazard_tree(n), "tree.json", registry);
  if (!tree.ok()) {
    std::fprintf(stderr, "bench_verify: the generated tree does not load: %s\n",
                 spec::format(tree.diagnostics.at(0)).c_str());
    return 2;
  }
  const Figures t = run(*tree.system, registry);
  std::printf(
      "tree of %d components: %.2f s, %zu/%zu properties hold, %zu onsets, at most %llu states and %.1f MB in SPIN "
      "(target 120 s, 4 GB)\n",
      n, t.seconds, t.holds, t.properties, t.onsets, static_cast<unsigned long long>(t.max_states), t.max_pan_mb);
  // The bus protocol of robodoc's deployment (verify --bus): every pattern, every fault class.
  Figures b;
  {
    const auto start = std::chrono::steady_clock::now();
    auto report = verify::verify_bus(*robodoc.system, verify::BusOptions{});
    b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!report) {
      std::fprintf(stderr, "bench_verify: %s\n", report.error().message.c_str());
      b.exit = 2;
    } else {
      b.exit = report->exit_code();
      for (const verify::BusProperty& p : report->properties) {
        ++b.properties;
        if (p.verdict == verify::BusVerdict::Holds) ++b.holds;
      }
      for (const verify::BusSearch& s : report->searches) {
        b.max_pan_mb = std::max(b.max_pan_mb, s.memory_mb);
        b.max_states = std::max(b.max_states, s.states);
      }
    }
  }
  std::printf(
      "robodoc's bus (verify --bus): %.2f s, %zu/%zu properties hold, at most %llu states and %.1f MB per "
      "search (target 60 s, 2 GB)\n",
      b.seconds, b.holds, b.properties, static_cast<unsigned long long>(b.max_states), b.max_pan_mb);
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  const double child_mb =
      static_cast<double>(usage.ru_maxrss) / 1024.0;  // largest child: SPIN, the compiler or a verifier
  std::printf("largest child process (SPIN, the C compiler or a verifier): %.1f MB resident\n", child_mb);
  std::ofstream f(out);
  f << "{\n  \"context\": { \"note\": \"wall-clock seconds of safecass verify, including compiling SPIN's verifiers; "
       "they "
       "depend on the machine's load\", \"max_child_resident_mb\": "
    << child_mb << " },\n  \"benchmarks\": [\n"
    << json("robodoc", r, 10) << ",\n"
    << json(("tree_" + std::to_string(n)).c_str(), t, 120) << ",\n"
    << json("robodoc_bus", b, 60) << "\n  ]\n}\n";
  std::printf("wrote %s\n", out.c_str());
  const bool ok = r.exit == 0 && t.exit == 0 && b.exit == 0;
  return ok ? 0 : 1;
}
