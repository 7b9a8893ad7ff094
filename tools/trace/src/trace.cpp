// Building the trace: the specification's chain hazard → events → filters → reaction, and the
// evidence of the scenario runs (which events fired, which transitions they took, which
// expectations checked the reaction), with every missing piece as a gap.

#include "safecass/trace/trace.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

#include "safecass/core/text.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/introspect/model.hpp"
#include "safecass/json/read.hpp"
#include "safecass/native/system.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/file.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::trace {

namespace {

using Diagnostics = std::vector<spec::Diagnostic>;

constexpr Transition kTransitionOrder[] = {Transition::N2W, Transition::N2E, Transition::W2E,
                                           Transition::W2N, Transition::E2N, Transition::E2W};

spec::Diagnostic error_at(spec::Position where, std::string message) {
  return spec::Diagnostic{spec::Diagnostic::Severity::Error, std::move(where), std::move(message), ""};
}

std::string param_text(const ParamValue& v) {
  if (const double* d = std::get_if<double>(&v)) return number_text(*d);
  if (const bool* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  if (const std::string* s = std::get_if<std::string>(&v)) return *s;
  std::string out = "[";
  if (const auto* list = std::get_if<std::vector<std::string>>(&v)) {
    for (std::size_t k = 0; k < list->size(); ++k) out += (k == 0 ? "" : ", ") + (*list)[k];
  } else if (const auto* nums = std::get_if<std::vector<double>>(&v)) {
    for (std::size_t k = 0; k < nums->size(); ++k) out += (k == 0 ? "" : ", ") + number_text((*nums)[k]);
  }
  return out + "]";
}

std::string transitions_text(TransitionSet set) {
  std::string out;
  for (Transition t : kTransitionOrder) {
    if (set.contains(t)) out += (out.empty() ? "" : " ") + std::string(to_string(t));
  }
  return out;
}

/// The component part of an address ("CONTROL.s_R.ForceData" → "CONTROL").
std::string component_of(const std::string& address) { return address.substr(0, address.find('.')); }

/// What the specification says about one filter (one pipeline stage).
struct FilterFacts {
  FilterLink link;
  EventId onset = kNoEvent;
  EventId completion = kNoEvent;
};

/// What one scenario run showed, beyond the runner's coverage.
struct RunFacts {
  runner::RunResult result;
  std::map<EventId, Time> first_onset;  ///< an onset processed (not ignored)
  std::map<EventId, std::set<MachineId>> onset_machines;
  std::map<EventId, std::vector<Time>> completions;  ///< completion events processed, by onset
  std::vector<std::pair<Time, MachineId>> machine_resets;
  std::vector<std::pair<Time, ComponentId>> component_resets;
  std::map<EventId, std::set<std::string>> onset_components;
  double duration = 0.0;
};

/// The time an onset that first fired at `since` was cleared in the run (its completion processed,
/// or its machine or component reset), or nullopt.
std::optional<Time> cleared_at(const RunFacts& run, const Coordinator& co, EventId onset, Time since) {
  std::optional<Time> best;
  const auto take = [&](Time t) {
    if (t >= since && (!best || t < *best)) best = t;
  };
  if (auto it = run.completions.find(onset); it != run.completions.end()) {
    for (Time t : it->second) take(t);
  }
  const auto machines = run.onset_machines.find(onset);
  if (machines == run.onset_machines.end()) return best;
  for (const auto& [t, m] : run.machine_resets) {
    if (machines->second.count(m) != 0) take(t);
  }
  for (const auto& [t, c] : run.component_resets) {
    for (MachineId m : machines->second) {
      if (co.structure().machine_component(m) == c) take(t);
    }
  }
  return best;
}

/// Reads `safecass verify --json` output: one JSON object per line; `{"kind":"hazard","name":ID,
/// "result":"holds"|"violated"|"undecided"}` gives a hazard's verdict.
[[nodiscard]] tl::expected<std::map<std::string, Verdict>, Diagnostics> read_verify(const std::string& path) {
  auto text = spec::read_regular_file(path);
  if (!text) return tl::unexpected(Diagnostics{error_at(spec::Position{path, 0, 0}, text.error().message)});
  std::map<std::string, Verdict> out;
  Diagnostics errors;
  bool any = false;
  int line = 0;
  std::size_t start = 0;
  while (start < text->size()) {
    std::size_t end = text->find('\n', start);
    if (end == std::string::npos) end = text->size();
    const std::string_view row(text->data() + start, end - start);
    start = end + 1;
    ++line;
    if (row.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    const json::JsonParse parsed = json::parse_json(row);
    if (parsed.error || !parsed.value || !parsed.value->is_object()) {
      errors.push_back(error_at(spec::Position{path, line, parsed.error ? parsed.error->position.column : 1},
                                "not a `safecass verify --json` line: " +
                                    (parsed.error ? parsed.error->message : std::string("a JSON object is expected"))));
      continue;
    }
    const json::JsonValue& object = *parsed.value;
    const json::JsonValue* kind = object.find("kind");
    if (kind == nullptr || !kind->is_string()) {
      errors.push_back(error_at(spec::Position{path, line, 1}, "not a `safecass verify --json` line: no \"kind\""));
      continue;
    }
    any = true;
    if (kind->string != "hazard") continue;
    const json::JsonValue* name = object.find("name");
    const json::JsonValue* result = object.find("result");
    if (name == nullptr || result == nullptr || !name->is_string() || !result->is_string()) {
      errors.push_back(error_at(spec::Position{path, line, 1}, "a hazard line needs \"name\" and \"result\" strings"));
      continue;
    }
    Verdict v = Verdict::Undecided;
    if (result->string == "holds")
      v = Verdict::Holds;
    else if (result->string == "violated")
      v = Verdict::Violated;
    out[name->string] = v;
  }
  if (errors.empty() && !any)
    errors.push_back(error_at(spec::Position{path, 0, 0}, "no `safecass verify --json` result in the file"));
  if (!errors.empty()) return tl::unexpected(std::move(errors));
  return out;
}

}  // namespace

std::string_view to_string(Verdict v) noexcept {
  switch (v) {
    case Verdict::Holds: return "holds";
    case Verdict::Violated: return "violated";
    case Verdict::Undecided: return "undecided";
    case Verdict::NotRun: break;
  }
  return "not run";
}

std::string_view to_string(Severity s) noexcept {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Info: break;
  }
  return "info";
}

bool Trace::has_error_gap() const noexcept {
  return std::any_of(gaps.begin(), gaps.end(), [](const Gap& g) { return g.severity == Severity::Error; });
}

namespace {

/// Builds one trace, step by step (build_trace below): the specification and its files, the
/// built system's filters and events, the scenario runs, each hazard with its gaps, the gaps of
/// what no hazard claims, the coverage summary.
class Builder {
public:
  Builder(const TraceOptions& options, const FilterRegistry& registry) : options_(options), registry_(registry) {}

  [[nodiscard]] tl::expected<Trace, Diagnostics> build() {
    if (Diagnostics errors = load(); !errors.empty()) return tl::unexpected(std::move(errors));
    collect_sources();
    collect_filters();
    if (Diagnostics errors = run_scenarios(); !errors.empty()) return tl::unexpected(std::move(errors));
    for (const spec::HazardSpec& h : sys().hazards) trace_.hazards.push_back(trace_hazard(h));
    unclaimed_filters_and_failed_scenarios();
    collect_onsets();
    std::stable_sort(gaps_.begin(), gaps_.end(), [](const Gap& a, const Gap& b) { return a.severity < b.severity; });
    trace_.gaps = std::move(gaps_);
    summarize_coverage();
    return std::move(trace_);
  }

private:
  struct StageSource {
    std::string pipeline;
    std::vector<std::string> chain;
    spec::Position where;
    std::optional<double> period;
  };

  const spec::SystemSpec& sys() const { return *loaded_.system; }
  const Coordinator& co() const { return system_->coordinator(); }

  // ---- the specification ----------------------------------------------------------------------
  /// Loads the system, the verify verdicts and every spec file's hash, and builds the system.
  [[nodiscard]] Diagnostics load() {
    trace_.system_path = options_.system;
    loaded_ = spec::load_system(options_.system, registry_);
    Diagnostics errors;
    for (spec::Diagnostic& d : loaded_.diagnostics) {
      (d.severity == spec::Diagnostic::Severity::Error ? errors : trace_.notes).push_back(std::move(d));
    }
    if (!errors.empty() || !loaded_.system) {
      if (errors.empty()) errors.push_back(error_at(spec::Position{options_.system, 0, 0}, "cannot load the system"));
      return errors;
    }
    trace_.system = sys().name;

    if (!options_.verify_json.empty()) {
      auto v = read_verify(options_.verify_json);
      if (!v) return std::move(v.error());
      verdicts_ = std::move(*v);
      trace_.verify_source = options_.verify_json;
    }

    // Every spec file with its SHA-256: the evidence names exactly what it was built from.
    std::vector<std::string> paths{sys().path.empty() ? options_.system : sys().path};
    for (const spec::ComponentSpec& c : sys().components) {
      if (!c.file.empty() && std::find(paths.begin(), paths.end(), c.file) == paths.end()) paths.push_back(c.file);
    }
    for (const std::string& p : paths) {
      auto bytes = spec::read_regular_file(p, std::size_t{16} << 20);
      if (!bytes) return Diagnostics{error_at(spec::Position{p, 0, 0}, bytes.error().message)};
      trace_.files.push_back(SpecFile{p, sha256_hex(*bytes)});
    }

    // The built system: events as the coordinator checked them, filters with their defaults.
    auto built = native::build_system(sys(), registry_);
    if (!built) return std::move(built.error());
    system_ = std::move(*built);
    return {};
  }

  /// Where each filter stage and each event is written in the specification.
  void collect_sources() {
    for (const spec::ComponentSpec& c : sys().components) {
      for (const spec::FilterSpec& fs : c.filters) {
        std::vector<std::string> chain;
        if (!fs.pipeline.empty()) {
          for (const FilterConfig& st : fs.stages) chain.push_back(st.name);
        }
        for (const FilterConfig& st : fs.stages)
          stage_source_[st.name] = StageSource{fs.pipeline, chain, fs.where, c.period};
      }
      for (std::size_t k = 0; k < c.events.size(); ++k) {
        const spec::Position where = k < c.event_where.size() ? c.event_where[k] : c.where;
        event_source_.emplace(c.events[k].name, std::make_pair(c.name, where));
        event_order_.push_back(c.events[k].name);
      }
    }
  }

  void collect_filters() {
    for (const auto& f : system_->monitor().filters()) filters_.push_back(filter_facts(*f));
  }

  /// One built filter: where it is written, what it reads and targets, its period, the events it
  /// generates and its other parameters.
  FilterFacts filter_facts(const Filter& f) const {
    FilterFacts ff;
    FilterLink& l = ff.link;
    const FilterConfig& cfg = f.config();
    l.name = cfg.name;
    l.type = cfg.type;
    l.component = std::string(co().structure().component_name(f.component()));
    l.target = f.target() == kNoMachine ? std::string() : co().structure().address_of(f.target());
    for (const Signal* s : f.inputs()) l.signals += (l.signals.empty() ? "" : ", ") + s->name();
    for (const Signal* s : f.outputs()) {
      if (s != nullptr) l.outputs += (l.outputs.empty() ? "" : ", ") + s->name();  // an optional output not used
    }
    l.execution = cfg.execution == ExecutionMode::Active ? "ACTIVE" : "PASSIVE";
    const auto src = stage_source_.find(cfg.name);
    if (src != stage_source_.end()) {
      l.pipeline = src->second.pipeline;
      l.chain = src->second.chain;
      l.where = src->second.where;
    }
    if (cfg.execution == ExecutionMode::Passive) {
      l.period = number_text(to_seconds(Monitor::kDefaultPeriod)) + " s (monitor)";
    } else if (src != stage_source_.end() && src->second.period) {
      l.period = number_text(*src->second.period) + " s (" + l.component + "'s period)";
    } else {
      l.period = "the scenario's tick (" + l.component + " names no period)";
    }
    // Events: the manifest's first Event parameter is the onset, the second the completion.
    std::set<std::string> event_params;
    if (const FilterRegistry::Entry* entry = registry_.find(cfg.type)) {
      int k = 0;
      for (const ParamSpec& p : entry->manifest.params) {
        if (p.type != ParamType::Event) continue;
        event_params.insert(p.name);
        const auto it = cfg.params.find(p.name);
        if (it != cfg.params.end() && k < 2) {
          if (const std::string* name = std::get_if<std::string>(&it->second)) {
            if (auto e = co().structure().find_event(*name)) (k == 0 ? ff.onset : ff.completion) = *e;
          }
        }
        ++k;
      }
    }
    if (ff.onset != kNoEvent && ff.completion == kNoEvent) ff.completion = co().structure().event(ff.onset).counterpart;
    for (const auto& [name, value] : cfg.params) {
      if (event_params.count(name) != 0) continue;
      if (name == "threshold") {
        l.threshold = param_text(value);
        continue;
      }
      if (name == "input_signal" || name == "input_signals") continue;  // the signals column
      l.parameters.push_back(name + "=" + param_text(value));
    }
    return ff;
  }

  /// An event with where it is written, the filters that generate it and what they target.
  EventLink event_link(EventId id) const {
    const Event& e = co().structure().event(id);
    EventLink l;
    l.name = e.name;
    l.onset = e.is_onset;
    l.severity = e.severity;
    l.transitions = transitions_text(e.transitions);
    l.level = e.is_onset ? std::string(to_string(onset_level(e.transitions, State::Normal))) : "Normal";
    l.latched = e.latched;
    if (e.is_onset && e.counterpart != kNoEvent) l.completion = co().structure().event(e.counterpart).name;
    if (const auto src = event_source_.find(e.name); src != event_source_.end()) {
      l.component = src->second.first;
      l.where = src->second.second;
    }
    for (const FilterFacts& f : filters_) {
      if ((e.is_onset ? f.onset : f.completion) != id) continue;
      FilterLink fl = f.link;
      fl.role = e.is_onset ? "onset" : "completion";
      l.filters.push_back(std::move(fl));
      if (std::find(l.targets.begin(), l.targets.end(), f.link.target) == l.targets.end())
        l.targets.push_back(f.link.target);
    }
    if (l.filters.empty() && !l.component.empty())
      l.targets.push_back(l.component + ".s_A (generated by " + l.component + ")");
    if (e.is_broadcast()) l.targets.push_back("every s_A (broadcast)");
    return l;
  }

  // ---- the scenarios --------------------------------------------------------------------------
  [[nodiscard]] Diagnostics run_scenarios() {
    Diagnostics errors;
    for (const std::string& path : options_.scenarios) {
      auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{path, options_.system}, registry_);
      if (!opened) {
        for (spec::Diagnostic& d : opened.error()) errors.push_back(std::move(d));
        continue;
      }
      run_scenario(path, **opened);
    }
    return errors;
  }

  /// Runs one scenario, keeping what its records show (first onsets, completions, resets).
  void run_scenario(const std::string& path, runner::ScenarioRunner& runner) {
    Coordinator& rc = runner.coordinator();
    RunFacts run;
    ScenarioResult sr;
    sr.path = path;
    const bool keep_history = options_.histories;
    const auto id = rc.subscribe([&](const Record& r) {
      if (keep_history) sr.history.push_back(introspect::history_entry(r, rc));
      if (r.kind == RecordKind::Event && r.outcome != Outcome::Ignored && r.event != kNoEvent &&
          to_index(r.event) >= framework_event::kCount) {
        const Event& e = rc.structure().event(r.event);
        if (e.is_onset) {
          run.first_onset.emplace(r.event, r.time);
          if (!r.mirror && r.machine != kNoMachine) run.onset_machines[r.event].insert(r.machine);
          if (r.machine != kNoMachine)
            run.onset_components[r.event].insert(
                std::string(rc.structure().component_name(rc.structure().machine_component(r.machine))));
        } else if (e.counterpart != kNoEvent) {
          run.completions[e.counterpart].push_back(r.time);
        }
      }
      if (r.kind == RecordKind::Reset) {
        if (r.machine != kNoMachine)
          run.machine_resets.emplace_back(r.time, r.machine);
        else if (r.component != kNoComponent)
          run.component_resets.emplace_back(r.time, r.component);
      }
    });
    runner::RunOptions ro;
    ro.quiet = true;
    run.result = runner.run(ro);
    rc.unsubscribe(id);
    run.duration = runner.scenario().duration;
    sr.passed = run.result.passed();
    sr.checks = run.result.checks;
    sr.failures = run.result.failures;
    sr.duration = run.duration;
    trace_.scenarios.push_back(std::move(sr));
    runs_.push_back(std::move(run));
  }

  /// The scenarios in which onset `id` fired and was then cleared (completed or reset).
  std::vector<std::string> clearing_runs(EventId id) const {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < runs_.size(); ++k) {
      const auto first = runs_[k].first_onset.find(id);
      if (first != runs_[k].first_onset.end() && cleared_at(runs_[k], co(), id, first->second))
        out.push_back(trace_.scenarios[k].path);
    }
    return out;
  }

  /// Trace::onsets: every onset a component declares, in the system's order, then the framework
  /// onsets some filter generates, each with its filters and scenarios.
  void collect_onsets() {
    std::vector<EventId> ids;
    for (const std::string& name : event_order_) {
      auto id = co().structure().find_event(name);
      if (id && co().structure().event(*id).is_onset) ids.push_back(*id);
    }
    for (const FilterFacts& f : filters_) {
      if (f.onset != kNoEvent && to_index(f.onset) < framework_event::kCount &&
          std::find(ids.begin(), ids.end(), f.onset) == ids.end())
        ids.push_back(f.onset);
    }
    for (const FilterFacts& f : filters_) trace_.filters.push_back(f.link);
    for (EventId id : ids) {
      EventLink l = event_link(id);
      l.fired_by = uses_of(l.name);
      l.cleared_by = clearing_runs(id);
      trace_.onsets.push_back(std::move(l));
    }
  }

  /// The scenarios that fired event `name`, with the transitions it took in each. Event ids agree
  /// between the trace's system and every run's: the same spec, built the same way.
  std::vector<ScenarioUse> uses_of(const std::string& name) const {
    std::vector<ScenarioUse> out;
    for (std::size_t k = 0; k < runs_.size(); ++k) {
      if (runs_[k].result.coverage.events_fired.count(name) == 0) continue;
      ScenarioUse u{trace_.scenarios[k].path, {}};
      for (Transition t : kTransitionOrder) {
        if (runs_[k].result.coverage.taken.count({name, std::string(to_string(t))}) != 0)
          u.transitions.emplace_back(to_string(t));
      }
      out.push_back(std::move(u));
    }
    return out;
  }

  void gap(Severity s, std::string kind, std::string hazard, std::string subject, std::string message,
           spec::Position where) {
    gaps_.push_back(
        Gap{s, std::move(kind), std::move(hazard), std::move(subject), std::move(message), std::move(where)});
  }

  // ---- the hazards ----------------------------------------------------------------------------
  HazardTrace trace_hazard(const spec::HazardSpec& h) {
    HazardTrace ht;
    ht.id = h.id;
    ht.description = h.description;
    ht.where = h.where;
    const std::vector<EventId> onsets = hazard_events(h, ht);
    // The reaction, and which scenarios check it after a linked onset fired.
    std::vector<std::optional<Time>> first_linked(runs_.size());
    for (std::size_t k = 0; k < runs_.size(); ++k) {
      for (EventId e : onsets) {
        const auto it = runs_[k].first_onset.find(e);
        if (it != runs_[k].first_onset.end() && (!first_linked[k] || it->second < *first_linked[k]))
          first_linked[k] = it->second;
      }
    }
    hazard_reaction(h, first_linked, ht);
    hazard_excerpt(onsets, first_linked, ht);
    const auto it = verdicts_.find(h.id);
    if (it != verdicts_.end()) {
      ht.verified = it->second;
      ht.verify_detail = "hazard " + h.id + " in " + options_.verify_json;
    } else {
      ht.verify_detail = options_.verify_json.empty() ? "no verify result given: --verify FILE"
                                                      : "no result for " + h.id + " in " + options_.verify_json;
    }
    hazard_gaps(h, ht);
    return ht;
  }

  /// The onsets linked to hazard `h` (in the system's order) and their completions, into
  /// `ht.events`, with the scenarios that fired and cleared them. Returns the onsets.
  std::vector<EventId> hazard_events(const spec::HazardSpec& h, HazardTrace& ht) {
    std::vector<EventId> onsets;
    for (const std::string& name : event_order_) {
      auto id = co().structure().find_event(name);
      if (!id || !co().structure().event(*id).is_onset || co().structure().event(*id).hazard != h.id) continue;
      onsets.push_back(*id);
      linked_onsets_.insert(*id);
      EventLink onset = event_link(*id);
      onset.fired_by = uses_of(onset.name);
      onset.cleared_by = clearing_runs(*id);
      ht.events.push_back(std::move(onset));
      if (co().structure().event(*id).counterpart != kNoEvent) {
        EventLink completion = event_link(co().structure().event(*id).counterpart);
        completion.fired_by = uses_of(completion.name);
        ht.events.push_back(std::move(completion));
      }
    }
    return onsets;
  }

  /// Each reaction of `h`, with the scenarios whose expectations check it at its level after a
  /// linked onset first fired (`first_linked`, per run).
  void hazard_reaction(const spec::HazardSpec& h, const std::vector<std::optional<Time>>& first_linked,
                       HazardTrace& ht) const {
    for (std::size_t r = 0; r < h.reaction.size(); ++r) {
      ReactionLink rl;
      rl.address = h.reaction[r].first;
      rl.level = std::string(to_string(h.reaction[r].second));
      rl.where = r < h.reaction_where.size() ? h.reaction_where[r] : h.where;
      for (std::size_t k = 0; k < runs_.size(); ++k) {
        if (!first_linked[k]) continue;
        const bool checked =
            std::any_of(runs_[k].result.coverage.states_checked.begin(), runs_[k].result.coverage.states_checked.end(),
                        [&](const runner::StateCheck& c) {
                          return c.held && c.address == rl.address && c.expected >= h.reaction[r].second &&
                                 c.at >= *first_linked[k];
                        });
        if (checked) rl.checked_by.push_back(trace_.scenarios[k].path);
      }
      ht.reaction.push_back(std::move(rl));
    }
  }

  /// The timeline excerpt of the hazard: the run whose expectations check most of its reaction,
  /// from a linked onset's first firing to its clearing, over the components involved.
  void hazard_excerpt(const std::vector<EventId>& onsets, const std::vector<std::optional<Time>>& first_linked,
                      HazardTrace& ht) const {
    std::size_t best_checks = 0;
    std::optional<std::size_t> chosen;
    for (std::size_t k = 0; k < runs_.size(); ++k) {
      if (!first_linked[k]) continue;
      std::size_t checks = 0;
      for (const ReactionLink& rl : ht.reaction) {
        checks += std::count(rl.checked_by.begin(), rl.checked_by.end(), trace_.scenarios[k].path) != 0 ? 1 : 0;
      }
      if (!chosen || checks > best_checks) {
        chosen = k;
        best_checks = checks;
      }
    }
    if (!chosen) return;
    const RunFacts& run = runs_[*chosen];
    ht.excerpt_scenario = trace_.scenarios[*chosen].path;
    const Time from = *first_linked[*chosen];
    Time to = seconds_to_time(run.duration);
    std::set<std::string> components;
    for (EventId e : onsets) {
      const auto it = run.first_onset.find(e);
      if (it == run.first_onset.end() || it->second != from) continue;
      if (auto c = cleared_at(run, co(), e, from)) to = *c;
    }
    for (EventId e : onsets) {
      if (const auto it = run.onset_components.find(e); it != run.onset_components.end()) {
        components.insert(it->second.begin(), it->second.end());
      }
    }
    for (const ReactionLink& rl : ht.reaction) {
      if (rl.address != "SYSTEM") components.insert(component_of(rl.address));
    }
    const double span = std::max(to_seconds(to - from), 0.01);
    ht.excerpt_from = std::max(0.0, to_seconds(from) - span * 0.25);
    ht.excerpt_to = std::min(run.duration, to_seconds(to) + span * 0.25);
    // Keep the system's order of components.
    for (const spec::ComponentSpec& c : sys().components) {
      if (components.count(c.name) != 0) ht.excerpt_components.push_back(c.name);
    }
  }

  /// The gaps of one hazard: undetected, reaction violated, events not fired or not cleared,
  /// reactions unchecked.
  void hazard_gaps(const spec::HazardSpec& h, const HazardTrace& ht) {
    const bool detected = std::any_of(ht.events.begin(), ht.events.end(),
                                      [](const EventLink& e) { return e.onset && !e.filters.empty(); });
    if (ht.events.empty()) {
      gap(Severity::Error, "hazard-undetected", h.id, h.id,
          "hazard " + h.id + " has no detecting filter: no event names it (add \"hazard\": \"" + h.id +
              "\" to the onset that detects it)",
          h.where);
    } else if (!detected) {
      gap(Severity::Error, "hazard-undetected", h.id, h.id,
          "hazard " + h.id + " has no detecting filter: no filter generates any of its onsets (" +
              ht.events.front().name + (ht.events.size() > 2 ? ", …" : "") +
              "); only the components' code could raise them",
          h.where);
    }
    if (ht.verified == Verdict::Violated) {
      gap(Severity::Error, "reaction-violated", h.id, h.id,
          "`safecass verify` found the reaction of " + h.id + " violated (" + options_.verify_json + ")", h.where);
    }
    for (const EventLink& e : ht.events) {
      const bool latched_completion =
          !e.onset && std::any_of(ht.events.begin(), ht.events.end(),
                                  [&](const EventLink& o) { return o.onset && o.latched && o.completion == e.name; });
      if (e.fired_by.empty() && !latched_completion) {
        gap(Severity::Warning, "event-not-fired", h.id, e.name,
            std::string(e.onset ? "onset " : "completion ") + e.name + " of " + h.id + " is fired by no scenario",
            e.where);
      }
      if (e.onset && !e.fired_by.empty() && e.cleared_by.empty()) {
        gap(Severity::Warning, "onset-not-cleared", h.id, e.name,
            "onset " + e.name + " of " + h.id + " is " + (e.latched ? "reset" : "completed or reset") +
                " by no scenario after it fired",
            e.where);
      }
    }
    for (const ReactionLink& rl : ht.reaction) {
      if (rl.checked_by.empty()) {
        gap(Severity::Warning, "reaction-unchecked", h.id, rl.address,
            "reaction " + rl.address + " >= " + rl.level + " of " + h.id +
                " is checked by no scenario (an `expect` of it at that level after a linked onset fired)",
            rl.where);
      }
    }
  }

  /// Filters that generate an onset no hazard claims, and scenarios that fail.
  void unclaimed_filters_and_failed_scenarios() {
    for (const FilterFacts& f : filters_) {
      if (f.onset == kNoEvent || linked_onsets_.count(f.onset) != 0) continue;
      const Event& e = co().structure().event(f.onset);
      if (to_index(e.id) < framework_event::kCount) continue;
      gap(Severity::Info, "filter-without-hazard", "", f.link.name,
          "filter " + f.link.name + " generates " + e.name + ", which is linked to no declared hazard", f.link.where);
      if (std::none_of(trace_.unlinked.begin(), trace_.unlinked.end(),
                       [&](const EventLink& l) { return l.name == e.name; })) {
        EventLink l = event_link(f.onset);
        l.fired_by = uses_of(l.name);
        trace_.unlinked.push_back(std::move(l));
      }
    }
    for (const ScenarioResult& s : trace_.scenarios) {
      if (s.passed) continue;
      gap(Severity::Error, "scenario-failed", "", s.path,
          "scenario " + s.path + " fails (" + std::to_string(s.failures.size()) + " expectation" +
              (s.failures.size() == 1 ? "" : "s") +
              "): its evidence does not count until it passes; first: " + s.failures.front(),
          spec::Position{s.path, 0, 0});
    }
  }

  // ---- the coverage summary -------------------------------------------------------------------
  void summarize_coverage() {
    Coverage& cv = trace_.coverage;
    std::set<std::string> fired;
    std::set<std::pair<std::string, std::string>> taken;
    for (const RunFacts& r : runs_) {
      fired.insert(r.result.coverage.events_fired.begin(), r.result.coverage.events_fired.end());
      taken.insert(r.result.coverage.taken.begin(), r.result.coverage.taken.end());
    }
    for (EventId e : id_range(EventId{framework_event::kCount}, co().structure().event_count())) {
      const Event& ev = co().structure().event(e);
      ++cv.events_defined;
      cv.events_fired += fired.count(ev.name) != 0 ? 1 : 0;
      for (Transition t : kTransitionOrder) {
        if (!ev.transitions.contains(t)) continue;
        ++cv.transitions_defined;
        cv.transitions_taken += taken.count({ev.name, std::string(to_string(t))}) != 0 ? 1 : 0;
      }
    }
    for (const HazardTrace& h : trace_.hazards) {
      ++cv.hazards;
      const bool detected = std::any_of(h.events.begin(), h.events.end(),
                                        [](const EventLink& e) { return e.onset && !e.filters.empty(); });
      const bool exercised = std::any_of(h.events.begin(), h.events.end(),
                                         [](const EventLink& e) { return e.onset && !e.fired_by.empty(); });
      cv.hazards_detected += detected ? 1 : 0;
      cv.hazards_exercised += exercised ? 1 : 0;
      for (const ReactionLink& r : h.reaction) {
        ++cv.reactions;
        cv.reactions_checked += r.checked_by.empty() ? 0 : 1;
      }
    }
  }

  const TraceOptions& options_;
  const FilterRegistry& registry_;
  Trace trace_;
  spec::LoadResult loaded_;
  std::map<std::string, Verdict> verdicts_;
  std::unique_ptr<native::System> system_;
  std::map<std::string, StageSource, std::less<>> stage_source_;
  std::map<std::string, std::pair<std::string, spec::Position>, std::less<>>
      event_source_;  ///< name → component, where
  std::vector<std::string> event_order_;
  std::vector<FilterFacts> filters_;
  std::vector<RunFacts> runs_;
  std::vector<Gap> gaps_;
  std::set<EventId> linked_onsets_;  ///< onsets some hazard claims
};

}  // namespace

[[nodiscard]] tl::expected<Trace, std::vector<spec::Diagnostic>> build_trace(const TraceOptions& options,
                                                                             const FilterRegistry& registry) {
  return Builder(options, registry).build();
}

}  // namespace safecass::trace
