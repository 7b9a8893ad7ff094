#pragma once
/// @file monitor.hpp
/// The filters of one coordinator: its signals, its filter instances, and the monitor thread that
/// runs PASSIVE filters (DESIGN §3, §4).
///
/// Lifecycle: configure (add_signal, add_filter, add_pipeline) → run: the framework extension
/// calls run_active(component, now) from each component's loop; PASSIVE filters run from tick(now),
/// called either by the monitor thread (start()/stop(), real time, default period 5 ms) or by a
/// simulation driver on the simulated clock. Configuration must finish before running.

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/filter.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/filters/signal.hpp"

namespace safecass {

namespace detail {
class Banks;
}

class Monitor {
public:
  static constexpr std::chrono::nanoseconds kDefaultPeriod = std::chrono::milliseconds(5);
  /// Samples each signal keeps by default.
  static constexpr std::size_t kDefaultSignalHistory = 1024;

  /// `coordinator` and `registry` must outlive the monitor. `banks` false runs every filter as an
  /// object (docs/filters.md, "Filter banks": the reference the banks are tested against).
  Monitor(Coordinator& coordinator, const FilterRegistry& registry, std::size_t signal_history = kDefaultSignalHistory,
          bool banks = true);
  ~Monitor();
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;

  Coordinator& coordinator() noexcept { return coordinator_; }
  SignalRegistry& signals() noexcept { return signals_; }
  const SignalRegistry& signals() const noexcept { return signals_; }

  /// Declares signal "Component.signal" of `size` doubles. Errors: NotFound (component),
  /// InvalidArgument, Duplicate (different size).
  [[nodiscard]] Expected<Signal*> add_signal(std::string_view name, std::size_t size = 1);

  /// Creates a filter: checks its type, parameters, target, events and input/output sizes; on any
  /// error nothing is created and the message names the filter and the parameter.
  [[nodiscard]] Expected<Filter*> add_filter(FilterConfig config);
  /// Creates a chain: each stage without an input reads the previous stage's output; intermediate
  /// outputs without a name are called "<name>.<stage index>". All stages or none.
  [[nodiscard]] Expected<std::vector<Filter*>> add_pipeline(std::string_view name, std::vector<FilterConfig> stages);

  Filter* find_filter(std::string_view name) const noexcept;
  const std::vector<std::unique_ptr<Filter>>& filters() const noexcept { return filters_; }

  /// Filters whose state is in a bank (docs/filters.md, "Filter banks").
  std::size_t banked_count() const noexcept;

  /// Runs the ACTIVE filters of `component`, in creation order. Lock-free unless an event fires.
  void run_active(ComponentId component, Time now) noexcept;
  /// Runs every PASSIVE filter once, in creation order (one monitor tick).
  void tick(Time now) noexcept;
  /// The number of PASSIVE filters (a runtime need not start the monitor thread without any).
  std::size_t passive_count() const noexcept;

  /// Starts the monitor thread: tick(clock.now()) every `period` of real time.
  void start(std::chrono::nanoseconds period = kDefaultPeriod);
  void stop() noexcept;
  bool running() const noexcept { return thread_.joinable(); }

  /// Shallow injection into one filter (see Filter::inject); recorded on the observer stream.
  /// Errors: those of check_inject_shallow(); then nothing is queued.
  [[nodiscard]] Expected<void> inject_shallow(std::string_view filter, const std::vector<std::vector<double>>& samples);
  /// Deep injection: `samples` written into the signal's history buffer at time `at`, marked as
  /// injected; every consumer sees them; recorded on the observer stream. Errors: those of
  /// check_inject_deep(); then nothing is written.
  [[nodiscard]] Expected<void> inject_deep(std::string_view signal, const std::vector<std::vector<double>>& samples,
                                           Time at);
  /// Why inject_shallow(filter, samples) would refuse, changing nothing: NotFound (no such filter),
  /// InvalidArgument (no samples, a filter without input, a wrong size, or a NaN or infinite
  /// value: injected values must be finite, docs/filters.md).
  [[nodiscard]] Expected<void> check_inject_shallow(std::string_view filter,
                                                    const std::vector<std::vector<double>>& samples) const;
  /// Why inject_deep(signal, samples, ...) would refuse, changing nothing: NotFound (no such
  /// signal), InvalidArgument (no samples, more than the signal's history holds, a wrong size, a
  /// non-finite value).
  [[nodiscard]] Expected<void> check_inject_deep(std::string_view signal,
                                                 const std::vector<std::vector<double>>& samples) const;

  /// Resolves a signal name as a filter of `component` would: bare names belong to it.
  std::string qualify(std::string_view signal, std::string_view component) const;

private:
  [[nodiscard]] Expected<FilterInit> prepare(FilterConfig config,
                                             std::vector<std::pair<std::string, std::size_t>>& new_outputs);
  void record_injection(MachineId machine, std::string text);
  /// The run group of a filter: its component's ACTIVE filters, or the PASSIVE ones.
  detail::Banks& group(const Filter& filter);
  /// Makes the run groups again from the first `count` filters (a failed pipeline is undone).
  void regroup(std::size_t count);

  Coordinator& coordinator_;
  const FilterRegistry& registry_;
  SignalRegistry signals_;
  std::vector<std::unique_ptr<Filter>> filters_;
  std::unordered_map<std::string_view, Filter*> by_name_;  ///< keys: the filters' own names
  bool banks_;
  std::vector<std::unique_ptr<detail::Banks>> active_;  ///< per component
  std::unique_ptr<detail::Banks> passive_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace safecass
