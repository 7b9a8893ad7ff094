// Core hot paths (DESIGN §7): reading a component's extended state (lock-free, ≤ 5 ns), one onset
// and its completion on one machine (each a transition, ≤ 200 ns for the pair), an onset at the
// head of a chain of connected components and its completion (propagate and clear through all of
// them, ≤ 2 µs for 10), and dispatch. The coordinator runs on its default clock (steady_clock),
// as in a deployed system.

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"

namespace safecass {
namespace {

/// "C<i><suffix>", built with append: operator+ on temporaries trips GCC 12's -Wrestrict at -O3.
std::string component_name(int i, const char* suffix = "") {
  std::string name("C");
  name.append(std::to_string(i));
  name.append(suffix);
  return name;
}

struct Chain {
  Coordinator co{"bench"};
  std::vector<ComponentId> components;
  MachineId head = kNoMachine;
  EventId onset = kNoEvent;
  EventId completion = kNoEvent;

  /// C0 ← C1 ← … ← C(n-1): each Ci.in is connected to C(i-1).out, default service dependencies.
  explicit Chain(int n) {
    for (int i = 0; i < n; ++i) {
      const ComponentId c = *co.add_component(component_name(i));
      (void)co.add_provided(c, "out");
      if (i > 0) {
        (void)co.add_required(c, "in");
        (void)co.connect(component_name(i, ".in"), component_name(i - 1, ".out"));
      }
      components.push_back(c);
    }
    head = co.structure().application_machine(components.front());
    onset = *co.add_event(EventDef{"EVT_ERR", 50, {Transition::N2E, Transition::W2E}, "", false, "", ""});
    completion = *co.add_event(EventDef{"/EVT_ERR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""});
  }

  /// One onset and its completion; true when the onset reached the last component.
  bool round() {
    co.generate(onset, head);
    const bool reached = co.extended(components.back()).state == State::Error;
    co.generate(completion, head);
    return reached && co.coordinator_state() == State::Normal;
  }
};

void BM_ReadExtendedState(benchmark::State& state) {
  Chain chain(1);
  const ComponentId c = chain.components.front();
  for (auto _ : state) benchmark::DoNotOptimize(chain.co.extended(c).state);
}
BENCHMARK(BM_ReadExtendedState);

// One onset and its completion on one machine, each causing a transition (N2E, E2N).
void BM_EventTransition(benchmark::State& state) {
  Chain chain(1);
  for (int i = 0; i < 8; ++i) {
    if (!chain.round()) state.SkipWithError("the onset caused no transition");
  }
  for (auto _ : state) {
    chain.co.generate(chain.onset, chain.head);
    chain.co.generate(chain.completion, chain.head);
  }
  benchmark::DoNotOptimize(chain.co.extended(chain.components.front()).state);
}
BENCHMARK(BM_EventTransition);

// The same with one observer that counts the records (a deployed coordinator has one: its node's
// publisher): each write's records are staged, then handed out after the lock.
void BM_EventTransitionObserved(benchmark::State& state) {
  Chain chain(1);
  std::uint64_t records = 0;
  chain.co.subscribe([&records](const Record&) { ++records; });
  for (int i = 0; i < 8; ++i) {
    if (!chain.round()) state.SkipWithError("the onset caused no transition");
  }
  for (auto _ : state) {
    chain.co.generate(chain.onset, chain.head);
    chain.co.generate(chain.completion, chain.head);
  }
  benchmark::DoNotOptimize(records);
  if (records == 0) state.SkipWithError("the observer saw no record");
}
BENCHMARK(BM_EventTransitionObserved);

// An onset at the head of a chain of N connected components and its completion: the Error
// propagates to every component and clears from every one.
void BM_PropagationChain(benchmark::State& state) {
  Chain chain(static_cast<int>(state.range(0)));
  for (int i = 0; i < 8; ++i) {
    if (!chain.round()) state.SkipWithError("the onset did not reach the end of the chain");
  }
  for (auto _ : state) {
    chain.co.generate(chain.onset, chain.head);
    chain.co.generate(chain.completion, chain.head);
  }
  benchmark::DoNotOptimize(chain.co.coordinator_state());
}
BENCHMARK(BM_PropagationChain)->Arg(10);

// The paper's RunNormal / RunWarning / RunError split (§V-B) on a component in Error.
void BM_Dispatch(benchmark::State& state) {
  Chain chain(1);
  chain.co.generate(chain.onset, chain.head);
  const ComponentId c = chain.components.front();
  long normal = 0;
  long warning = 0;
  long error = 0;
  for (auto _ : state) {
    chain.co.dispatch(
        c, [&] { ++normal; }, [&](const Event& e) { warning += e.severity; },
        [&](const Event& e) { error += e.severity; });
    benchmark::DoNotOptimize(error);
  }
  if (error == 0 || normal != 0 || warning != 0) state.SkipWithError("dispatch called the wrong handler");
}
BENCHMARK(BM_Dispatch);

}  // namespace
}  // namespace safecass
