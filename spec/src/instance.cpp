#include "safecass/spec/instance.hpp"

#include "safecass/spec/load.hpp"

namespace safecass::spec {

namespace {

/// A problem of the whole system file (no better position is known).
Diagnostic at_file(const std::string& file, std::string message) {
  return Diagnostic{Diagnostic::Severity::Error, Position{file, 1, 1}, std::move(message), ""};
}

}  // namespace

std::string coordinator_name(const SystemSpec& system, const InstanceOptions& options) {
  if (!options.coordinator.empty()) return options.coordinator;
  if (!options.name.empty()) return options.name;
  return system.name.empty() ? "system" : system.name;
}

Instance::Instance(SystemSpec spec, const FilterRegistry& registry, const InstanceOptions& options)
    : spec_(std::move(spec)),
      registry_(registry),
      coordinator_(coordinator_name(spec_, options), options.clock, options.coordinator_options),
      monitor_(coordinator_, registry, options.signal_history) {}

Instance::~Instance() = default;

[[nodiscard]] Opened<std::unique_ptr<Instance>> build_instance(SystemSpec system, const FilterRegistry& registry,
                                                               const InstanceOptions& options) {
  const std::string file = system.path;
  std::unique_ptr<Instance> built(new Instance(std::move(system), registry, options));
  if (auto r = instantiate(built->spec_, built->coordinator_, built->monitor_, options.coordinator); !r) {
    return tl::unexpected(Diagnostics{at_file(file, r.error().message)});
  }
  return built;
}

[[nodiscard]] Opened<SystemSpec> load_valid_system(const std::string& path, const FilterRegistry& registry,
                                                   Diagnostics* notes) {
  LoadResult loaded = load_system(path, registry);
  Diagnostics errors = keep_errors(std::move(loaded.diagnostics), notes);
  if (!errors.empty()) return tl::unexpected(std::move(errors));
  if (!loaded.system) return tl::unexpected(Diagnostics{at_file(path, "cannot load system '" + path + "'")});
  return std::move(*loaded.system);
}

[[nodiscard]] Opened<std::unique_ptr<Instance>> open_instance(const std::string& path, const FilterRegistry& registry,
                                                              const InstanceOptions& options, Diagnostics* notes) {
  auto system = load_valid_system(path, registry, notes);
  if (!system) return tl::unexpected(std::move(system.error()));
  return build_instance(std::move(*system), registry, options);
}

}  // namespace safecass::spec
