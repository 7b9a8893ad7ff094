#include "safecass/runner/scenario_runner.hpp"

#include <algorithm>
#include <cmath>

#include "safecass/introspect/format.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::runner {

namespace {
constexpr Time kMonitorPeriod = std::chrono::milliseconds(5);

std::string secs(Time t) { return introspect::seconds_text(t); }
}  // namespace

ScenarioRunner::ScenarioRunner(spec::Scenario scenario, spec::SystemSpec system, const FilterRegistry& registry)
    : scenario_(std::move(scenario)),
      system_(std::move(system)),
      coordinator_(system_.name.empty() ? "system" : system_.name, &clock_),
      monitor_(std::make_unique<Monitor>(coordinator_, registry)),
      runtime_(std::make_unique<native::Runtime>(*monitor_, kMonitorPeriod)) {}

ScenarioRunner::~ScenarioRunner() { runtime_->stop(); }

std::vector<spec::Diagnostic> ScenarioRunner::prepare() {
  std::vector<spec::Diagnostic> out;
  const auto error_at = [this](const spec::ScenarioStep& s, std::string message) {
    return spec::Diagnostic{spec::Diagnostic::Severity::Error, scenario_.where(s), std::move(message), s.pointer()};
  };
  const spec::Position at_system{scenario_.system, 1, 1};
  if (auto built = spec::instantiate(system_, coordinator_, *monitor_); !built) {
    out.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, at_system, built.error().message, ""});
    return out;
  }
  const Time tick = seconds_to_time(scenario_.period);
  for (const spec::ComponentSpec& c : system_.components) {
    const ComponentId id = *coordinator_.find_component(c.name);
    const Time period = c.period ? seconds_to_time(*c.period) : tick;
    if (auto r = runtime_->add_task(id, period); !r) {
      out.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, c.where, r.error().message, ""});
    }
  }
  for (const spec::ScenarioStep& s : scenario_.steps) {
    const spec::StepAction* action = s.action.get();  // null for a sample step
    switch (s.kind) {
      case spec::ScenarioStep::Kind::Sample:
        for (const auto& [name, values] : s.samples) {
          Signal* sig = monitor_->signals().find(name);
          if (sig == nullptr) {
            out.push_back(error_at(s, "no signal '" + std::string(name) + "' (signals are written Component.signal)"));
          } else if (sig->size() != values.size()) {
            out.push_back(error_at(s, "signal '" + std::string(name) + "' has size " + std::to_string(sig->size()) +
                                                     ", the sample has " + std::to_string(values.size()) + " values"));
          }
        }
        break;
      case spec::ScenarioStep::Kind::Ramp: {
        Signal* sig = monitor_->signals().find(action->signal);
        if (sig == nullptr) out.push_back(error_at(s, "no signal '" + action->signal + "'"));
        else if (sig->size() != 1) out.push_back(error_at(s, "a ramp needs a scalar signal; '" + action->signal + "' has size " + std::to_string(sig->size())));
        break;
      }
      case spec::ScenarioStep::Kind::Generate: {
        auto e = coordinator_.find_event(action->event);
        if (!e) {
          out.push_back(error_at(s, e.error().message));
        } else if (!coordinator_.event(*e).is_broadcast()) {
          if (action->target.empty()) out.push_back(error_at(s, "\"generate\" of '" + action->event + "' needs a \"target\" machine"));
          else if (auto m = coordinator_.find_machine(action->target); !m) out.push_back(error_at(s, m.error().message));
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
            out.push_back(error_at(s, "no filter '" + action->filter + "'"));
          } else if (f->inputs().empty()) {
            out.push_back(error_at(s, "filter '" + action->filter + "' has no input"));
          } else {
            for (const auto& v : action->values) {
              if (v.size() != f->inputs()[0]->size()) {
                out.push_back(error_at(s, "filter '" + action->filter + "' reads '" + f->inputs()[0]->name() + "' of size " +
                                              std::to_string(f->inputs()[0]->size()) + "; an injected sample has " +
                                              std::to_string(v.size()) + " values"));
                break;
              }
            }
          }
        } else if (Signal* sig = monitor_->signals().find(action->signal); sig == nullptr) {
          out.push_back(error_at(s, "no signal '" + action->signal + "'"));
        }
        break;
      case spec::ScenarioStep::Kind::Reset:
        // The same rule as Coordinator::reset() and the console: a service state is derived, so a
        // reset of one would do nothing. Refused here, at load, rather than silently at run time.
        if (auto a = coordinator_.resolve(action->target); !a) {
          out.push_back(error_at(s, a.error().message));
        } else if (a->kind == Address::Kind::Service) {
          out.push_back(error_at(s, "cannot reset service state '" + action->target +
                                        "': it is derived; reset its component or a machine"));
        }
        break;
      case spec::ScenarioStep::Kind::Expect:
      case spec::ScenarioStep::Kind::ExpectOutstanding:
      case spec::ScenarioStep::Kind::ExpectCause:
        for (const auto& [address, expected] : action->expectations) {
          auto a = coordinator_.resolve(address);
          if (!a) {
            out.push_back(error_at(s, a.error().message));
            continue;
          }
          if (s.kind == spec::ScenarioStep::Kind::ExpectOutstanding) {
            if (a->kind != Address::Kind::Component && a->kind != Address::Kind::Machine) {
              out.push_back(error_at(s, "expect_outstanding needs a component or a machine, not '" + address + "'"));
            } else if (expected != "none" && !coordinator_.find_event(expected)) {
              out.push_back(error_at(s, "no event '" + expected + "'"));
            }
          }
          if (s.kind == spec::ScenarioStep::Kind::ExpectCause) {
            const auto colon = expected.find(':');
            if (auto m = coordinator_.find_machine(expected.substr(0, colon)); !m) out.push_back(error_at(s, m.error().message));
            if (!coordinator_.find_event(expected.substr(colon + 1))) out.push_back(error_at(s, "no event '" + expected.substr(colon + 1) + "'"));
          }
        }
        break;
    }
  }
  return out;
}

void ScenarioRunner::apply(const spec::ScenarioStep& s, Time now) {
  const spec::StepAction* action = s.action.get();  // null for a sample step
  switch (s.kind) {
    case spec::ScenarioStep::Kind::Sample:
      for (const auto& [name, values] : s.samples) monitor_->signals().find(name)->push(now, values.data());
      break;
    case spec::ScenarioStep::Kind::Ramp:
      ramps_.push_back(Ramp{monitor_->signals().find(action->signal), now, seconds_to_time(action->until), action->from, action->to});
      break;
    case spec::ScenarioStep::Kind::Generate:
      (void)coordinator_.generate(action->event, action->target);
      break;
    case spec::ScenarioStep::Kind::Inject:
      if (!action->deep) {
        (void)monitor_->inject_shallow(action->filter, action->values);
      } else {
        const std::string signal = action->filter.empty() ? action->signal : monitor_->find_filter(action->filter)->inputs()[0]->name();
        (void)monitor_->inject_deep(signal, action->values, now);
      }
      break;
    case spec::ScenarioStep::Kind::Reset:
      (void)coordinator_.reset(action->target, "scenario", action->reason);
      break;
    default: break;
  }
}

std::string ScenarioRunner::check_one(const spec::ScenarioStep& s, const std::string& address, const std::string& expected) {
  const Address a = *coordinator_.resolve(address);
  switch (s.kind) {
    case spec::ScenarioStep::Kind::Expect: {
      const State want = *parse_state(expected);
      const State got = coordinator_.state_of(a);
      if (got == want) return {};
      return address + " is " + std::string(to_string(got)) + ", expected " + std::string(to_string(want));
    }
    case spec::ScenarioStep::Kind::ExpectOutstanding: {
      const StateSnapshot snap = a.kind == Address::Kind::Component ? coordinator_.extended(a.component)
                                                                    : coordinator_.snapshot(a.machine);
      const std::string got = snap.outstanding == kNoEvent ? "none" : coordinator_.event(snap.outstanding).name;
      if (got == expected) return {};
      return "outstanding event of " + address + " is " + got + ", expected " + expected;
    }
    case spec::ScenarioStep::Kind::ExpectCause: {
      // Some condition at the address's current level has this root cause.
      const State level = coordinator_.state_of(a);
      std::string seen;
      for (const Explanation& e : coordinator_.explain(a)) {
        if (e.level != level) continue;
        const std::string cause = e.root_origin + ":" + e.root_event;
        if (cause == expected) return {};
        seen += (seen.empty() ? "" : ", ") + cause;
      }
      return "cause of " + address + " (" + std::string(to_string(level)) + ") is " + (seen.empty() ? "none" : seen) +
             ", expected " + expected;
    }
    default: return {};
  }
}

void ScenarioRunner::check(const spec::ScenarioStep& s, Time now, RunResult& result) {
  for (const auto& [address, expected] : s.action->expectations) {
    ++result.checks;
    const std::string problem = check_one(s, address, expected);
    if (problem.empty()) continue;
    result.failures.push_back(scenario_.path + ":" + std::to_string(s.line) + ":" + std::to_string(s.column) +
                              ": expectation failed at t=" + secs(now) + ": " + problem + " [" + s.pointer() + "]");
  }
}

RunResult ScenarioRunner::run(const RunOptions& options) {
  RunResult result;
  std::unique_ptr<Recorder> recorder;
  if (!options.record_path.empty()) {
    auto r = Recorder::open(coordinator_, options.record_path);
    if (!r) {
      result.failures.push_back(r.error().message);
      return result;
    }
    recorder = std::move(*r);
  }
  const auto subscription = coordinator_.subscribe([&](const Record& r) {
    if (r.kind == RecordKind::Event && r.outcome != Outcome::Ignored && r.event != kNoEvent) {
      result.coverage.events_fired.insert(coordinator_.event(r.event).name);
      if (r.root.event != kNoEvent) result.coverage.events_fired.insert(coordinator_.event(r.root.event).name);
    }
    if (r.kind == RecordKind::Transition && r.event != kNoEvent) {
      result.coverage.taken.emplace(coordinator_.event(r.event).name, std::string(to_string(transition_between(r.from, r.to))));
    }
    const bool shown = r.kind == RecordKind::Transition || r.kind == RecordKind::Reset || r.kind == RecordKind::Injection ||
                       (r.kind == RecordKind::Event && (r.outcome == Outcome::Masked || r.outcome == Outcome::Ignored));
    if (options.quiet || !shown) return;
    const std::string line = options.json ? record_to_json(r, coordinator_) : record_to_text(r, coordinator_);
    std::fprintf(options.out, "%s\n", line.c_str());
  });

  const auto ticks = static_cast<std::int64_t>(std::llround(scenario_.duration / scenario_.period));
  advance_to(Time{ticks * seconds_to_time(scenario_.period).count()}, result);
  for (; next_check_ < checks_.size(); ++next_check_) {
    const spec::ScenarioStep& s = *checks_[next_check_];
    result.failures.push_back(scenario_.path + ":" + std::to_string(s.line) + ":" + std::to_string(s.column) +
                              ": expectation at t=" + secs(seconds_to_time(s.at)) + " is after the scenario's duration");
  }
  coordinator_.unsubscribe(subscription);
  if (recorder) {
    recorder->close();
    result.record = recorder->status();
  }
  for (EventId e = framework_event::kCount; e < coordinator_.event_count(); ++e) {
    const Event& ev = coordinator_.event(e);
    for (Transition t : {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N, Transition::E2W}) {
      if (ev.transitions.contains(t)) result.coverage.defined.emplace(ev.name, std::string(to_string(t)));
    }
  }
  return result;
}

void ScenarioRunner::split_steps() {
  if (split_) return;
  split_ = true;
  for (const spec::ScenarioStep& s : scenario_.steps) {
    const bool is_check = s.kind == spec::ScenarioStep::Kind::Expect || s.kind == spec::ScenarioStep::Kind::ExpectOutstanding ||
                          s.kind == spec::ScenarioStep::Kind::ExpectCause;
    (is_check ? checks_ : actions_).push_back(&s);
  }
}

Time ScenarioRunner::now() const noexcept {
  return Time{(next_tick_ - 1) * seconds_to_time(scenario_.period).count()};
}

void ScenarioRunner::advance_to(Time until, RunResult& result) {
  split_steps();
  const Time::rep tick_ns = seconds_to_time(scenario_.period).count();
  for (; next_tick_ * tick_ns <= until.count(); ++next_tick_) {
    const Time now{next_tick_ * tick_ns};
    clock_.set(now);
    // (1) steps due at this tick, in file order (first tick at or after their time).
    while (next_step_ < actions_.size() && seconds_to_time(actions_[next_step_]->at) <= now) apply(*actions_[next_step_++], now);
    for (auto it = ramps_.begin(); it != ramps_.end();) {
      const double span = to_seconds(it->until - it->from_time);
      const double f = span <= 0 ? 1.0 : std::min(1.0, to_seconds(now - it->from_time) / span);
      it->signal->push(now, it->from + (it->to - it->from) * f);
      it = now >= it->until ? ramps_.erase(it) : it + 1;
    }
    // (2) filters and component loops due at this tick.
    runtime_->step(now);
    // (3) expectations due at this tick.
    while (next_check_ < checks_.size() && seconds_to_time(checks_[next_check_]->at) <= now) check(*checks_[next_check_++], now, result);
  }
}

int run_scenario_file(const std::string& path, const FilterRegistry& registry, const RunOptions& options,
                      RunResult* result, std::FILE* err) {
  spec::ScenarioLoad sc = spec::load_scenario(path);
  for (const auto& d : sc.diagnostics) std::fprintf(err, "%s\n", spec::format(d).c_str());
  if (!sc.scenario) return 2;
  if (!options.system_override.empty()) sc.scenario->system = options.system_override;
  spec::LoadResult sys = spec::load_system(sc.scenario->system, registry);
  for (const auto& d : sys.diagnostics) {
    if (d.severity == spec::Diagnostic::Severity::Error) std::fprintf(err, "%s\n", spec::format(d).c_str());
  }
  if (!sys.ok() || !sys.system) return 2;
  ScenarioRunner runner(std::move(*sc.scenario), std::move(*sys.system), registry);
  const auto problems = runner.prepare();
  for (const auto& d : problems) std::fprintf(err, "%s\n", spec::format(d).c_str());
  if (!problems.empty()) return 2;
  RunResult r = runner.run(options);
  for (const std::string& f : r.failures) std::fprintf(err, "%s\n", f.c_str());
  int code = r.passed() ? 0 : 1;
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
