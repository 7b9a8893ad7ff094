// `safecass analyze` (docs/analyze.md): the trace, the failure modes with their effects, the
// fault trees through SCRAM, and the GSN safety case.

#include <algorithm>

#include "fault_tree.hpp"
#include "modes.hpp"
#include "safecass/core/text.hpp"

namespace safecass::analyze {

std::string_view to_string(ModeKind kind) noexcept {
  switch (kind) {
    case ModeKind::Onset: return "onset";
    case ModeKind::MachineError: return "machine-error";
    case ModeKind::StaleSignal: return "stale-signal";
    case ModeKind::MonitoringFault: return "monitoring-fault";
    case ModeKind::CoordinatorLost: return "coordinator-lost";
    case ModeKind::SupervisorLost: break;
  }
  return "supervisor-lost";
}

bool Analysis::has_error_gap() const noexcept { return gap_count(trace::Severity::Error) != 0; }

std::size_t Analysis::gap_count(trace::Severity severity) const noexcept {
  std::size_t n = 0;
  for (const FailureMode& m : modes) {
    n += static_cast<std::size_t>(
        std::count_if(m.gaps.begin(), m.gaps.end(), [&](const Gap& g) { return g.severity == severity; }));
  }
  return n;
}

[[nodiscard]] Expected<TopRequest> parse_top(std::string_view text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0)
    return fail(ErrorCode::InvalidArgument, "'" + std::string(text) + "' is not ADDRESS=LEVEL (e.g. SERVO=Error)");
  const std::string_view level = text.substr(eq + 1);
  TopRequest t;
  t.address = std::string(text.substr(0, eq));
  if (level == "Error") {
    t.level = State::Error;
  } else if (level == "Warning") {
    t.level = State::Warning;
  } else {
    return fail(ErrorCode::InvalidArgument,
                "'" + std::string(text) + "': the level must be Warning or Error, not '" + std::string(level) + "'");
  }
  return t;
}

namespace {

spec::Diagnostic error_at(const std::string& file, std::string message) {
  return spec::Diagnostic{spec::Diagnostic::Severity::Error, spec::Position{file, 0, 0}, std::move(message), {}};
}

/// The top events: each hazard's reaction addresses at their levels (one top per address and
/// level, naming every hazard that requires it), then the ones asked for.
[[nodiscard]] spec::Opened<std::vector<TopEvent>> top_events(const spec::SystemSpec& sys, const AnalyzeOptions& options,
                                                             const Engine& engine) {
  std::vector<TopEvent> tops;
  auto add = [&](const std::string& address, State level, const std::string& why) {
    for (TopEvent& t : tops) {
      if (t.address == address && t.level == level) {
        t.why += ", " + why;
        return;
      }
    }
    TopEvent t;
    t.address = address;
    t.level = level;
    t.why = why;
    tops.push_back(std::move(t));
  };
  for (const spec::HazardSpec& h : sys.hazards) {
    for (const auto& [address, level] : h.reaction) add(address, level, h.id + "'s reaction");
  }
  spec::Diagnostics errors;
  for (const TopRequest& r : options.tops) {
    if (auto a = engine.resolve(r.address); !a)
      errors.push_back(
          error_at("--top", "'" + r.address + "' is not an address of " + sys.name + ": " + a.error().message));
    else
      add(r.address, r.level, "--top");
  }
  if (!errors.empty()) return tl::unexpected(std::move(errors));
  return tops;
}

// ---- the safety case (GSN) ------------------------------------------------------------------------

class CaseBuilder {
public:
  explicit CaseBuilder(const Analysis& a) : a_(a) {}

  SafetyCase build() {
    const std::string system = a_.trace.system;
    GsnNode& top = node("G1", "goal", "The hazards of " + system + " are acceptably mitigated");
    top.context.push_back(
        node("C1", "context", "The hazards of " + system + "'s hazard analysis (" + a_.trace.system_path + ")").id);
    top.context.push_back(node("C2", "context",
                               "The specification " + a_.trace.system_path + " as the robot runs it, with " +
                                   std::to_string(a_.modes.size()) + " failure modes (the FMEA)")
                              .id);
    const std::string strategy = node("S1", "strategy", "Argument over each hazard").id;
    nodes_[0].parts.push_back(strategy);
    std::vector<std::string> parts;
    for (std::size_t k = 0; k < a_.trace.hazards.size(); ++k) parts.push_back(hazard(a_.trace.hazards[k], k + 1));
    if (parts.empty()) parts.push_back(undeveloped("G0", "The system declares its hazards").id);
    find("S1").parts = parts;
    return SafetyCase{std::move(nodes_)};
  }

private:
  GsnNode& node(std::string id, std::string type, std::string text) {
    nodes_.push_back(GsnNode{std::move(id), std::move(type), std::move(text), false, {}, {}});
    return nodes_.back();
  }
  GsnNode& undeveloped(std::string id, std::string text) {
    GsnNode& n = node(std::move(id), "goal", std::move(text));
    n.undeveloped = true;
    return n;
  }
  GsnNode& find(const std::string& id) {
    return *std::find_if(nodes_.begin(), nodes_.end(), [&](const GsnNode& n) { return n.id == id; });
  }

  /// G<k>: the hazard is mitigated, by S<k>: detection, reaction and test.
  std::string hazard(const trace::HazardTrace& h, std::size_t k) {
    const std::string n = std::to_string(k);
    std::string goal = "G1." + n;
    node(goal, "goal", h.id + " (" + h.description + ") is mitigated");
    node("S1." + n, "strategy", "Argument over the detection, the reaction and the tests of " + h.id);
    find(goal).parts.push_back("S1." + n);
    std::vector<std::string> sub{detection(h, n), reaction(h, n), tests(h, n)};
    find("S1." + n).parts = sub;
    return goal;
  }

  std::string detection(const trace::HazardTrace& h, const std::string& n) {
    std::string id = "G1." + n + ".1";
    std::vector<std::string> solutions;
    int s = 0;
    for (const trace::EventLink& e : h.events) {
      for (const trace::FilterLink& f : e.filters) {
        if (!e.onset) continue;
        solutions.push_back(
            node("Sn" + n + ".1." + std::to_string(++s), "solution",
                 "Filter " + f.name + " (" + f.type + " on " + f.signals + ") raises " + e.name + " at " + f.target)
                .id);
      }
    }
    GsnNode& g = node(id, "goal", h.id + " is detected by the monitoring");
    g.undeveloped = solutions.empty();
    g.parts = solutions;
    return id;
  }

  std::string reaction(const trace::HazardTrace& h, const std::string& n) {
    std::string id = "G1." + n + ".2";
    std::string required;
    for (const trace::ReactionLink& r : h.reaction)
      required += (required.empty() ? "" : ", ") + r.address + " at " + r.level;
    std::vector<std::string> solutions;
    bool missed = false;
    for (const FailureMode& m : a_.modes) {
      for (const HazardLink& l : m.hazards)
        missed = missed || (l.id == h.id && l.role == "detected" && !l.missed.empty());
    }
    if (!missed && !required.empty())
      solutions.push_back(
          node("Sn" + n + ".2.1", "solution",
               "FMEA: every onset of " + h.id + " alone reaches " + required + " (the engine's propagation)")
              .id);
    if (h.verified == trace::Verdict::Holds)
      solutions.push_back(node("Sn" + n + ".2.2", "solution",
                               "safecass verify: the reaction holds for every reachable combination of faults")
                              .id);
    GsnNode& g =
        node(id, "goal",
             required.empty() ? h.id + " requires a reaction" : "Whenever " + h.id + " is detected, " + required);
    // Not proved by verify, or missed by the engine: the goal is not yet supported.
    g.undeveloped = missed || required.empty() || h.verified != trace::Verdict::Holds;
    g.parts = solutions;
    return id;
  }

  std::string tests(const trace::HazardTrace& h, const std::string& n) {
    std::string id = "G1." + n + ".3";
    std::vector<std::string> solutions;
    std::vector<std::string> seen;
    bool failed = false;
    for (const trace::EventLink& e : h.events) {
      if (!e.onset) continue;
      for (const trace::ScenarioUse& u : e.fired_by) {
        if (std::find(seen.begin(), seen.end(), u.scenario) != seen.end()) continue;
        seen.push_back(u.scenario);
        bool passed = false;
        for (const trace::ScenarioResult& r : a_.trace.scenarios) passed = passed || (r.path == u.scenario && r.passed);
        failed = failed || !passed;
        solutions.push_back(node("Sn" + n + ".3." + std::to_string(seen.size()), "solution",
                                 "Scenario " + u.scenario + " (" + (passed ? "passes" : "FAILS") + ")")
                                .id);
      }
    }
    GsnNode& g = node(id, "goal", "The detection and the reaction of " + h.id + " are tested");
    g.undeveloped = solutions.empty() || failed;
    g.parts = solutions;
    return id;
  }

  const Analysis& a_;
  std::vector<GsnNode> nodes_;
};

}  // namespace

SafetyCase safety_case(const Analysis& a) { return CaseBuilder(a).build(); }

[[nodiscard]] spec::Opened<bool> apply_reliability(const spec::ReliabilitySpec& reliability,
                                                   std::vector<FailureMode>& modes) {
  const auto by_event = [](const FailureMode& m, const std::string& name) {
    return m.kind == ModeKind::Onset && m.event == name;
  };
  spec::Diagnostics errors;
  for (const spec::ReliabilitySpec::Mode& r : reliability.modes) {
    const bool known = std::any_of(modes.begin(), modes.end(),
                                   [&](const FailureMode& m) { return m.name == r.name || by_event(m, r.name); });
    if (!known)
      errors.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error,
                                        r.where,
                                        "reliability: '" + r.name +
                                            "' is no failure mode of the analysis (an event raised nowhere there, or a "
                                            "signal no Watchdog watches): safecass analyze --fmea lists them",
                                        {}});
  }
  if (!errors.empty()) return tl::unexpected(std::move(errors));
  // Entries naming an event alone first, so that an entry naming one of its modes wins.
  for (const bool general : {true, false}) {
    for (const spec::ReliabilitySpec::Mode& r : reliability.modes) {
      for (FailureMode& m : modes) {
        if (general ? by_event(m, r.name) : m.name == r.name) {
          m.rate = r.rate;
          m.probability = r.probability;
        }
      }
    }
  }
  return true;
}

[[nodiscard]] tl::expected<Analysis, std::vector<spec::Diagnostic>> build_analysis(const AnalyzeOptions& options,
                                                                                   const FilterRegistry& registry) {
  if (options.order < 1 || options.order > 6)
    return tl::unexpected(
        spec::Diagnostics{error_at("--order", "the order must be 1 to 6, not " + std::to_string(options.order))});
  trace::TraceOptions to;
  to.system = options.system;
  to.scenarios = options.scenarios;
  to.verify_json = options.verify_json;
  auto traced = trace::build_trace(to, registry);
  if (!traced) return tl::unexpected(std::move(traced.error()));
  Analysis a;
  a.trace = std::move(*traced);
  auto instance = spec::open_instance(options.system, registry);
  if (!instance) return tl::unexpected(std::move(instance.error()));
  Engine engine(std::move(*instance));
  const spec::SystemSpec& sys = engine.spec();
  auto modes = failure_modes(sys, a.trace, engine);
  if (!modes) return tl::unexpected(spec::Diagnostics{error_at(options.system, modes.error().message)});
  a.modes = std::move(modes->modes);
  auto tops = top_events(sys, options, engine);
  if (!tops) return tl::unexpected(std::move(tops.error()));
  if (sys.reliability) {
    if (auto applied = apply_reliability(*sys.reliability, a.modes); !applied)
      return tl::unexpected(std::move(applied.error()));
  }
  a.trees = fault_trees(a.modes, modes->raises, std::move(*tops), options.order, sys.reliability);
  if (options.fault_trees) {
    if (auto ran = run_scram(sys.name, a.modes, a.trees, options.scram, options.work_dir); !ran)
      return tl::unexpected(spec::Diagnostics{error_at(options.system, ran.error().message)});
  } else {
    a.trees.mef = mef_document(sys.name, a.modes, a.trees);
  }
  a.safety_case = safety_case(a);
  return a;
}

}  // namespace safecass::analyze
