#include "safecass/native/system.hpp"

namespace safecass::native {

System::System(std::unique_ptr<SimulatedClock> clock, std::unique_ptr<spec::Instance> instance)
    : own_clock_(std::move(clock)),
      instance_(std::move(instance)),
      runtime_(instance_->monitor(), Monitor::kDefaultPeriod) {}

System::~System() { runtime_.stop(); }

[[nodiscard]] spec::Opened<std::unique_ptr<System>> build_system(spec::SystemSpec system,
                                                                 const FilterRegistry& registry,
                                                                 const SystemOptions& options) {
  auto clock = options.clock == nullptr ? std::make_unique<SimulatedClock>() : nullptr;
  spec::InstanceOptions instance_options;
  instance_options.coordinator = options.coordinator;
  instance_options.clock = options.clock != nullptr ? options.clock : clock.get();
  auto instance = spec::build_instance(std::move(system), registry, instance_options);
  if (!instance) return tl::unexpected(std::move(instance.error()));
  std::unique_ptr<System> built(new System(std::move(clock), std::move(*instance)));
  spec::Diagnostics problems;
  for (const spec::ComponentSpec& c : built->spec().components) {
    auto id = built->coordinator().structure().find_component(c.name);
    if (!id) continue;  // another coordinator's component: connected by the middleware, not run here
    const Time period = c.period ? seconds_to_time(*c.period) : options.component_period;
    if (auto r = built->runtime_.add_task(*id, period); !r) {
      problems.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, c.where, r.error().message, ""});
    }
  }
  if (!problems.empty()) return tl::unexpected(std::move(problems));
  return built;
}

[[nodiscard]] spec::Opened<std::unique_ptr<System>> open_system(const std::string& path, const FilterRegistry& registry,
                                                                const SystemOptions& options,
                                                                spec::Diagnostics* notes) {
  auto system = spec::load_valid_system(path, registry, notes);
  if (!system) return tl::unexpected(std::move(system.error()));
  return build_system(std::move(*system), registry, options);
}

}  // namespace safecass::native
