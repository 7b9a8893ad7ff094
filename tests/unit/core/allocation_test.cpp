// Proves that the core hot paths allocate nothing once set up (DESIGN §7): lock-free reads and
// dispatch, an onset and its completion on one machine, an onset and its completion propagating
// along a chain of ten components, with and without an observer and callbacks.
//
// Every global operator new and delete is replaced (plain, array, aligned, nothrow, sized) by a
// version that counts while a scope on the current thread is open, so nothing gtest or another
// thread does is counted. The first test shows the counter really counts.

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"

namespace {

std::atomic<long> g_allocations{0};
std::atomic<long> g_deallocations{0};
thread_local bool t_counting = false;

void* allocate(std::size_t n) noexcept {
  if (t_counting) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}

void* allocate_aligned(std::size_t n, std::align_val_t al) noexcept {
  if (t_counting) g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto alignment = std::max(static_cast<std::size_t>(al), sizeof(void*));
  void* p = nullptr;
  return posix_memalign(&p, alignment, n == 0 ? 1 : n) == 0 ? p : nullptr;
}

void deallocate(void* p) noexcept {
  if (p == nullptr) return;
  if (t_counting) g_deallocations.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}

void* allocate_or_throw(std::size_t n) {
  if (void* p = allocate(n)) return p;
  throw std::bad_alloc();
}

void* allocate_aligned_or_throw(std::size_t n, std::align_val_t al) {
  if (void* p = allocate_aligned(n, al)) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t n) { return allocate_or_throw(n); }
void* operator new[](std::size_t n) { return allocate_or_throw(n); }
void* operator new(std::size_t n, std::align_val_t al) { return allocate_aligned_or_throw(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return allocate_aligned_or_throw(n, al); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate(n); }
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return allocate_aligned(n, al);
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return allocate_aligned(n, al);
}

void operator delete(void* p) noexcept { deallocate(p); }
void operator delete[](void* p) noexcept { deallocate(p); }
void operator delete(void* p, std::size_t) noexcept { deallocate(p); }
void operator delete[](void* p, std::size_t) noexcept { deallocate(p); }
void operator delete(void* p, std::align_val_t) noexcept { deallocate(p); }
void operator delete[](void* p, std::align_val_t) noexcept { deallocate(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { deallocate(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { deallocate(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { deallocate(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { deallocate(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { deallocate(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { deallocate(p); }

namespace safecass {
namespace {

struct HeapUse {
  long allocations = 0;
  long deallocations = 0;
};

/// Runs `body` with counting on for this thread and returns the heap operations it made.
template <class F>
HeapUse heap_use_of(F&& body) {
  g_allocations = 0;
  g_deallocations = 0;
  t_counting = true;
  body();
  t_counting = false;
  return HeapUse{g_allocations.load(), g_deallocations.load()};
}

constexpr int kWarmUp = 4;
constexpr int kRounds = 100;

/// A coordinator with a single component and an Error onset/completion pair on its s_A, and a
/// chain of ten components C0 ← C1 ← … ← C9 (each Ci.in connected to C(i-1).out).
struct Rig {
  SimulatedClock clock;
  Coordinator co{"alloc", &clock};
  ComponentId single{0};
  MachineId single_app{0};
  std::vector<ComponentId> chain;
  MachineId head_app{0};
  EventId onset{0};
  EventId completion{0};
  EventId warning{0};
  EventId warning_completion{0};

  Rig() {
    single = *co.add_component("SINGLE");
    single_app = co.structure().application_machine(single);
    (void)co.add_provided(single, "out");
    for (int i = 0; i < 10; ++i) {
      const ComponentId c = *co.add_component("C" + std::to_string(i));
      (void)co.add_provided(c, "out");
      if (i > 0) {
        (void)co.add_required(c, "in");
        (void)co.connect("C" + std::to_string(i) + ".in", "C" + std::to_string(i - 1) + ".out");
      }
      chain.push_back(c);
    }
    head_app = co.structure().application_machine(chain.front());
    onset = *co.add_event(EventDef{"EVT_ERR", 50, {Transition::N2E, Transition::W2E}, "", false, "", ""});
    completion = *co.add_event(EventDef{"/EVT_ERR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""});
    warning = *co.add_event(EventDef{"EVT_WARN", 40, {Transition::N2W}, "", false, "", ""});
    warning_completion = *co.add_event(EventDef{"/EVT_WARN", 40, {Transition::W2N}, "", false, "", ""});
  }

  /// Onset then completion on one machine; true when both caused the expected transitions.
  bool single_round() {
    co.generate(onset, single_app);
    const bool raised = co.state(single_app) == State::Error && co.extended(single).state == State::Error;
    co.generate(completion, single_app);
    return raised && co.state(single_app) == State::Normal && co.extended(single).state == State::Normal;
  }

  /// Onset at the head of the chain then its completion; true when it reached and left the tail.
  bool chain_round() {
    co.generate(onset, head_app);
    const bool reached = co.extended(chain.back()).state == State::Error;
    co.generate(completion, head_app);
    return reached && co.coordinator_state() == State::Normal;
  }
};

TEST(CoreAllocation, TheCounterSeesAVectorPushBackSoTheseTestsCannotPassVacuously) {
  std::vector<int> v;
  const HeapUse push = heap_use_of([&] { v.push_back(1); });
  EXPECT_EQ(push.allocations, 1);
  const HeapUse release = heap_use_of([&] { std::vector<int>().swap(v); });
  EXPECT_EQ(release.deallocations, 1);

  struct alignas(64) Wide {
    char bytes[64];
  };
  const HeapUse aligned = heap_use_of([] { delete new Wide; });
  EXPECT_EQ(aligned.allocations, 1);
  EXPECT_EQ(aligned.deallocations, 1);
  const HeapUse nothrow = heap_use_of([] { delete[] new (std::nothrow) char[16]; });
  EXPECT_EQ(nothrow.allocations, 1);
  EXPECT_EQ(nothrow.deallocations, 1);
}

TEST(CoreAllocation, LockFreeReadsAndDispatchAllocateNothing) {
  Rig rig;
  rig.co.generate(rig.onset, rig.single_app);  // a non-Normal state, so dispatch passes an event
  long sink = 0;
  auto read_everything = [&] {
    for (int i = 0; i < kRounds; ++i) {
      sink += static_cast<long>(rig.co.extended(rig.single).state);
      sink += static_cast<long>(rig.co.extended(rig.single).outstanding);
      sink += static_cast<long>(rig.co.snapshot(rig.single_app).outstanding);
      sink += static_cast<long>(rig.co.state(rig.single_app));
      sink += static_cast<long>(rig.co.service_state(rig.single, 0));
      sink += static_cast<long>(rig.co.service_state(rig.chain.back(), 0));
      sink += static_cast<long>(rig.co.coordinator_state());
      rig.co.dispatch(
          rig.single, [&] { sink += 1; }, [&](const Event& e) { sink += e.severity; },
          [&](const Event& e) { sink += to_index(e.id); });
    }
  };
  read_everything();
  const HeapUse use = heap_use_of(read_everything);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
  EXPECT_NE(sink, 0);
}

TEST(CoreAllocation, AnOnsetAndItsCompletionCausingTransitionsOnOneMachineAllocateNothing) {
  Rig rig;
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(rig.single_round());
  bool transitions = true;
  const HeapUse use = heap_use_of([&] {
    for (int i = 0; i < kRounds; ++i) transitions = rig.single_round() && transitions;
  });
  EXPECT_TRUE(transitions);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
}

TEST(CoreAllocation, AnOnsetAndItsCompletionPropagatingThroughAChainOfTenComponentsAllocateNothing) {
  Rig rig;
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(rig.chain_round());
  bool propagated = true;
  const HeapUse use = heap_use_of([&] {
    for (int i = 0; i < kRounds; ++i) propagated = rig.chain_round() && propagated;
  });
  EXPECT_TRUE(propagated);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
}

TEST(CoreAllocation, WithAnObserverAndCallbacksOnEveryMachineTheHotPathsStillAllocateNothing) {
  Rig rig;
  long records = 0;
  long callbacks = 0;
  rig.co.subscribe([&records](const Record&) { ++records; });
  for (MachineId m : id_range<MachineId>(rig.co.structure().machine_count())) {
    rig.co.on_machine(
        m, StateCallbacks{[&callbacks](State) { ++callbacks; }, [&callbacks](const TransitionInfo&) { ++callbacks; },
                          [&callbacks](State) { ++callbacks; }});
  }
  for (ComponentId c : id_range<ComponentId>(rig.co.structure().component_count())) {
    rig.co.on_component(
        c, StateCallbacks{[&callbacks](State) { ++callbacks; }, [&callbacks](const TransitionInfo&) { ++callbacks; },
                          [&callbacks](State) { ++callbacks; }});
  }
  auto rounds = [&] {
    bool ok = true;
    for (int i = 0; i < kRounds; ++i) {
      ok = rig.single_round() && ok;
      ok = rig.chain_round() && ok;
    }
    return ok;
  };
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(rig.single_round() && rig.chain_round());
  records = callbacks = 0;
  bool ok = false;
  const HeapUse use = heap_use_of([&] { ok = rounds(); });
  EXPECT_TRUE(ok);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
  // Per round: 2 machine + 2 component transitions on SINGLE; 10 × 2 machine (s_A of C0, s_R.in
  // of the others) + 10 × 2 component transitions along the chain; 3 calls each.
  EXPECT_EQ(callbacks, kRounds * 3L * (4 + 40));
  EXPECT_GT(records, kRounds * 44L);
}

TEST(CoreAllocation, RefreshesIgnoredCompletionsMaskedOnsetsAndWarningPropagationAllocateNothing) {
  Rig rig;
  // Make propagation of warnings possible along the chain.
  for (int i = 0; i < 10; ++i) {
    ServiceDependency d;
    d.propagate = State::Warning;
    ASSERT_TRUE(rig.co.set_service(rig.chain[static_cast<std::size_t>(i)], "out", d));
  }
  auto mixed = [&] {
    bool ok = true;
    rig.co.generate(rig.onset, rig.head_app);         // N2E, propagates to the tail
    rig.co.generate(rig.warning, rig.head_app);       // masked below Error; its mirrors too
    rig.co.generate(rig.warning, rig.head_app);       // refresh
    rig.co.generate(rig.completion, rig.single_app);  // ignored: not active
    rig.co.generate(rig.completion, rig.head_app);    // E2W everywhere: the warning is still present
    ok = ok && rig.co.extended(rig.chain.back()).state == State::Warning;
    rig.co.generate(rig.warning_completion, rig.head_app);
    ok = ok && rig.co.coordinator_state() == State::Normal;
    return ok;
  };
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(mixed());
  bool ok = true;
  const HeapUse use = heap_use_of([&] {
    for (int i = 0; i < kRounds; ++i) ok = mixed() && ok;
  });
  EXPECT_TRUE(ok);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
}

}  // namespace
}  // namespace safecass

namespace safecass {
namespace {

TEST(CoreAllocation, InterningAKnownNameAndAnEventWithFilterDataAllocateNothing) {
  // A filter interns its names once, at configuration; looking a known name up again (the hash
  // index of intern()) and generating events that carry filter data then allocate nothing.
  Rig rig;
  const NameId filter = rig.co.intern("force_limit");
  const NameId signal = rig.co.intern("SINGLE.force");
  for (int i = 0; i < kWarmUp; ++i) (void)rig.single_round();
  bool ok = true;
  const HeapUse use = heap_use_of([&] {
    for (int i = 0; i < kRounds; ++i) {
      ok = ok && rig.co.intern("force_limit") == filter && rig.co.intern("SINGLE.force") == signal;
      SampleCause cause;
      cause.filter = filter;
      cause.signal = signal;
      cause.value = 31.0 + i;
      rig.co.generate(rig.onset, rig.single_app, cause);
      ok = ok && rig.co.state(rig.single_app) == State::Error;
      rig.co.generate(rig.completion, rig.single_app);
      ok = ok && rig.co.state(rig.single_app) == State::Normal;
    }
  });
  EXPECT_TRUE(ok);
  EXPECT_EQ(use.allocations, 0);
  EXPECT_EQ(use.deallocations, 0);
  EXPECT_EQ(rig.co.structure().name_of(filter), "force_limit");
}

}  // namespace
}  // namespace safecass
