#pragma once
/// @file scenario_runner.hpp
/// Runs a system in-process in simulated time, driven by a scenario (DESIGN §6): at each tick t,
/// in order, (1) apply the steps due at t in file order (samples, ramps, generate, inject, reset),
/// (2) run the filters due at t (each component's ACTIVE filters at its own period, PASSIVE
/// filters at the monitor period) and the components' bodies, (3) check the expectations due at t.
/// Same inputs → same output, byte for byte.
///
/// It is opened in one step (ScenarioRunner::open): the system is built by the one factory of
/// system.hpp and every name the scenario uses is checked, or every problem is returned and
/// nothing runs. Example programs then set task bodies on runtime() and call run().

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/native/runtime.hpp"
#include "safecass/native/system.hpp"
#include "safecass/record/input_recorder.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/scenario.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::runner {

struct RunOptions {
  bool json = false;        ///< one JSON object per line instead of text
  bool quiet = false;       ///< print nothing but failures
  std::string record_path;  ///< write the whole history as JSON lines
  /// Record the inputs (samples and actions, record/input_log.hpp) to this file; with record_path
  /// and no inputs_path, next to the history (InputRecorder::path_for_history). "-": none.
  std::string inputs_path;
  FileLimits limits;            ///< rotation of both files (--max-bytes)
  std::string system_override;  ///< run this system file instead of the scenario's "system"
  std::FILE* out = stdout;
};

/// One `expect` of a state, as checked: which address, at what level, when, and whether it held.
struct StateCheck {
  std::string address;
  State expected = State::Normal;
  Time at{};
  bool held = false;
};

/// One expectation that did not hold, when the runner checked it.
struct ExpectationFailure {
  spec::Position where;  ///< the step's action value in the scenario file
  std::string pointer;   ///< its JSON pointer, "/steps/4/expect"
  Time at{};             ///< the tick at which it was checked
  std::string address;   ///< the address checked
  std::string problem;   ///< what was found against what was expected, "JR3 is Normal, expected Error"
  /// The line RunResult::failures holds: "file:line:col: expectation failed at t=...: problem [pointer]".
  std::string text() const;
};

/// What a run did, for `safecass test`'s coverage summary and `safecass trace`'s matrix.
struct Coverage {
  std::set<std::string> events_fired;                     ///< events processed (not ignored)
  std::set<std::pair<std::string, std::string>> taken;    ///< (event, transition) that caused a transition
  std::set<std::pair<std::string, std::string>> defined;  ///< (event, transition) listed by the system's events
  std::vector<StateCheck> states_checked;                 ///< every `expect` step's checks, in run order
};

struct RunResult {
  int checks = 0;                     ///< expectations checked
  std::vector<std::string> failures;  ///< "file:line:col: expectation failed at t=...: ..."
  Coverage coverage;
  /// With RunOptions::record_path: what the recorder wrote and lost (after the run).
  std::optional<RecordStatus> record;
  /// With an inputs recording: what the input recorder wrote and lost (after the run).
  std::optional<InputRecordStatus> inputs;
  bool passed() const noexcept { return failures.empty(); }
  /// No history or inputs were asked for, or every record is in them (no write error, nothing
  /// dropped or lost).
  bool history_complete() const noexcept { return (!record || record->complete()) && (!inputs || inputs->complete()); }
};

/// Where a scenario run comes from.
struct ScenarioSource {
  /// A scenario file. Empty: the system runs with no steps, ticking at native::kDefaultTick.
  std::string scenario;
  /// The system file. Empty: the scenario's "system"; otherwise it replaces it.
  std::string system;
};

class ScenarioRunner {
public:
  /// Loads the scenario and its system, builds the system (native::build_system(), components that name
  /// no period run at the scenario's period) and checks every name the scenario uses (signals,
  /// sizes, events, filters, addresses). Every problem is returned with its position, and then
  /// nothing was built. Warnings of the system file are appended to `notes` when given.
  [[nodiscard]] static spec::Opened<std::unique_ptr<ScenarioRunner>> open(const ScenarioSource& source,
                                                                          const FilterRegistry& registry,
                                                                          spec::Diagnostics* notes = nullptr);
  /// The same from parts already loaded. `registry` must outlive the runner.
  [[nodiscard]] static spec::Opened<std::unique_ptr<ScenarioRunner>> open(spec::Scenario scenario,
                                                                          spec::SystemSpec system,
                                                                          const FilterRegistry& registry);
  ~ScenarioRunner();
  ScenarioRunner(const ScenarioRunner&) = delete;
  ScenarioRunner& operator=(const ScenarioRunner&) = delete;

  native::System& system() noexcept { return *system_; }
  Coordinator& coordinator() noexcept { return coordinator_; }
  Monitor& monitor() noexcept { return *monitor_; }
  native::Runtime& runtime() noexcept { return *runtime_; }
  SimulatedClock& clock() noexcept { return clock_; }
  const spec::Scenario& scenario() const noexcept { return scenario_; }

  /// Runs the whole scenario.
  /// Equivalent to begin(options, result); advance_to(duration); finish(result).
  RunResult run(const RunOptions& options);

  /// Opens the history and inputs recorders of `options` and starts printing records as run()
  /// does (transitions with their causes, resets, injections, masked and ignored events). A
  /// recorder that cannot be opened is a failure in `result`; false then.
  bool begin(const RunOptions& options, RunResult& result);
  /// Stops printing, reports expectations after the last tick, closes the recorders (their status
  /// in `result`) and fills the coverage.
  void finish(RunResult& result);

  /// A feed: called at every tick, after the clock is set and before the scenario's steps, to push
  /// samples and apply actions (a replay). Set before the first tick.
  void set_feed(std::function<void(Time now)> feed) { feed_ = std::move(feed); }
  /// Told of each expectation that fails, at the tick it is checked (the system is then exactly as
  /// the check found it, so a tool can explain the address), before its line joins
  /// RunResult::failures. Must not drive the runner.
  void set_on_failure(std::function<void(const ExpectationFailure&)> told) { on_failure_ = std::move(told); }
  /// The first tick is the first multiple of the period at or after `t` (default 0). Before the
  /// first tick.
  void start_at(Time t);
  /// The input recorder opened by begin(), or null: a feed records the actions it applies here.
  InputRecorder* input_recorder() noexcept { return inputs_.get(); }

  /// Incremental driving, for interactive tools (the console's `watch`): processes every tick up
  /// to and including `until` not processed yet, exactly as run() does (steps, ramps, filters,
  /// expectations; failed expectations are appended to `result`). Ticks past the scenario's
  /// duration keep running the system with no more steps. Do not combine with run().
  void advance_to(Time until, RunResult& result);
  /// The time of the last tick processed; negative before the first.
  Time now() const noexcept;

private:
  struct Ramp {
    Signal* signal;
    Time from_time;
    Time until;
    double from;
    double to;
  };
  ScenarioRunner(spec::Scenario scenario, std::unique_ptr<native::System> system);
  /// Every name the scenario uses, checked against the built system.
  spec::Diagnostics check_names();
  void apply(const spec::ScenarioStep& step, Time now);
  /// The components a coordinator of the system file runs, or nullptr when `name` is none.
  const std::vector<std::string>* coordinator_components(const std::string& name) const;
  /// Every address of the system, for suggestions: SYSTEM, coordinators, components, machines, services.
  std::vector<std::string> addresses() const;
  void split_steps();
  void check(const spec::ScenarioStep& step, Time now, RunResult& result);
  std::string check_one(const spec::ScenarioStep& step, const std::string& address, const std::string& expected);

  spec::Scenario scenario_;
  std::unique_ptr<native::System> system_;
  SimulatedClock& clock_;
  Coordinator& coordinator_;
  Monitor* monitor_;
  native::Runtime* runtime_;
  std::vector<Ramp> ramps_;
  // Progress of the tick loop (run() and advance_to()).
  bool split_ = false;
  std::vector<const spec::ScenarioStep*> actions_;
  std::vector<const spec::ScenarioStep*> checks_;
  std::size_t next_step_ = 0;
  std::size_t next_check_ = 0;
  std::int64_t next_tick_ = 0;
  std::function<void(Time)> feed_;
  std::function<void(const ExpectationFailure&)> on_failure_;
  std::unique_ptr<Recorder> recorder_;
  std::unique_ptr<InputRecorder> inputs_;
  Coordinator::SubscriptionId printer_ = 0;
};

/// The actions of one scenario step, as every driver of a scenario applies them through
/// introspect::apply(): one PushSample per sample of a `sample` step, the `generate`, the `inject`
/// (deep into a filter: into that filter's first input) and the `reset` (of a coordinator of the
/// system file: of each of its components, docs/semantics.md §4.5), with who = "scenario". Empty
/// for a ramp (its samples are pushed tick by tick) and for expectations.
std::vector<introspect::Action> step_actions(const spec::ScenarioStep& step, const Monitor& monitor,
                                             const spec::SystemSpec& system);

/// Checks one expectation of an `expect`, `expect_outstanding` or `expect_cause` step against the
/// coordinator that holds `address` (a component, machine, service or SYSTEM of it): empty when it
/// is met, else what was found against what was expected ("JR3 is Normal, expected Error"). The
/// scenario runner and a live coordinator's scenario (`safecass run --scenario`) both check with it.
std::string expectation_problem(const Coordinator& co, const spec::ScenarioStep& step, const std::string& address,
                                const std::string& expected);

/// Loads a scenario and its system and runs it; prints diagnostics to `err`. Returns 0 passed,
/// 1 an expectation failed, 2 invalid input, or a history file (RunOptions::record_path) that is
/// incomplete: a write error or dropped records, each said on `err` with the file, the count and
/// the system's reason (and, with RunOptions::json, as a last {"kind":"recorder",...} line on
/// `out`). The run itself is never cut short by the recorder. `result` (optional) receives the
/// run's details.
int run_scenario_file(const std::string& path, const FilterRegistry& registry, const RunOptions& options,
                      RunResult* result = nullptr, std::FILE* err = stderr);

/// Every problem of a scenario at once, as `safecass run` reports them: the format problems of
/// the file (spec::load_scenario) and the names its readable steps use that the system does not
/// have (with "did you mean" suggestions), in file order (line, column),
/// then the errors of the system file if it does not load. Empty = the scenario can run.
/// `system_override` replaces the scenario's "system", as RunOptions::system_override does.
std::vector<spec::Diagnostic> check_scenario(const std::string& path, const FilterRegistry& registry,
                                             const std::string& system_override = {});

}  // namespace safecass::runner
