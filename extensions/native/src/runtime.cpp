#include "safecass/native/runtime.hpp"

#include <time.h>

#include <cerrno>
#include <chrono>
#include <cstdint>

namespace safecass::native {

Runtime::Runtime(Monitor& monitor, Time monitor_period)
    : monitor_(monitor), coordinator_(monitor.coordinator()), monitor_period_(monitor_period) {}

Runtime::~Runtime() { stop(); }

Expected<void> Runtime::add_task(ComponentId component, Time period, Body body, FilterOrder order) {
  if (to_index(component) >= coordinator_.structure().component_count()) {
    return fail(ErrorCode::NotFound, "no component with id " + std::to_string(to_index(component)));
  }
  const std::string name(coordinator_.structure().component_name(component));
  if (period <= Time{0}) return fail(ErrorCode::InvalidArgument, "task of '" + name + "': period must be positive");
  for (const Task& t : tasks_) {
    if (t.component == component)
      return fail(ErrorCode::InvalidArgument, "component '" + name + "' already has a task");
  }
  tasks_.push_back(Task{component, period, std::move(body), order});
  return {};
}

Expected<void> Runtime::set_body(ComponentId component, Body body, FilterOrder order) {
  for (Task& t : tasks_) {
    if (t.component == component) {
      t.body = std::move(body);
      t.order = order;
      return {};
    }
  }
  return fail(ErrorCode::NotFound, "component id " + std::to_string(to_index(component)) + " has no task");
}

void Runtime::cycle(Task& task, Time now) noexcept {
  if (task.order == FilterOrder::AfterBody) {
    run_body(task, now);
    monitor_.run_active(task.component, now);
  } else {
    monitor_.run_active(task.component, now);
    run_body(task, now);
  }
}

void Runtime::run_body(Task& task, Time now) noexcept {
  if (!task.body) return;
  const MachineId framework = coordinator_.structure().framework_machine(task.component);
  try {
    task.body(now);
    if (task.threw) {
      task.threw = false;
      coordinator_.generate(framework_event::completion_of(framework_event::kThreadException), framework);
    }
  } catch (...) {
    // The application's loop failed: that is a framework fault of the component, not a crash.
    if (!task.threw) {
      task.threw = true;
      coordinator_.generate(framework_event::kThreadException, framework);
    }
  }
}

void Runtime::step(Time now) noexcept {
  for (Task& t : tasks_) {
    if (!t.started) {
      t.started = true;
      t.next_due = now;
    }
    if (now < t.next_due) continue;
    cycle(t, now);
    while (t.next_due <= now) t.next_due += t.period;
  }
  if (!monitor_started_) {
    monitor_started_ = true;
    next_monitor_ = now;
  }
  if (now >= next_monitor_) {
    monitor_.tick(now);
    while (next_monitor_ <= now) next_monitor_ += monitor_period_;
  }
}

namespace {

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

/// Sleeps until `deadline` (ns of CLOCK_MONOTONIC, the clock of std::chrono::steady_clock on
/// Linux): an absolute deadline, so a period does not drift by the time spent computing the next
/// wake-up or by a signal that interrupts the sleep.
void sleep_until_ns(std::int64_t deadline) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline % 1'000'000'000);
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

void Runtime::start() {
  if (!threads_.empty()) return;
  stop_.store(false);
  for (Task& task : tasks_) {
    threads_.emplace_back([this, &task] {
      const MachineId framework = coordinator_.structure().framework_machine(task.component);
      const std::int64_t period = task.period.count();
      std::int64_t next = monotonic_ns();
      while (!stop_.load(std::memory_order_acquire)) {
        const std::int64_t begin = monotonic_ns();
        cycle(task, coordinator_.clock().now());
        const std::int64_t end = monotonic_ns();
        const bool overran = end - begin > period;
        if (overran != task.overran) {
          task.overran = overran;
          coordinator_.generate(overran ? framework_event::kPeriodOverrun
                                        : framework_event::completion_of(framework_event::kPeriodOverrun),
                                framework);
        }
        next += period;
        if (next < end) next = end;  // do not try to catch up missed cycles in a burst
        sleep_until_ns(next);
      }
    });
  }
  // The monitor thread runs PASSIVE filters only: without any, it would only wake up for nothing.
  if (monitor_.passive_count() > 0) monitor_.start(monitor_period_);
}

void Runtime::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
  monitor_.stop();
}

}  // namespace safecass::native
