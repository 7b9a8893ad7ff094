#pragma once
/// @file system.hpp
/// The one way every tool puts a system together. A system file becomes a coordinator, its
/// monitor with the specified filters, and a native runtime with one periodic task per local
/// component — or the list of every problem, each with its position, and nothing built.
///
/// `safecass run` (simulated and live), the console, the viewer and the examples all open their
/// system here, so they agree on what a system is and on its default periods:
/// - a component that names no `"period"` runs at the driver's tick: the scenario's period, or
///   kDefaultTick when nothing drives the system from a scenario (DESIGN §6);
/// - PASSIVE filters run at the monitor period, Monitor::kDefaultPeriod (5 ms).

#include <memory>
#include <string>
#include <vector>

#include <tl/expected.hpp>

#include "safecass/core/clock.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/native/runtime.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::runner {

/// Every problem found while opening, each with its file:line:col.
using Diagnostics = std::vector<spec::Diagnostic>;
/// A value, or every problem that kept it from being built.
template <class T>
using Opened = tl::expected<T, Diagnostics>;

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

/// A built system. Owns, in construction order, its specification, its clock (when simulated),
/// the coordinator, the monitor and the native runtime; the runtime is stopped before the rest is
/// destroyed.
class System {
public:
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  const spec::SystemSpec& spec() const noexcept { return spec_; }
  Coordinator& coordinator() noexcept { return coordinator_; }
  const Coordinator& coordinator() const noexcept { return coordinator_; }
  Monitor& monitor() noexcept { return monitor_; }
  native::Runtime& runtime() noexcept { return runtime_; }
  /// The clock a simulated-time driver sets; null when the system reads an outside clock.
  SimulatedClock* simulated_clock() noexcept { return own_clock_.get(); }

private:
  friend Opened<std::unique_ptr<System>> build_system(spec::SystemSpec, const FilterRegistry&, const SystemOptions&);
  System(spec::SystemSpec spec, const FilterRegistry& registry, const SystemOptions& options);

  spec::SystemSpec spec_;
  std::unique_ptr<SimulatedClock> own_clock_;
  Coordinator coordinator_;
  Monitor monitor_;
  native::Runtime runtime_;
};

/// Builds a loaded specification: instantiates the (local) components, their filters and
/// connections, and adds each local component's task. `registry` must outlive the System.
[[nodiscard]] Opened<std::unique_ptr<System>> build_system(spec::SystemSpec system, const FilterRegistry& registry,
                                                           const SystemOptions& options = {});

/// Loads the system file and builds it. Diagnostics that are not errors (warnings, notes) are
/// appended to `notes` when given; errors are the unexpected side and nothing is built.
[[nodiscard]] Opened<std::unique_ptr<System>> open_system(const std::string& path, const FilterRegistry& registry,
                                                          const SystemOptions& options = {},
                                                          Diagnostics* notes = nullptr);

/// Keeps the errors of `diagnostics` and moves the others (warnings, notes) to `notes`, or drops
/// them when `notes` is null. Returns the errors, in their order.
Diagnostics keep_errors(Diagnostics diagnostics, Diagnostics* notes);

/// Prints each diagnostic on its own line (spec::format) to `out`.
void print(const Diagnostics& diagnostics, std::FILE* out);
/// The diagnostics as text, one per line, for an Error message.
std::string to_text(const Diagnostics& diagnostics);

}  // namespace safecass::runner
