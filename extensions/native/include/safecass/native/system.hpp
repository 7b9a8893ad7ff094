#pragma once
/// @file system.hpp
/// A system run by the native runtime: the system file built by the one factory
/// (spec::build_instance) and a native runtime with one periodic task per local component — or
/// the list of every problem, each with its position, and nothing built.
///
/// `safecass run` (simulated and live), the console, the viewer, replay, trace and the examples
/// open their runnable system here, so they agree on its default periods:
/// - a component that names no `"period"` runs at the driver's tick: the scenario's period, or
///   kDefaultTick when nothing drives the system from a scenario (DESIGN §6);
/// - PASSIVE filters run at the monitor period, Monitor::kDefaultPeriod (5 ms).

#include <memory>
#include <string>

#include "safecass/core/clock.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/native/runtime.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/instance.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::native {

/// The tick of a system with no scenario, and so the period of its components that name none:
/// the scenario format's default period (DESIGN §6).
inline constexpr Time kDefaultTick = std::chrono::milliseconds(1);

struct SystemOptions {
  /// Build only this coordinator's components: one process of a multi-process system (the other
  /// coordinators' components are left for the middleware to connect). Empty: the whole system.
  std::string coordinator;
  /// The clock the coordinator reads (a live process passes the host clock). Null: a simulated
  /// clock owned by the System, set by a simulated-time driver.
  Clock* clock = nullptr;
  /// The period of a component that names none.
  Time component_period = kDefaultTick;
};

/// A built system. Owns, in construction order, its clock (when simulated), the instance (its
/// specification, coordinator and monitor) and the native runtime; the runtime is stopped before
/// the rest is destroyed.
class System {
public:
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  const spec::SystemSpec& spec() const noexcept { return instance_->spec(); }
  Coordinator& coordinator() noexcept { return instance_->coordinator(); }
  const Coordinator& coordinator() const noexcept { return instance_->coordinator(); }
  Monitor& monitor() noexcept { return instance_->monitor(); }
  Runtime& runtime() noexcept { return runtime_; }
  /// The clock a simulated-time driver sets; null when the system reads an outside clock.
  SimulatedClock* simulated_clock() noexcept { return own_clock_.get(); }

private:
  friend spec::Opened<std::unique_ptr<System>> build_system(spec::SystemSpec, const FilterRegistry&,
                                                            const SystemOptions&);
  System(std::unique_ptr<SimulatedClock> clock, std::unique_ptr<spec::Instance> instance);

  std::unique_ptr<SimulatedClock> own_clock_;
  std::unique_ptr<spec::Instance> instance_;
  Runtime runtime_;
};

/// Builds a loaded specification (spec::build_instance) and adds each local component's task.
/// `registry` must outlive the System.
[[nodiscard]] spec::Opened<std::unique_ptr<System>> build_system(spec::SystemSpec system,
                                                                 const FilterRegistry& registry,
                                                                 const SystemOptions& options = {});

/// Loads the system file and builds it. Diagnostics that are not errors (warnings, notes) are
/// appended to `notes` when given; errors are the unexpected side and nothing is built.
[[nodiscard]] spec::Opened<std::unique_ptr<System>> open_system(const std::string& path, const FilterRegistry& registry,
                                                                const SystemOptions& options = {},
                                                                spec::Diagnostics* notes = nullptr);

}  // namespace safecass::native
