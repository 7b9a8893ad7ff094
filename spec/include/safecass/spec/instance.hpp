#pragma once
/// @file instance.hpp
/// The one factory of a system: a specification becomes a coordinator and its monitor with the
/// specified components, connections, signals and filters, owned together — or the list of every
/// problem, each with its position, and nothing built.
///
/// Every program that puts a system together builds it here with the filter registry it is given
/// (an application's own filter types included): the native runtime and the scenario runner, the
/// supervisor's model, the viewer's picture of each coordinator, verify's model and the ROS
/// bridges' shadows.

#include <cstddef>
#include <memory>
#include <string>

#include "safecass/core/clock.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::spec {

struct InstanceOptions {
  /// Build only this coordinator's components: one process of a multi-process system (the other
  /// coordinators' components are left for the middleware to connect). It also names the
  /// Coordinator. Empty: the whole system.
  std::string coordinator;
  /// The Coordinator's name when the whole system is built. Empty: the system's name, or
  /// "system" when it has none.
  std::string name;
  /// The clock the coordinator reads; it must outlive the Instance. Null: the host's steady clock.
  const Clock* clock = nullptr;
  CoordinatorOptions coordinator_options;
  /// Samples each signal keeps.
  std::size_t signal_history = Monitor::kDefaultSignalHistory;
};

/// A built system: its specification, the coordinator and the monitor, in construction order.
class Instance {
public:
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  ~Instance();

  const SystemSpec& spec() const noexcept { return spec_; }
  Coordinator& coordinator() noexcept { return coordinator_; }
  const Coordinator& coordinator() const noexcept { return coordinator_; }
  Monitor& monitor() noexcept { return monitor_; }
  const Monitor& monitor() const noexcept { return monitor_; }
  const FilterRegistry& registry() const noexcept { return registry_; }

private:
  friend Opened<std::unique_ptr<Instance>> build_instance(SystemSpec, const FilterRegistry&, const InstanceOptions&);
  Instance(SystemSpec spec, const FilterRegistry& registry, const InstanceOptions& options);

  SystemSpec spec_;
  const FilterRegistry& registry_;
  Coordinator coordinator_;
  Monitor monitor_;
};

/// The name build_instance() gives the Coordinator (InstanceOptions::coordinator, ::name, the system's).
std::string coordinator_name(const SystemSpec& system, const InstanceOptions& options);

/// Builds a loaded specification (load_system() reported no error): the (local) components, their
/// filters and connections. `registry` must outlive the Instance. An error is one diagnostic at
/// the system file that names what could not be built.
[[nodiscard]] Opened<std::unique_ptr<Instance>> build_instance(SystemSpec system, const FilterRegistry& registry,
                                                               const InstanceOptions& options = {});

/// Loads the system file (load_system()): the specification, or its errors. Diagnostics that are
/// not errors (warnings, notes) are appended to `notes` when given.
[[nodiscard]] Opened<SystemSpec> load_valid_system(const std::string& path, const FilterRegistry& registry,
                                                   Diagnostics* notes = nullptr);

/// Loads the system file and builds it. Diagnostics that are not errors (warnings, notes) are
/// appended to `notes` when given; errors are the unexpected side and nothing is built.
[[nodiscard]] Opened<std::unique_ptr<Instance>> open_instance(const std::string& path, const FilterRegistry& registry,
                                                              const InstanceOptions& options = {},
                                                              Diagnostics* notes = nullptr);

}  // namespace safecass::spec
