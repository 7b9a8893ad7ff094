// The state-machine core against its peers (`make bench-peers`, docs/benchmarks.md "Peers"):
// one Normal/Warning/Error machine driven by an error onset and its completion, in three
// libraries, in one binary:
//   - SAFECASS: Coordinator::generate() on a component's s_A (what BM_EventTransition measures);
//   - Boost.MSM: the back-end msm::back::state_machine over a functor-row transition table;
//   - Boost.Statechart: sc::state_machine with simple_state and a custom reaction.
// One iteration is one onset and its completion (two events, two transitions); the figure of
// interest is ns per event = time per iteration / 2 (counter "ns_per_event").
//
// The machines are equivalent in what they decide: an error onset leads from Normal or Warning
// to Error; the completion of the error leads back to Warning while a warning is still active,
// else to Normal; a warning onset leads from Normal to Warning and its completion back. What
// SAFECASS does on top, per event, is listed in docs/benchmarks.md.

#include <benchmark/benchmark.h>

#include <boost/mpl/list.hpp>
#include <boost/mpl/vector.hpp>
#include <boost/msm/back/state_machine.hpp>
#include <boost/msm/front/functor_row.hpp>
#include <boost/msm/front/state_machine_def.hpp>
#include <boost/statechart/custom_reaction.hpp>
#include <boost/statechart/event.hpp>
#include <boost/statechart/simple_state.hpp>
#include <boost/statechart/state_machine.hpp>
#include <boost/statechart/transition.hpp>

#include <cstdint>

#include "safecass/core/coordinator.hpp"

namespace {

// ---- Boost.MSM ------------------------------------------------------------------------------
namespace msm = boost::msm;
namespace mpl = boost::mpl;

struct ErrorOnset {};
struct ErrorCompletion {};
struct WarningOnset {};
struct WarningCompletion {};

struct HealthDef : msm::front::state_machine_def<HealthDef> {
  struct Normal : msm::front::state<> {};
  struct Warning : msm::front::state<> {};
  struct Error : msm::front::state<> {};
  using initial_state = Normal;

  int warnings = 0;               ///< active warning conditions (for Error's completion)
  std::uint64_t transitions = 0;  ///< counted by every row, so the work cannot be optimised away

  struct Count {
    template <class E, class Fsm, class S, class T>
    void operator()(const E&, Fsm& fsm, S&, T&) const {
      ++fsm.transitions;
    }
  };
  struct AddWarning {
    template <class E, class Fsm, class S, class T>
    void operator()(const E&, Fsm& fsm, S&, T&) const {
      ++fsm.warnings;
      ++fsm.transitions;
    }
  };
  struct DropWarning {
    template <class E, class Fsm, class S, class T>
    void operator()(const E&, Fsm& fsm, S&, T&) const {
      --fsm.warnings;
      ++fsm.transitions;
    }
  };
  struct NoWarning {
    template <class E, class Fsm, class S, class T>
    bool operator()(const E&, Fsm& fsm, S&, T&) const {
      return fsm.warnings == 0;
    }
  };
  struct SomeWarning {
    template <class E, class Fsm, class S, class T>
    bool operator()(const E&, Fsm& fsm, S&, T&) const {
      return fsm.warnings > 0;
    }
  };

  using none = msm::front::none;
  template <class From, class Event, class To, class Action, class Guard = none>
  using Row = msm::front::Row<From, Event, To, Action, Guard>;
  using transition_table =
      mpl::vector<Row<Normal, ErrorOnset, Error, Count>, Row<Normal, WarningOnset, Warning, AddWarning>,
                  Row<Warning, ErrorOnset, Error, Count>, Row<Warning, WarningCompletion, Normal, DropWarning>,
                  Row<Error, ErrorCompletion, Normal, Count, NoWarning>,
                  Row<Error, ErrorCompletion, Warning, Count, SomeWarning>>;

  template <class Fsm, class Event>
  void no_transition(const Event&, Fsm&, int) {}
};
using Health = msm::back::state_machine<HealthDef>;

// ---- Boost.Statechart -----------------------------------------------------------------------
namespace sc = boost::statechart;

struct EvErrorOnset : sc::event<EvErrorOnset> {};
struct EvErrorCompletion : sc::event<EvErrorCompletion> {};
struct EvWarningOnset : sc::event<EvWarningOnset> {};
struct EvWarningCompletion : sc::event<EvWarningCompletion> {};

struct ScNormal;
struct ScWarning;
struct ScError;
struct HealthChart : sc::state_machine<HealthChart, ScNormal> {
  int warnings = 0;
  std::uint64_t transitions = 0;
};
struct ScNormal : sc::simple_state<ScNormal, HealthChart> {
  using reactions = mpl::list<sc::transition<EvErrorOnset, ScError>, sc::transition<EvWarningOnset, ScWarning>>;
  ScNormal() = default;
};
struct ScWarning : sc::simple_state<ScWarning, HealthChart> {
  using reactions = mpl::list<sc::transition<EvErrorOnset, ScError>, sc::transition<EvWarningCompletion, ScNormal>>;
};
struct ScError : sc::simple_state<ScError, HealthChart> {
  using reactions = sc::custom_reaction<EvErrorCompletion>;
  sc::result react(const EvErrorCompletion&) {
    ++context<HealthChart>().transitions;
    return context<HealthChart>().warnings > 0 ? transit<ScWarning>() : transit<ScNormal>();
  }
};

// ---- the benchmarks -------------------------------------------------------------------------

void set_ns_per_event(benchmark::State& state) {
  // Two events per iteration; kAvgIterationsRate | kInvert gives seconds per iteration.
  state.counters["ns_per_event"] = benchmark::Counter(static_cast<double>(state.iterations()) * 2.0,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// SAFECASS: an error onset and its completion on a component's s_A, each a transition; the
// coordinator on its default clock, with its history ring and its (empty) observer list.
void BM_PeerSafecassEvent(benchmark::State& state) {
  safecass::Coordinator co("bench");
  const safecass::ComponentId c = *co.add_component("C");
  (void)co.add_provided(c, "out");
  const safecass::MachineId target = co.structure().application_machine(c);
  using safecass::Transition;
  const safecass::EventId onset =
      *co.add_event(safecass::EventDef{"EVT_ERR", 50, {Transition::N2E, Transition::W2E}, "", false, "", ""});
  const safecass::EventId completion =
      *co.add_event(safecass::EventDef{"/EVT_ERR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""});
  for (int i = 0; i < 8; ++i) {
    co.generate(onset, target);
    if (co.state(target) != safecass::State::Error) state.SkipWithError("the onset caused no transition");
    co.generate(completion, target);
  }
  for (auto _ : state) {
    co.generate(onset, target);
    co.generate(completion, target);
  }
  if (co.state(target) != safecass::State::Normal) state.SkipWithError("the completion did not return to Normal");
  set_ns_per_event(state);
}
BENCHMARK(BM_PeerSafecassEvent);

void BM_PeerMsmEvent(benchmark::State& state) {
  Health fsm;
  fsm.start();
  for (auto _ : state) {
    fsm.process_event(ErrorOnset{});
    fsm.process_event(ErrorCompletion{});
    benchmark::DoNotOptimize(fsm.transitions);
  }
  if (fsm.transitions != 2 * static_cast<std::uint64_t>(state.iterations()) || fsm.current_state()[0] != 0) {
    state.SkipWithError("Boost.MSM took an unexpected path");
  }
  set_ns_per_event(state);
}
BENCHMARK(BM_PeerMsmEvent);

void BM_PeerStatechartEvent(benchmark::State& state) {
  HealthChart chart;
  chart.initiate();
  const EvErrorOnset onset;
  const EvErrorCompletion completion;
  for (auto _ : state) {
    chart.process_event(onset);
    chart.process_event(completion);
    benchmark::DoNotOptimize(chart.transitions);
  }
  if (chart.state_cast<const ScNormal*>() == nullptr) state.SkipWithError("Boost.Statechart did not return to Normal");
  set_ns_per_event(state);
}
BENCHMARK(BM_PeerStatechartEvent);

}  // namespace
