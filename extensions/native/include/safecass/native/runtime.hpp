#pragma once
/// @file runtime.hpp
/// The native framework extension: plain C++ periodic tasks, the embedded default runtime.
///
/// Each component gets a task with a period. Every cycle the task runs the component's ACTIVE
/// filters and then its body (typically `coordinator.dispatch(component, run_normal, run_warning,
/// run_error)`), or, for a body that reads its sensors and writes their samples, the body first
/// (FilterOrder::AfterBody): then a sample is judged in the cycle that wrote it, not the next one. PASSIVE filters run
/// on the monitor period. A body that throws raises EVT_THREAD_EXCEPTION on the component's s_F (cleared by the next
/// cycle that completes); in real time a cycle longer than its period raises EVT_PERIOD_OVERRUN (cleared by the next
/// cycle on time).
///
/// Two ways to run, never both at once:
/// - simulated time: `step(now)` runs, in order, every task due at `now`, then the monitor tick if
///   due. A driver (the scenario runner) sets the simulated clock and calls step() each tick.
/// - real time: `start()` runs each task on its own thread at its period and the monitor thread;
///   `stop()` joins them.

#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"

namespace safecass::native {

/// When a task runs its component's ACTIVE filters (DESIGN §3: each cycle, or on each push).
enum class FilterOrder : std::uint8_t {
  BeforeBody,  ///< the body acts on the states the filters just set; a sample it writes waits a cycle
  AfterBody,   ///< the body writes the cycle's samples, the filters judge them at once (detection
               ///< within the cycle); the body acts on the states of the previous cycle's samples
};

class Runtime {
public:
  using Body = std::function<void(Time now)>;

  /// `monitor` must outlive the runtime. `monitor_period` is the PASSIVE filters' period.
  explicit Runtime(Monitor& monitor, Time monitor_period = Monitor::kDefaultPeriod);
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  /// Adds the periodic task of `component`, its body and when its ACTIVE filters run. Errors:
  /// InvalidArgument (period ≤ 0, task exists), NotFound (component).
  [[nodiscard]] Expected<void> add_task(ComponentId component, Time period, Body body = {},
                                        FilterOrder order = FilterOrder::BeforeBody);
  /// Sets the body of an existing task (e.g. the application's control loop) and when the
  /// component's ACTIVE filters run relative to it.
  [[nodiscard]] Expected<void> set_body(ComponentId component, Body body, FilterOrder order = FilterOrder::BeforeBody);

  /// Simulated time: runs the tasks due at `now` (in the order they were added), then the monitor
  /// tick if due. Call with non-decreasing times.
  void step(Time now) noexcept;

  /// Real time: one thread per task plus the monitor thread.
  void start();
  void stop() noexcept;

  std::size_t task_count() const noexcept { return tasks_.size(); }

private:
  struct Task {
    ComponentId component;
    Time period;
    Body body;
    FilterOrder order = FilterOrder::BeforeBody;
    Time next_due{};
    bool started = false;
    bool threw = false;
    bool overran = false;
  };
  void cycle(Task& task, Time now) noexcept;
  void run_body(Task& task, Time now) noexcept;

  Monitor& monitor_;
  Coordinator& coordinator_;
  Time monitor_period_;
  Time next_monitor_{};
  bool monitor_started_ = false;
  std::vector<Task> tasks_;
  std::vector<std::thread> threads_;
  std::atomic<bool> stop_{false};
};

}  // namespace safecass::native
