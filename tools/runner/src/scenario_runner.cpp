#include "safecass/runner/scenario_runner.hpp"
#include "safecass/core/address.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "safecass/introspect/format.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::runner {

using native::build_system;
using native::kDefaultTick;
using native::System;
using native::SystemOptions;
using spec::Diagnostics;
using spec::keep_errors;
using spec::Opened;

namespace {
std::string secs(Time t) { return seconds_text(t); }

/// "no X 'name'" with the nearest known name, if one is near.
std::string unknown(const std::string& what, const std::string& name, const std::vector<std::string>& known) {
  return "no " + what + " '" + name + "'" + spec::did_you_mean(name, known);
}
}  // namespace

const std::vector<std::string>* ScenarioRunner::coordinator_components(const std::string& name) const {
  for (const auto& [coordinator, components] : system_->spec().coordinators) {
    if (coordinator == name) return &components;
  }
  return nullptr;
}

std::vector<std::string> ScenarioRunner::addresses() const {
  const spec::SystemSpec& system = system_->spec();
  std::vector<std::string> out{"SYSTEM"};
  for (const auto& [coordinator, components] : system.coordinators) out.push_back(coordinator);
  for (const spec::ComponentSpec& c : system.components) {
    out.push_back(c.name);
    out.push_back(address::framework(c.name));
    out.push_back(address::application(c.name));
    for (const std::string& p : c.provided) {
      out.push_back(address::provided(c.name, p));
      out.push_back(address::service(c.name, p));
    }
    for (const std::string& r : c.required) out.push_back(address::required(c.name, r));
  }
  return out;
}

ScenarioRunner::ScenarioRunner(spec::Scenario scenario, std::unique_ptr<System> system)
    : scenario_(std::move(scenario)),
      system_(std::move(system)),
      clock_(*system_->simulated_clock()),
      coordinator_(system_->coordinator()),
      monitor_(&system_->monitor()),
      runtime_(&system_->runtime()) {}

ScenarioRunner::~ScenarioRunner() {
  if (printer_ != 0) coordinator_.unsubscribe(printer_);
  runtime_->stop();
}

void ScenarioRunner::start_at(Time t) {
  const Time::rep tick_ns = seconds_to_time(scenario_.period).count();
  next_tick_ = t.count() <= 0 ? 0 : (t.count() + tick_ns - 1) / tick_ns;
}

Opened<std::unique_ptr<ScenarioRunner>> ScenarioRunner::open(spec::Scenario scenario, spec::SystemSpec system,
                                                             const FilterRegistry& registry) {
  SystemOptions options;
  options.component_period = seconds_to_time(scenario.period);
  auto built = build_system(std::move(system), registry, options);
  if (!built) return tl::unexpected(std::move(built.error()));
  std::unique_ptr<ScenarioRunner> runner(new ScenarioRunner(std::move(scenario), std::move(*built)));
  if (Diagnostics problems = runner->check_names(); !problems.empty()) return tl::unexpected(std::move(problems));
  return runner;
}

Opened<std::unique_ptr<ScenarioRunner>> ScenarioRunner::open(const ScenarioSource& source,
                                                             const FilterRegistry& registry, Diagnostics* notes) {
  // Every problem at once: the scenario's format problems and the names its readable steps use
  // that the system does not have, in file order, then the system file's errors.
  Diagnostics problems;
  Diagnostics system_errors;
  const auto sort_out = [&](const std::string& here) {
    problems = keep_errors(std::move(problems), notes);
    system_errors = keep_errors(std::move(system_errors), notes);
    // Diagnostics of the scenario file first, by position; a format problem and a name problem
    // of the same file are reported together, where they are.
    std::stable_sort(problems.begin(), problems.end(), [&](const spec::Diagnostic& a, const spec::Diagnostic& b) {
      const bool a_here = a.where.file == here;
      const bool b_here = b.where.file == here;
      if (a_here != b_here) return a_here;
      if (a.where.line != b.where.line) return a.where.line < b.where.line;
      return a.where.column < b.where.column;
    });
    problems.insert(problems.end(), std::make_move_iterator(system_errors.begin()),
                    std::make_move_iterator(system_errors.end()));
  };

  std::optional<spec::Scenario> scenario;
  bool complete = true;  // the scenario file has no format problem (else only its names are checked)
  if (!source.scenario.empty()) {
    spec::ScenarioLoad loaded = spec::load_scenario(source.scenario);
    problems = std::move(loaded.diagnostics);
    complete = loaded.scenario.has_value();
    scenario = complete ? std::move(loaded.scenario) : std::move(loaded.partial);
    if (!scenario) {  // unreadable, or not JSON: nothing more can be said
      sort_out(source.scenario);
      return tl::unexpected(std::move(problems));
    }
  } else {
    scenario.emplace();
    scenario->period = to_seconds(kDefaultTick);
    scenario->duration = 0.0;
  }
  if (!source.system.empty()) scenario->system = source.system;
  std::unique_ptr<ScenarioRunner> runner;
  if (scenario->system.empty()) {
    if (problems.empty()) {
      problems.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, spec::Position{source.scenario, 0, 0},
                                          "a system file is needed (a SYSTEM, or a scenario that names one)", ""});
    }
  } else {
    spec::LoadResult loaded = spec::load_system(scenario->system, registry);
    const bool loaded_ok = loaded.ok();  // read before the diagnostics are moved out
    system_errors = std::move(loaded.diagnostics);
    if (loaded_ok && loaded.system) {
      SystemOptions options;
      options.component_period = seconds_to_time(scenario->period);
      auto built = build_system(std::move(*loaded.system), registry, options);
      if (!built) {
        system_errors.insert(system_errors.end(), built.error().begin(), built.error().end());
      } else {
        runner.reset(new ScenarioRunner(std::move(*scenario), std::move(*built)));
        Diagnostics names = runner->check_names();
        problems.insert(problems.end(), std::make_move_iterator(names.begin()), std::make_move_iterator(names.end()));
      }
    } else if (loaded_ok) {
      system_errors.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error,
                                               spec::Position{scenario->system, 0, 0},
                                               "cannot load system '" + scenario->system + "'", ""});
    }
  }
  sort_out(source.scenario);
  if (!problems.empty() || !complete || !runner) return tl::unexpected(std::move(problems));
  return runner;
}

Diagnostics ScenarioRunner::check_names() {
  const Structure& shape = coordinator_.structure();
  Diagnostics out;
  const auto error_at = [this](const spec::ScenarioStep& s, std::string message) {
    return spec::Diagnostic{spec::Diagnostic::Severity::Error, scenario_.where(s), std::move(message), s.pointer()};
  };
  std::vector<std::string> signal_names;
  for (const auto& sig : monitor_->signals().all()) signal_names.push_back(sig->name());
  std::vector<std::string> filter_names;
  for (const auto& f : monitor_->filters()) filter_names.push_back(f->name());
  std::vector<std::string> event_names;
  for (EventId e : id_range<EventId>(shape.event_count())) event_names.push_back(shape.event(e).name);
  const std::vector<std::string> address_names = addresses();
  const auto no_address = [&](const std::string& address, const std::string& message) {
    return message + spec::did_you_mean(address, address_names);
  };
  for (const spec::ScenarioStep& s : scenario_.steps) {
    const spec::StepAction* action = s.action.get();  // null for a sample step
    const std::size_t before = out.size();
    switch (s.kind) {
      case spec::ScenarioStep::Kind::Sample:
        for (const auto& [name, values] : s.samples) {
          Signal* sig = monitor_->signals().find(name);
          if (sig == nullptr) {
            const std::string suggestion = spec::did_you_mean(name, signal_names);
            out.push_back(
                error_at(s, "no signal '" + std::string(name) + "'" +
                                (suggestion.empty() ? " (signals are written Component.signal)" : suggestion)));
          } else if (sig->size() != values.size()) {
            out.push_back(error_at(s, "signal '" + std::string(name) + "' has size " + std::to_string(sig->size()) +
                                          ", the sample has " + std::to_string(values.size()) + " values"));
          }
        }
        break;
      case spec::ScenarioStep::Kind::Ramp: {
        Signal* sig = monitor_->signals().find(action->signal);
        if (sig == nullptr)
          out.push_back(error_at(s, unknown("signal", action->signal, signal_names)));
        else if (sig->size() != 1)
          out.push_back(error_at(
              s, "a ramp needs a scalar signal; '" + action->signal + "' has size " + std::to_string(sig->size())));
        break;
      }
      case spec::ScenarioStep::Kind::Generate: {
        auto e = shape.find_event(action->event);
        if (!e) {
          out.push_back(error_at(s, unknown("event", action->event, event_names)));
        } else if (!shape.event(*e).is_broadcast()) {
          if (action->target.empty())
            out.push_back(error_at(s, "\"generate\" of '" + action->event + "' needs a \"target\" machine"));
          else if (auto m = shape.find_machine(action->target); !m) {
            out.push_back(error_at(s, no_address(action->target, m.error().message)));
          }
        }
        break;
      }
      case spec::ScenarioStep::Kind::Inject:
        // JSON has no NaN or infinity; a scenario built in C++ follows the same rule (docs/filters.md).
        if (std::any_of(action->values.begin(), action->values.end(), [](const std::vector<double>& v) {
              return std::any_of(v.begin(), v.end(), [](double x) { return !std::isfinite(x); });
            })) {
          out.push_back(error_at(s, "an injected value is not a finite number: injected values must be finite"));
          break;
        }
        if (!action->filter.empty()) {
          Filter* f = monitor_->find_filter(action->filter);
          if (f == nullptr) {
            out.push_back(error_at(s, unknown("filter", action->filter, filter_names)));
          } else if (f->inputs().empty()) {
            out.push_back(error_at(s, "filter '" + action->filter + "' has no input"));
          } else {
            for (const auto& v : action->values) {
              if (v.size() != f->inputs()[0]->size()) {
                out.push_back(error_at(s, "filter '" + action->filter + "' reads '" + f->inputs()[0]->name() +
                                              "' of size " + std::to_string(f->inputs()[0]->size()) +
                                              "; an injected sample has " + std::to_string(v.size()) + " values"));
                break;
              }
            }
          }
        } else if (Signal* sig = monitor_->signals().find(action->signal); sig == nullptr) {
          out.push_back(error_at(s, unknown("signal", action->signal, signal_names)));
        }
        if (out.size() == before) {
          // What the injection itself refuses (more samples than the history holds, a deep sample of
          // the wrong size), said here rather than applied to nothing at its tick.
          for (const introspect::Action& a : step_actions(s, *monitor_, system_->spec())) {
            if (auto ok = introspect::check(a, coordinator_, *monitor_); !ok) {
              out.push_back(error_at(s, ok.error().message));
              break;
            }
          }
        }
        break;
      case spec::ScenarioStep::Kind::Reset:
        // The same rule as Coordinator::reset() and the console: a service state is derived, so a
        // reset of one would do nothing. Refused here, at load, rather than silently at run time.
        if (coordinator_components(action->target) != nullptr) {
          // A coordinator of the system file: all its components are reset (docs/semantics.md §4.5).
        } else if (auto a = shape.resolve(action->target); !a) {
          out.push_back(error_at(s, no_address(action->target, a.error().message)));
        } else if (a->kind == Address::Kind::Service) {
          out.push_back(error_at(s, "cannot reset service state '" + action->target +
                                        "': it is derived; reset its component or a machine"));
        }
        break;
      case spec::ScenarioStep::Kind::Expect:
      case spec::ScenarioStep::Kind::ExpectOutstanding:
      case spec::ScenarioStep::Kind::ExpectCause:
        for (const auto& [address, expected] : action->expectations) {
          if (coordinator_components(address) != nullptr && s.kind == spec::ScenarioStep::Kind::Expect) continue;
          auto a = shape.resolve(address);
          if (!a) {
            out.push_back(error_at(s, no_address(address, a.error().message)));
            continue;
          }
          if (s.kind == spec::ScenarioStep::Kind::ExpectOutstanding) {
            if (a->kind != Address::Kind::Component && a->kind != Address::Kind::Machine) {
              out.push_back(error_at(s, "expect_outstanding needs a component or a machine, not '" + address + "'"));
            } else if (expected != "none" && !shape.find_event(expected)) {
              out.push_back(error_at(s, unknown("event", expected, event_names)));
            }
          }
          if (s.kind == spec::ScenarioStep::Kind::ExpectCause) {
            const auto colon = expected.find(':');
            if (auto m = shape.find_machine(expected.substr(0, colon)); !m) {
              out.push_back(error_at(s, no_address(expected.substr(0, colon), m.error().message)));
            }
            if (!shape.find_event(expected.substr(colon + 1))) {
              out.push_back(error_at(s, unknown("event", expected.substr(colon + 1), event_names)));
            }
          }
        }
        break;
    }
  }
  return out;
}

std::vector<introspect::Action> step_actions(const spec::ScenarioStep& s, const Monitor& monitor,
                                             const spec::SystemSpec& system) {
  std::vector<introspect::Action> out;
  const spec::StepAction* a = s.action.get();  // null for a sample step
  switch (s.kind) {
    case spec::ScenarioStep::Kind::Sample:
      for (const auto& [name, values] : s.samples) {
        out.emplace_back(introspect::PushSample{std::string(name), values.to_vector()});
      }
      break;
    case spec::ScenarioStep::Kind::Generate: out.emplace_back(introspect::GenerateEvent{a->event, a->target}); break;
    case spec::ScenarioStep::Kind::Inject:
      if (!a->deep) {
        out.emplace_back(introspect::InjectShallow{a->filter, a->values});
      } else {
        std::string signal = a->signal;
        if (const Filter* f = a->filter.empty() ? nullptr : monitor.find_filter(a->filter);
            f != nullptr && !f->inputs().empty()) {
          signal = f->inputs()[0]->name();
        }
        out.emplace_back(introspect::InjectDeep{std::move(signal), a->values});
      }
      break;
    case spec::ScenarioStep::Kind::Reset: {
      const auto group = std::find_if(system.coordinators.begin(), system.coordinators.end(),
                                      [&](const auto& c) { return c.first == a->target; });
      if (group == system.coordinators.end()) {
        out.emplace_back(introspect::ResetState{a->target, "scenario", a->reason});
      } else {
        for (const std::string& c : group->second) out.emplace_back(introspect::ResetState{c, "scenario", a->reason});
      }
      break;
    }
    default: break;
  }
  return out;
}

void ScenarioRunner::apply(const spec::ScenarioStep& s, Time now) {
  if (s.kind == spec::ScenarioStep::Kind::Ramp) {
    const spec::StepAction& a = *s.action;
    ramps_.push_back(Ramp{monitor_->signals().find(a.signal), now, seconds_to_time(a.until), a.from, a.to});
    return;
  }
  // Checked when the runner was opened (check_names): an action refused here is a bug, not input.
  for (const introspect::Action& action : step_actions(s, *monitor_, system_->spec())) {
    (void)introspect::apply(action, coordinator_, *monitor_, now, inputs_.get());
  }
}

std::string ScenarioRunner::check_one(const spec::ScenarioStep& s, const std::string& address,
                                      const std::string& expected) {
  if (const auto* components = coordinator_components(address);
      components != nullptr && s.kind == spec::ScenarioStep::Kind::Expect) {
    // The state of a coordinator of the system: the product of its components' (DESIGN §2.2).
    State got = State::Normal;
    for (const std::string& c : *components)
      got = std::max(got, coordinator_.state_of(*coordinator_.structure().resolve(c)));
    const State want = *parse_state(expected);
    if (got == want) return {};
    return address + " is " + std::string(to_string(got)) + ", expected " + std::string(to_string(want));
  }
  return expectation_problem(coordinator_, s, address, expected);
}

std::string expectation_problem(const Coordinator& co, const spec::ScenarioStep& s, const std::string& address,
                                const std::string& expected) {
  const Address a = *co.structure().resolve(address);
  switch (s.kind) {
    case spec::ScenarioStep::Kind::Expect: {
      const State want = *parse_state(expected);
      const State got = co.state_of(a);
      if (got == want) return {};
      return address + " is " + std::string(to_string(got)) + ", expected " + std::string(to_string(want));
    }
    case spec::ScenarioStep::Kind::ExpectOutstanding: {
      if (a.kind != Address::Kind::Component && a.kind != Address::Kind::Machine) return {};  // refused on load
      const StateSnapshot snap = a.kind == Address::Kind::Component ? co.extended(a.component) : co.snapshot(a.machine);
      const std::string got = snap.outstanding == kNoEvent ? "none" : co.structure().event(snap.outstanding).name;
      if (got == expected) return {};
      return "outstanding event of " + address + " is " + got + ", expected " + expected;
    }
    case spec::ScenarioStep::Kind::ExpectCause: {
      // Some condition at the address's current level has this root cause.
      const State level = co.state_of(a);
      std::string seen;
      for (const Explanation& e : co.explain(a)) {
        if (e.level != level) continue;
        const std::string cause = e.root.name();
        if (cause == expected) return {};
        seen += (seen.empty() ? "" : ", ") + cause;
      }
      return "cause of " + address + " (" + std::string(to_string(level)) + ") is " + (seen.empty() ? "none" : seen) +
             ", expected " + expected;
    }
    default: return {};
  }
}

std::string ExpectationFailure::text() const {
  return where.file + ":" + std::to_string(where.line) + ":" + std::to_string(where.column) +
         ": expectation failed at t=" + secs(at) + ": " + problem + " [" + pointer + "]";
}

void ScenarioRunner::check(const spec::ScenarioStep& s, Time now, RunResult& result) {
  for (const auto& [address, expected] : s.action->expectations) {
    ++result.checks;
    const std::string problem = check_one(s, address, expected);
    if (s.kind == spec::ScenarioStep::Kind::Expect) {
      result.coverage.states_checked.push_back(StateCheck{address, *parse_state(expected), now, problem.empty()});
    }
    if (problem.empty()) continue;
    const ExpectationFailure failure{scenario_.where(s), s.pointer(), now, address, problem};
    if (on_failure_) on_failure_(failure);
    result.failures.push_back(failure.text());
  }
}

bool ScenarioRunner::begin(const RunOptions& options, RunResult& result) {
  if (!options.record_path.empty()) {
    auto r = Recorder::open(coordinator_, options.record_path, 65536, options.limits);
    if (!r) {
      result.failures.push_back(r.error().message);
      return false;
    }
    recorder_ = std::move(*r);
  }
  std::string inputs_path = options.inputs_path;
  if (inputs_path.empty() && !options.record_path.empty())
    inputs_path = InputRecorder::path_for_history(options.record_path);
  if (!inputs_path.empty() && inputs_path != "-") {
    InputRecorderOptions o;
    o.limits = options.limits;
    o.period = seconds_to_time(scenario_.period);
    auto r = InputRecorder::open(*monitor_, inputs_path, o);
    if (!r) {
      result.failures.push_back(r.error().message);
      return false;
    }
    inputs_ = std::move(*r);
  }
  printer_ = coordinator_.subscribe([this, &result, json = options.json, quiet = options.quiet,
                                     out = options.out](const Record& r) {
    if (r.kind == RecordKind::Event && r.outcome != Outcome::Ignored && r.event != kNoEvent) {
      result.coverage.events_fired.insert(coordinator_.structure().event(r.event).name);
      if (r.root.event != kNoEvent)
        result.coverage.events_fired.insert(coordinator_.structure().event(r.root.event).name);
    }
    if (r.kind == RecordKind::Transition && r.event != kNoEvent) {
      result.coverage.taken.emplace(coordinator_.structure().event(r.event).name,
                                    std::string(to_string(transition_between(r.from, r.to))));
    }
    const bool shown = r.kind == RecordKind::Transition || r.kind == RecordKind::Reset ||
                       r.kind == RecordKind::Injection ||
                       (r.kind == RecordKind::Event && (r.outcome == Outcome::Masked || r.outcome == Outcome::Ignored));
    if (quiet || !shown) return;
    const std::string line = json ? record_to_json(r, coordinator_) : record_to_text(r, coordinator_);
    std::fprintf(out, "%s\n", line.c_str());
  });
  return true;
}

void ScenarioRunner::finish(RunResult& result) {
  for (; next_check_ < checks_.size(); ++next_check_) {
    const spec::ScenarioStep& s = *checks_[next_check_];
    result.failures.push_back(scenario_.path + ":" + std::to_string(s.line) + ":" + std::to_string(s.column) +
                              ": expectation at t=" + secs(seconds_to_time(s.at)) +
                              " is after the scenario's duration");
  }
  if (printer_ != 0) {
    coordinator_.unsubscribe(printer_);
    printer_ = 0;
  }
  if (inputs_) {
    inputs_->close(now() < Time{0} ? Time{0} : now());
    result.inputs = inputs_->status();
  }
  if (recorder_) {
    recorder_->close();
    result.record = recorder_->status();
  }
  for (EventId e : id_range(EventId{framework_event::kCount}, coordinator_.structure().event_count())) {
    const Event& ev = coordinator_.structure().event(e);
    for (Transition t :
         {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N, Transition::E2W}) {
      if (ev.transitions.contains(t)) result.coverage.defined.emplace(ev.name, std::string(to_string(t)));
    }
  }
}

RunResult ScenarioRunner::run(const RunOptions& options) {
  RunResult result;
  if (!begin(options, result)) return result;
  const auto ticks = static_cast<std::int64_t>(std::llround(scenario_.duration / scenario_.period));
  advance_to(Time{ticks * seconds_to_time(scenario_.period).count()}, result);
  finish(result);
  return result;
}

void ScenarioRunner::split_steps() {
  if (split_) return;
  split_ = true;
  for (const spec::ScenarioStep& s : scenario_.steps) {
    const bool is_check = s.kind == spec::ScenarioStep::Kind::Expect ||
                          s.kind == spec::ScenarioStep::Kind::ExpectOutstanding ||
                          s.kind == spec::ScenarioStep::Kind::ExpectCause;
    (is_check ? checks_ : actions_).push_back(&s);
  }
}

Time ScenarioRunner::now() const noexcept { return Time{(next_tick_ - 1) * seconds_to_time(scenario_.period).count()}; }

void ScenarioRunner::advance_to(Time until, RunResult& result) {
  split_steps();
  const Time::rep tick_ns = seconds_to_time(scenario_.period).count();
  for (; next_tick_ * tick_ns <= until.count(); ++next_tick_) {
    const Time now{next_tick_ * tick_ns};
    clock_.set(now);
    if (feed_) feed_(now);
    // (1) steps due at this tick, in file order (first tick at or after their time).
    while (next_step_ < actions_.size() && seconds_to_time(actions_[next_step_]->at) <= now)
      apply(*actions_[next_step_++], now);
    for (auto it = ramps_.begin(); it != ramps_.end();) {
      const double span = to_seconds(it->until - it->from_time);
      const double f = span <= 0 ? 1.0 : std::min(1.0, to_seconds(now - it->from_time) / span);
      it->signal->push(now, it->from + (it->to - it->from) * f);
      it = now >= it->until ? ramps_.erase(it) : it + 1;
    }
    // (2) filters and component loops due at this tick.
    runtime_->step(now);
    if (inputs_) inputs_->drain();
    // (3) expectations due at this tick.
    while (next_check_ < checks_.size() && seconds_to_time(checks_[next_check_]->at) <= now)
      check(*checks_[next_check_++], now, result);
  }
}

std::vector<spec::Diagnostic> check_scenario(const std::string& path, const FilterRegistry& registry,
                                             const std::string& system_override) {
  auto opened = ScenarioRunner::open(ScenarioSource{path, system_override}, registry);
  return opened ? Diagnostics{} : std::move(opened.error());
}

int run_scenario_file(const std::string& path, const FilterRegistry& registry, const RunOptions& options,
                      RunResult* result, std::FILE* err) {
  auto opened = ScenarioRunner::open(ScenarioSource{path, options.system_override}, registry);
  if (!opened) {
    print(opened.error(), err);
    return 2;
  }
  ScenarioRunner& runner = **opened;
  RunResult r = runner.run(options);
  for (const std::string& f : r.failures) std::fprintf(err, "%s\n", f.c_str());
  int code = r.passed() ? 0 : 1;
  // Nothing lost silently: a recording that misses samples or records is said, and fails the command.
  if (r.inputs) {
    for (const std::string& loss : describe_losses(*r.inputs)) std::fprintf(err, "%s\n", loss.c_str());
    if (options.json) std::fprintf(options.out, "%s\n", record_status_json(*r.inputs).c_str());
    if (!r.inputs->complete()) code = 2;
  }
  if (r.record) {
    // Nothing lost silently: a history that misses records is said, and fails the command.
    for (const std::string& loss : describe_losses(*r.record)) std::fprintf(err, "%s\n", loss.c_str());
    if (options.json) std::fprintf(options.out, "%s\n", record_status_json(*r.record).c_str());
    if (!r.record->complete()) code = 2;
  }
  if (result != nullptr) *result = std::move(r);
  return code;
}

}  // namespace safecass::runner
