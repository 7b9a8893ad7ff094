#include "safecass/runner/system.hpp"

#include <algorithm>
#include <cstdio>

#include "safecass/spec/load.hpp"

namespace safecass::runner {

namespace {

std::string coordinator_name(const spec::SystemSpec& system, const SystemOptions& options) {
  if (!options.coordinator.empty()) return options.coordinator;
  return system.name.empty() ? "system" : system.name;
}

/// A problem of the whole system file (no better position is known).
spec::Diagnostic at_file(const std::string& file, std::string message) {
  return spec::Diagnostic{spec::Diagnostic::Severity::Error, spec::Position{file, 1, 1}, std::move(message), ""};
}

}  // namespace

System::System(spec::SystemSpec spec, const FilterRegistry& registry, const SystemOptions& options)
    : spec_(std::move(spec)),
      own_clock_(options.clock == nullptr ? std::make_unique<SimulatedClock>() : nullptr),
      coordinator_(coordinator_name(spec_, options), options.clock != nullptr ? options.clock : own_clock_.get()),
      monitor_(coordinator_, registry),
      runtime_(monitor_, Monitor::kDefaultPeriod) {}

System::~System() { runtime_.stop(); }

[[nodiscard]] Opened<std::unique_ptr<System>> build_system(spec::SystemSpec system, const FilterRegistry& registry,
                                                           const SystemOptions& options) {
  const std::string file = system.path;
  std::unique_ptr<System> built(new System(std::move(system), registry, options));
  Coordinator& co = built->coordinator_;
  if (auto r = spec::instantiate(built->spec_, co, built->monitor_, options.coordinator); !r) {
    return tl::unexpected(Diagnostics{at_file(file, r.error().message)});
  }
  Diagnostics problems;
  for (const spec::ComponentSpec& c : built->spec_.components) {
    auto id = co.find_component(c.name);
    if (!id) continue;  // another coordinator's component: connected by the middleware, not run here
    const Time period = c.period ? seconds_to_time(*c.period) : options.component_period;
    if (auto r = built->runtime_.add_task(*id, period); !r) {
      problems.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, c.where, r.error().message, ""});
    }
  }
  if (!problems.empty()) return tl::unexpected(std::move(problems));
  return built;
}

[[nodiscard]] Opened<std::unique_ptr<System>> open_system(const std::string& path, const FilterRegistry& registry,
                                                          const SystemOptions& options, Diagnostics* notes) {
  spec::LoadResult loaded = spec::load_system(path, registry);
  Diagnostics errors = keep_errors(std::move(loaded.diagnostics), notes);
  if (!errors.empty()) return tl::unexpected(std::move(errors));
  if (!loaded.system) return tl::unexpected(Diagnostics{at_file(path, "cannot load system '" + path + "'")});
  return build_system(std::move(*loaded.system), registry, options);
}

Diagnostics keep_errors(Diagnostics diagnostics, Diagnostics* notes) {
  Diagnostics errors;
  for (spec::Diagnostic& d : diagnostics) {
    if (d.severity == spec::Diagnostic::Severity::Error)
      errors.push_back(std::move(d));
    else if (notes != nullptr)
      notes->push_back(std::move(d));
  }
  return errors;
}

void print(const Diagnostics& diagnostics, std::FILE* out) {
  for (const spec::Diagnostic& d : diagnostics) std::fprintf(out, "%s\n", spec::format(d).c_str());
}

std::string to_text(const Diagnostics& diagnostics) {
  std::string text;
  for (const spec::Diagnostic& d : diagnostics) text += (text.empty() ? "" : "\n") + spec::format(d);
  return text;
}

}  // namespace safecass::runner
