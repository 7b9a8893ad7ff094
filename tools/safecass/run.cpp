// `safecass run` and `safecass test`.

#include <cstdio>
#include <fstream>
#include <map>

#include "commands.hpp"
#ifdef SAFECASS_WITH_ICE
#include "middleware_commands.hpp"
#endif
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/runner/scenario_runner.hpp"

namespace safecass::tools {

int run_run(const RunArgs& args) {
#ifdef SAFECASS_WITH_ICE
  if (!args.coordinator.empty()) return run_coordinator(args);
#endif
  if (args.scenario.empty()) {
    std::fprintf(stderr,
                 "safecass run: --scenario is required (unless --coordinator runs one coordinator in real time)\n");
    return 2;
  }
  const FilterRegistry& registry = builtin_filters();
  runner::RunOptions options;
  options.json = args.json;
  options.record_path = args.record;
  options.inputs_path = args.record_inputs;
  options.limits.max_bytes = args.max_bytes;
  options.system_override = args.system;
  runner::RunResult result;
  const int code = runner::run_scenario_file(args.scenario, registry, options, &result);
  if (code == 2 && result.history_complete()) return 2;  // invalid input: nothing ran
  if (!args.json) {
    std::printf("%s: %d expectation%s checked, %zu failed%s\n", args.scenario.c_str(), result.checks,
                result.checks == 1 ? "" : "s", result.failures.size(),
                result.history_complete() ? "" : "; the history file is incomplete (see above)");
  }
  return code;
}

int run_test(const TestArgs& args) {
  const FilterRegistry& registry = builtin_filters();
  struct Case {
    std::string name;
    int code;
    runner::RunResult result;
  };
  std::vector<Case> cases;
  runner::Coverage total;
  for (const std::string& path : args.scenarios) {
    runner::RunOptions options;
    options.quiet = true;
    Case c{path, 0, {}};
    c.code = runner::run_scenario_file(path, registry, options, &c.result);
    std::printf("%-6s %s (%d checks)\n",
                c.code == 0   ? "PASS"
                : c.code == 1 ? "FAIL"
                              : "ERROR",
                path.c_str(), c.result.checks);
    total.events_fired.insert(c.result.coverage.events_fired.begin(), c.result.coverage.events_fired.end());
    total.taken.insert(c.result.coverage.taken.begin(), c.result.coverage.taken.end());
    total.defined.insert(c.result.coverage.defined.begin(), c.result.coverage.defined.end());
    cases.push_back(std::move(c));
  }
  std::size_t passed = 0;
  for (const Case& c : cases) passed += c.code == 0 ? 1 : 0;
  std::printf("\n%zu of %zu scenarios passed\n", passed, cases.size());

  std::printf("\nCoverage\n  events fired (%zu):", total.events_fired.size());
  for (const std::string& e : total.events_fired) std::printf(" %s", e.c_str());
  std::printf("\n  transitions taken (%zu):", total.taken.size());
  for (const auto& [e, t] : total.taken) std::printf(" %s:%s", e.c_str(), t.c_str());
  std::size_t never = 0;
  std::string never_list;
  for (const auto& d : total.defined) {
    if (total.taken.count(d) == 0) {
      ++never;
      never_list += " " + d.first + ":" + d.second;
    }
  }
  std::printf("\n  defined transitions never taken (%zu of %zu):%s\n", never, total.defined.size(), never_list.c_str());

  if (!args.junit.empty()) {
    std::ofstream xml(args.junit);
    if (!xml) {
      std::fprintf(stderr, "cannot write %s\n", args.junit.c_str());
      return 2;
    }
    xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuite name=\"safecass\" tests=\"" << cases.size()
        << "\" failures=\"" << cases.size() - passed << "\">\n";
    for (const Case& c : cases) {
      xml << "  <testcase name=\"" << introspect::markup_text(c.name) << "\" classname=\"scenario\">\n";
      if (c.code == 2) xml << "    <error message=\"invalid scenario or system\"/>\n";
      for (const std::string& f : c.result.failures)
        xml << "    <failure message=\"" << introspect::markup_text(f) << "\"/>\n";
      xml << "  </testcase>\n";
    }
    xml << "</testsuite>\n";
  }
  for (const Case& c : cases) {
    if (c.code == 2) return 2;
  }
  return passed == cases.size() ? 0 : 1;
}

}  // namespace safecass::tools
