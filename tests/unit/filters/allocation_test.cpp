// Proves that the filter hot paths allocate nothing in steady state: a Threshold sample without
// an event, the three-stage pipeline, and a monitor tick over passive filters.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "safecass/filters/monitor.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};

void* counted(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return counted(n); }
void* operator new[](std::size_t n) { return counted(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace safecass {
namespace {

/// Counts the allocations made by `body`.
template <class F>
long allocations_in(F&& body) {
  g_allocations = 0;
  g_counting = true;
  body();
  g_counting = false;
  return g_allocations.load();
}

struct Rig {
  SimulatedClock clock;
  Coordinator co{"alloc", &clock};
  FilterRegistry registry;
  Monitor monitor{co, registry};
  ComponentId component{0};
  Rig() {
    register_builtin_filters(registry);
    component = *co.add_component("C");
    (void)co.add_event(EventDef{"EVT_X", 50, {Transition::N2E}, "", false, "", ""});
    (void)co.add_event(EventDef{"/EVT_X", 50, {Transition::E2N}, "", false, "", ""});
  }
  Filter* add(std::string type, Params p, ExecutionMode mode = ExecutionMode::Active) {
    FilterConfig c;
    c.type = std::move(type);
    c.target.component = "C";
    c.execution = mode;
    c.params = std::move(p);
    auto f = monitor.add_filter(std::move(c));
    EXPECT_TRUE(f);
    return f ? *f : nullptr;
  }
};

TEST(FilterAllocation, CounterDetectsAnAllocationSoTheseTestsCannotPassVacuously) {
  std::string* s = nullptr;
  const long n = allocations_in([&] { s = new std::string(100, 'x'); });
  delete s;
  EXPECT_GE(n, 1);
}

TEST(FilterAllocation, ThresholdSampleWithoutEventAllocatesNothing) {
  Rig s;
  Signal* x = *s.monitor.add_signal("C.x");
  Filter* f = s.add("Threshold",
                    {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  for (int i = 0; i < 10; ++i) {
    x->push(Time{i}, 1.0);
    f->run(Time{i});
  }
  EXPECT_EQ(allocations_in([&] {
              for (int i = 10; i < 1000; ++i) {
                x->push(Time{i}, 1.0);
                f->run(Time{i});
              }
            }),
            0);
}

TEST(FilterAllocation, ThreeStagePipelineAllocatesNothingInSteadyState) {
  Rig s;
  Signal* force = *s.monitor.add_signal("C.force", 3);
  s.add("Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}});
  s.add("MovingAverage",
        {{"input_signal", std::string("norm")}, {"output_signal", std::string("avg")}, {"window", 10.0}});
  s.add("Threshold",
        {{"input_signal", std::string("avg")}, {"threshold", 30.0}, {"event_onset", std::string("EVT_X")}});
  const double sample[] = {1, 2, 3};
  for (int i = 0; i < 20; ++i) {
    force->push(Time{i}, sample);
    s.monitor.run_active(s.component, Time{i});
  }
  EXPECT_EQ(allocations_in([&] {
              for (int i = 20; i < 1000; ++i) {
                force->push(Time{i}, sample);
                s.monitor.run_active(s.component, Time{i});
              }
            }),
            0);
}

TEST(FilterAllocation, MonitorTickOverPassiveFiltersAllocatesNothing) {
  Rig s;
  Signal* x = *s.monitor.add_signal("C.x");
  for (int i = 0; i < 100; ++i) {
    s.add("Threshold", {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}},
          ExecutionMode::Passive);
  }
  s.add("Watchdog", {{"input_signal", std::string("x")}, {"timeout", 1.0}}, ExecutionMode::Passive);
  for (int i = 0; i < 10; ++i) {
    x->push(Time{i}, 1.0);
    s.monitor.tick(Time{i});
  }
  EXPECT_EQ(allocations_in([&] {
              for (int i = 10; i < 500; ++i) {
                x->push(Time{i}, 1.0);
                s.monitor.tick(Time{i});
              }
            }),
            0);
}

TEST(FilterAllocation, EdgeEventsAfterWarmUpAllocateNothing) {
  Rig s;
  Signal* x = *s.monitor.add_signal("C.x");
  Filter* f = s.add("Threshold",
                    {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  for (int i = 0; i < 10; ++i) {
    x->push(Time{i}, i % 2 ? 20.0 : 1.0);
    f->run(Time{i});
  }
  EXPECT_EQ(allocations_in([&] {
              for (int i = 10; i < 1000; ++i) {
                x->push(Time{i}, i % 2 ? 20.0 : 1.0);
                f->run(Time{i});
              }
            }),
            0);
  EXPECT_EQ(s.co.coordinator_state(), State::Error);
}

TEST(FilterAllocation, BankedFiltersAllocateNothingWithSeveralSamplesInjectionsAndDetours) {
  // Banks (docs/filters.md): a Threshold, a Watchdog and a MovingAverage per signal, a vector's
  // Norm → MovingAverage → Threshold and its own MovingAverage, a Debounce, a Frequency, two
  // Deadlines of one pair of signals and one of a signal with itself, in banks;
  // several samples per run, a NaN now and then, a deep injection, a filter disabled and enabled
  // again: none of it allocates after the warm-up (the deep injection's ring is made by the
  // first injection, in the warm-up).
  Rig s;
  std::vector<Signal*> signals;
  for (int k = 0; k < 50; ++k) {
    const std::string x = "x" + std::to_string(k);
    signals.push_back(*s.monitor.add_signal("C." + x));
    s.add("Threshold", {{"input_signal", x}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
    s.add("Watchdog", {{"input_signal", x}, {"timeout", 1.0}});
    s.add("MovingAverage", {{"input_signal", x}, {"window", 10.0}});
  }
  // A vector through a banked pipeline, and the other banked types.
  Signal* force = *s.monitor.add_signal("C.force", 3);
  s.add("Norm", {{"input_signal", std::string("force")}, {"output_signal", std::string("norm")}});
  s.add("MovingAverage", {{"input_signal", std::string("norm")}, {"output_signal", std::string("avg")}});
  s.add("Threshold",
        {{"input_signal", std::string("avg")}, {"threshold", 30.0}, {"event_onset", std::string("EVT_X")}});
  s.add("MovingAverage", {{"input_signal", std::string("force")}, {"output_signal", std::string("mean_force")}});
  s.add("Debounce", {{"input_signal", std::string("x0")}, {"event_onset", std::string("EVT_X")}});
  s.add("Frequency", {{"input_signal", std::string("x1")}, {"min_rate", 1.0}, {"event_onset", std::string("EVT_X")}});
  for (const char* pair : {"x0 force", "x0 force", "x1 x1"}) {  // overdue at every run, late at every end
    const std::string p(pair);
    s.add("Deadline", {{"input_signals", std::vector<std::string>{p.substr(0, 2), p.substr(3)}},
                       {"deadline", 1e-9},
                       {"event_onset", std::string("EVT_X")}});
  }
  ASSERT_EQ(s.monitor.banked_count(), 159U);
  Filter* toggled = s.monitor.filters()[1].get();
  const double f[] = {1, 2, 3};
  auto cycle = [&](int i) {
    for (Signal* x : signals) {
      x->push(Time{10 * i}, i % 97 == 0 ? std::nan("") : 1.0);
      x->push(Time{10 * i + 5}, 2.0);
    }
    force->push(Time{10 * i}, f);
    if (i % 50 == 0) (void)s.monitor.inject_deep("C.x3", {{3.0}}, Time{10 * i + 6});
    if (i % 30 == 0) toggled->set_enabled(i % 60 != 0);
    s.monitor.run_active(s.component, Time{10 * i + 9});
  };
  for (int i = 0; i < 200; ++i) cycle(i);
  // Without the deep injection, whose argument is a vector made by the caller.
  EXPECT_EQ(allocations_in([&] {
              for (int i = 201; i < 1000; ++i) {
                for (Signal* x : signals) {
                  x->push(Time{10 * i}, i % 97 == 0 ? std::nan("") : 1.0);
                  x->push(Time{10 * i + 5}, 2.0);
                }
                force->push(Time{10 * i}, f);
                if (i % 30 == 0) toggled->set_enabled(i % 60 != 0);
                s.monitor.run_active(s.component, Time{10 * i + 9});
              }
            }),
            0);
}

}  // namespace
}  // namespace safecass
