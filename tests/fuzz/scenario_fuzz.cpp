// libFuzzer target for the scenario reader (spec::load_scenario_text, docs/scenario-format.md):
// any bytes, as a scenario file. Beyond "no crash, no sanitizer report", it traps when a promise
// is broken: the scenario is there exactly when there is no diagnostic, every diagnostic says
// something and points inside the input, and the steps of a scenario are in time order.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_text.hpp"
#include "safecass/spec/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz-scenario.json";
  const spec::ScenarioLoad r = spec::load_scenario_text(std::string(text), name);
  if (r.scenario.has_value() != r.diagnostics.empty()) __builtin_trap();
  for (const spec::Diagnostic& d : r.diagnostics) {
    if (d.message.empty() || d.where.file != name || !inside(text, d.where.line, d.where.column)) __builtin_trap();
  }
  if (r.scenario) {
    const auto& steps = r.scenario->steps;
    const auto by_time = [](const spec::ScenarioStep& a, const spec::ScenarioStep& b) { return a.at < b.at; };
    if (!std::is_sorted(steps.begin(), steps.end(), by_time)) __builtin_trap();
    for (const spec::ScenarioStep& s : steps) {
      if (!(s.at >= 0.0) || !inside(text, s.line, s.column)) __builtin_trap();
    }
  }
  return 0;
}
