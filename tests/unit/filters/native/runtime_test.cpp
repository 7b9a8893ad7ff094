// The native runtime in real time: a task keeps its period on absolute deadlines, and the monitor
// thread runs only when there are PASSIVE filters to run.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/native/runtime.hpp"

namespace safecass {
namespace {

using namespace std::chrono_literals;

struct System {
  Coordinator co{"native"};
  FilterRegistry registry;
  Monitor monitor{co, registry};
  ComponentId component;
  System() {
    register_builtin_filters(registry);
    component = *co.add_component("LOOP");
    EXPECT_TRUE(monitor.add_signal("LOOP.x"));
  }
  FilterConfig threshold(ExecutionMode mode) {
    FilterConfig f;
    f.name = mode == ExecutionMode::Active ? "active_limit" : "passive_limit";
    f.type = "Threshold";
    f.target.component = "LOOP";
    f.execution = mode;
    f.params["input_signal"] = std::string("x");
    f.params["threshold"] = 10.0;
    f.params["event_onset"] = std::string("EVT_LIMIT");
    return f;
  }
};

TEST(NativeRuntime, ARealTimeTaskRunsOncePerPeriodWithoutDrift) {
  System s;
  native::Runtime runtime(s.monitor);
  std::atomic<int> cycles{0};
  ASSERT_TRUE(runtime.add_task(s.component, 10ms, [&cycles](Time) { cycles.fetch_add(1); }));
  const auto start = std::chrono::steady_clock::now();
  runtime.start();
  std::this_thread::sleep_for(500ms);
  runtime.stop();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // One cycle at the start, then one per 10 ms deadline: a period that drifted (a relative sleep
  // after each cycle) would give fewer. A loaded machine may run late, never more often.
  EXPECT_LE(cycles.load(), static_cast<int>(elapsed / 0.010) + 2);
  EXPECT_GE(cycles.load(), 35) << "in " << elapsed << " s";
}

TEST(NativeRuntime, FiltersAfterTheBodyJudgeTheSampleItWroteInTheSameCycleAndBeforeItTheNextOne) {
  for (const native::FilterOrder order : {native::FilterOrder::AfterBody, native::FilterOrder::BeforeBody}) {
    System s;
    ASSERT_TRUE(s.co.add_event(EventDef{"EVT_LIMIT", 50, {Transition::N2E}, "", false, "", ""}));
    ASSERT_TRUE(s.monitor.add_filter(s.threshold(ExecutionMode::Active)));
    native::Runtime runtime(s.monitor);
    Signal* x = s.monitor.signals().find("LOOP.x");
    ASSERT_TRUE(runtime.add_task(
        s.component, 1ms, [x](Time now) { x->push(now, 20.0); }, order));
    const MachineId app = s.co.structure().application_machine(s.component);
    runtime.step(Time{0});
    EXPECT_EQ(s.co.state(app), order == native::FilterOrder::AfterBody ? State::Error : State::Normal)
        << "after the cycle that wrote the sample";
    runtime.step(Time{1ms});
    EXPECT_EQ(s.co.state(app), State::Error) << "one cycle later, in either order";
  }
}

TEST(NativeRuntime, TheMonitorThreadRunsOnlyWhenThereArePassiveFilters) {
  {
    System s;
    ASSERT_TRUE(s.co.add_event(EventDef{"EVT_LIMIT", 50, {Transition::N2E}, "", false, "", ""}));
    ASSERT_TRUE(s.co.add_event(EventDef{"/EVT_LIMIT", 50, {Transition::E2N}, "", false, "", ""}));
    ASSERT_TRUE(s.monitor.add_filter(s.threshold(ExecutionMode::Active)));
    native::Runtime runtime(s.monitor);
    ASSERT_TRUE(runtime.add_task(s.component, 1ms));
    runtime.start();
    EXPECT_FALSE(s.monitor.running()) << "no PASSIVE filter: nothing for the monitor thread to run";
    runtime.stop();
  }
  {
    System s;
    ASSERT_TRUE(s.co.add_event(EventDef{"EVT_LIMIT", 50, {Transition::N2E}, "", false, "", ""}));
    ASSERT_TRUE(s.co.add_event(EventDef{"/EVT_LIMIT", 50, {Transition::E2N}, "", false, "", ""}));
    ASSERT_TRUE(s.monitor.add_filter(s.threshold(ExecutionMode::Passive)));
    native::Runtime runtime(s.monitor);
    ASSERT_TRUE(runtime.add_task(s.component, 1ms));
    runtime.start();
    EXPECT_TRUE(s.monitor.running());
    s.monitor.signals().find("LOOP.x")->push(s.co.clock().now(), 20.0);
    const auto until = std::chrono::steady_clock::now() + 2s;
    while (s.co.state(s.co.structure().application_machine(s.component)) != State::Error &&
           std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(5ms);
    EXPECT_EQ(s.co.state(s.co.structure().application_machine(s.component)), State::Error) << "the PASSIVE filter ran";
    runtime.stop();
    EXPECT_FALSE(s.monitor.running());
  }
}

}  // namespace
}  // namespace safecass
