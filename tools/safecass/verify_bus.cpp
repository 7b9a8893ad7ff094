// `safecass verify --bus SYSTEM [--mutants] [--json]` (docs/verify.md "The bus").

#include <cstdio>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/json/write.hpp"
#include "safecass/spec/load.hpp"
#include "verify_command.hpp"

namespace safecass::tools {

namespace {

std::string pairs_text(const verify::BusPattern& p) {
  std::string r;
  for (const std::string& pair : p.pairs) r += (r.empty() ? "" : ", ") + pair;
  return r;
}

/// The mutation check: every mutant must be caught by some property.
int run_mutants(const spec::SystemSpec& system, verify::BusOptions options, bool json) {
  bool all_caught = true;
  if (!json) std::printf("%-22s %-9s %-14s %s\n", "mutant", "caught by", "fault class", "what it removes");
  for (const verify::BusMutant& m : verify::bus_mutants()) {
    options.mutant = m.name;
    options.first_violation = true;
    auto report = verify::verify_bus(system, options);
    if (!report) {
      std::fprintf(stderr, "verify --bus: %s\n", report.error().message.c_str());
      return 2;
    }
    std::string by = "nothing", in;
    for (const verify::BusSearch& s : report->searches) {
      if (s.verdict != verify::BusVerdict::Violated) continue;
      by = s.property;
      in = s.fault_class;
      break;
    }
    all_caught = all_caught && by != "nothing";
    if (json) {
      std::printf("%s\n", json::JsonObject()
                              .str("kind", "mutant")
                              .str("name", m.name)
                              .str("removes", m.text)
                              .str("caught_by", by)
                              .str("fault_class", in)
                              .text()
                              .c_str());
    } else {
      std::printf("%-22s %-9s %-14s %s\n", m.name.c_str(), by.c_str(), in.c_str(), m.text.c_str());
    }
  }
  return all_caught ? 0 : 1;
}

}  // namespace

int run_verify_bus(const std::string& system_path, const verify::BusOptions& options, bool json, bool mutants) {
  spec::LoadResult loaded;
  const spec::SystemSpec* system = load_to_verify(system_path, "verify --bus", loaded);
  if (system == nullptr) return 2;
  if (mutants) return run_mutants(*system, options, json);
  auto report = verify::verify_bus(*system, options);
  if (!report) {
    std::fprintf(stderr, "verify --bus: %s\n", report.error().message.c_str());
    return 2;
  }
  if (report->patterns.empty()) {
    std::printf("%s: one process, no bus to check (no \"coordinators\" in the system file)\n", report->system.c_str());
    return 0;
  }
  if (json) {
    for (const verify::BusSearch& s : report->searches) {
      json::JsonObject line;
      line.str("kind", "search")
          .str("pairs", pairs_text(report->patterns[s.pattern]))
          .str("fault_class", s.fault_class)
          .str("result", verify::to_string(s.verdict))
          .integer("states", static_cast<long long>(s.states))
          .raw("memory_mb", fixed3(s.memory_mb))
          .raw("seconds", fixed3(s.seconds));
      if (!s.property.empty()) line.str("property", s.property);
      std::printf("%s\n", line.text().c_str());
    }
    for (const verify::BusProperty& p : report->properties) {
      std::printf("%s\n", json::JsonObject()
                              .str("kind", "bus-property")
                              .str("name", p.name)
                              .str("result", verify::to_string(p.verdict))
                              .str("checks", p.text)
                              .integer("states", static_cast<long long>(p.states))
                              .raw("memory_mb", fixed3(p.memory_mb))
                              .raw("seconds", fixed3(p.seconds))
                              .text()
                              .c_str());
    }
    std::printf("%s\n", json::JsonObject()
                            .str("kind", "summary")
                            .str("system", report->system)
                            .raw("seconds", fixed3(report->seconds))
                            .integer("exit", report->exit_code())
                            .text()
                            .c_str());
    return report->exit_code();
  }
  std::printf("%s: the bus protocol, %zu pattern(s) of provider and receiver; %s\n", report->system.c_str(),
              report->patterns.size(), report->bounds.c_str());
  for (std::size_t i = 0; i < report->patterns.size(); ++i) {
    const verify::BusPattern& p = report->patterns[i];
    std::printf("pattern %zu: %s (%zu stream(s) held, %zu modelled)\n", i + 1, pairs_text(p).c_str(), p.streams_total,
                p.streams);
    for (const verify::BusSearch& s : report->searches) {
      if (s.pattern != i) continue;
      std::printf("  %-14s %-9s %llu states, %.1f MB, %.2f s%s%s\n", s.fault_class.c_str(),
                  std::string(verify::to_string(s.verdict)).c_str(), static_cast<unsigned long long>(s.states),
                  s.memory_mb, s.seconds, s.property.empty() ? "" : ": ", s.property.c_str());
      if (!s.detail.empty()) std::printf("    %s\n", s.detail.c_str());
    }
  }
  for (const verify::BusProperty& p : report->properties) {
    std::printf("%s %-9s %llu states, %.1f MB, %.2f s: %s\n", p.name.c_str(),
                std::string(verify::to_string(p.verdict)).c_str(), static_cast<unsigned long long>(p.states),
                p.memory_mb, p.seconds, p.text.c_str());
  }
  for (const verify::BusSearch& s : report->searches) {
    if (s.verdict != verify::BusVerdict::Violated) continue;
    std::printf("counterexample to %s (%s, fault class %s), P the provider, R the receiver:\n", s.property.c_str(),
                pairs_text(report->patterns[s.pattern]).c_str(), s.fault_class.c_str());
    for (const std::string& line : s.trace) std::printf("  %s\n", line.c_str());
  }
  std::printf("%s: bus protocol %s (%.2f s, every search exhaustive within its fault class)\n", report->system.c_str(),
              report->exit_code() == 0   ? "proved"
              : report->exit_code() == 1 ? "VIOLATED"
                                         : "not decided",
              report->seconds);
  return report->exit_code();
}

}  // namespace safecass::tools
