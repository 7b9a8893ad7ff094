// `safecass analyze` (tools/analyze, docs/analyze.md): the failure modes and their effects by the
// engine's propagation, the gaps, the fault trees whose cut sets SCRAM computes (checked against
// the engine on every example and test system), and the GSN safety case.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "fault_tree.hpp"
#include "modes.hpp"
#include "safecass/analyze/analyze.hpp"
#include "safecass/filters/registry.hpp"

namespace safecass::analyze {
namespace {

using ::testing::HasSubstr;

/// Every example and test system that loads: the cut sets are checked against the engine on each.
const char* const kSystems[] = {
    "examples/robodoc/robodoc.json",
    "examples/force_sensor/force_sensor.json",
    "examples/consumer/gripper.json",
    "tests/data/trace/arm.json",
    "tests/data/trace/undetected.json",
    "tests/data/verify/broadcast.json",
    "tests/data/verify/broadcast.fixed.json",
    "tests/data/verify/findings.json",
    "tests/data/verify/invariant.json",
    "tests/data/verify/level_rule.json",
    "tests/data/verify/level_rule.fixed.json",
    "tests/data/verify/missing_dependency.json",
    "tests/data/verify/missing_dependency.fixed.json",
    "tests/data/verify/propagation_level.json",
    "tests/data/verify/propagation_level.fixed.json",
    "tests/data/good_specs/robodoc.json",
    "tests/data/good_specs/original_2016/system.json",
    "tests/data/good_specs/legacy_2016/system.json",
    "tests/data/analyze/escalation.json",
    "tests/data/analyze/rates.json",
};

class Analyze : public ::testing::Test {
protected:
  Analyze() { register_builtin_filters(registry_); }

  Analysis analyze(const std::string& system, std::vector<std::string> scenarios = {},
                   std::vector<TopRequest> tops = {}, const std::string& verify = {}) {
    AnalyzeOptions o;
    o.system = system;
    o.scenarios = std::move(scenarios);
    o.tops = std::move(tops);
    o.verify_json = verify;
    auto a = build_analysis(o, registry_);
    if (!a) {
      std::string text;
      for (const auto& d : a.error()) text += spec::format(d) + "\n";
      ADD_FAILURE() << system << ":\n" << text;
      return {};
    }
    return std::move(*a);
  }

  static const FailureMode& mode(const Analysis& a, const std::string& name) {
    const auto it = std::find_if(a.modes.begin(), a.modes.end(), [&](const FailureMode& m) { return m.name == name; });
    if (it == a.modes.end()) throw std::runtime_error("no failure mode " + name);
    return *it;
  }

  static bool has_gap(const FailureMode& m, const std::string& kind, trace::Severity s) {
    return std::any_of(m.gaps.begin(), m.gaps.end(), [&](const Gap& g) { return g.kind == kind && g.severity == s; });
  }

  FilterRegistry registry_;
};

// ---- the FMEA -------------------------------------------------------------------------------------

TEST_F(Analyze, AnOnsetsSystemEffectIsEveryAddressTheEnginesPropagationReaches) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& force = mode(a, "EVT_FORCE_ERROR@JR3.s_A");
  EXPECT_EQ(force.local_effect, "JR3.s_A at Error");
  EXPECT_EQ(level_at(force.effects, "CONTROL.s_R.ForceData"), State::Error);
  EXPECT_EQ(level_at(force.effects, "SERVO"), State::Error);
  EXPECT_EQ(level_at(force.effects, "PENDANT.s_R.Status"), State::Error);
  EXPECT_EQ(level_at(force.effects, "BMM"), State::Normal);
  // A warning crosses only a service that propagates warnings: CONTROL's Status does, Command not.
  const FailureMode& tracking = mode(a, "EVT_TRACKING_ERROR@CONTROL.s_A");
  EXPECT_EQ(level_at(tracking.effects, "PENDANT.s_R.Status"), State::Warning);
  EXPECT_EQ(level_at(tracking.effects, "SERVO"), State::Normal);
  EXPECT_EQ(level_at(tracking.effects, "SYSTEM"), State::Warning);
}

TEST_F(Analyze, EveryFrameworkAndApplicationMachineHasAnErrorModeEvenWhereNoEventNamesIt) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  for (const char* c : {"JR3", "BMM", "CONTROL", "SERVO", "PENDANT"}) {
    for (const char* machine : {".s_F", ".s_A"}) {
      const FailureMode& m = mode(a, std::string(c) + machine);
      EXPECT_EQ(m.kind, ModeKind::MachineError);
      EXPECT_EQ(level_at(m.effects, std::string(c) + machine), State::Error);
    }
  }
  // PENDANT's application has no detecting filter: an undetected mode, shown as one.
  EXPECT_EQ(mode(a, "PENDANT.s_A").detection, "none");
  EXPECT_TRUE(has_gap(mode(a, "PENDANT.s_A"), "no-detection", trace::Severity::Info));
  EXPECT_FALSE(has_gap(mode(a, "PENDANT.s_F"), "no-detection", trace::Severity::Info));
}

TEST_F(Analyze, AnOnsetLinkedToAHazardThatNoFilterRaisesIsUndetected) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& freeze = mode(a, "EVT_CONTROL_FORCE_FREEZE@CONTROL.s_A");
  EXPECT_THAT(freeze.detection, HasSubstr("none"));
  EXPECT_TRUE(has_gap(freeze, "no-detection", trace::Severity::Warning));
  EXPECT_FALSE(has_gap(mode(a, "EVT_FORCE_ERROR@JR3.s_A"), "no-detection", trace::Severity::Warning));
}

TEST_F(Analyze, AnOnsetThatReachesOnlyWarningAloneMissesAnErrorReactionAndIsAnErrorGap) {
  const Analysis a = analyze("tests/data/verify/level_rule.json");
  const FailureMode& force = mode(a, "EVT_FORCE@ARM.s_A");
  EXPECT_TRUE(force.escalates);
  EXPECT_EQ(force.level, State::Warning);
  EXPECT_EQ(level_at(force.escalated, "ARM.s_A"), State::Error);
  ASSERT_EQ(force.hazards.size(), 1U);
  EXPECT_THAT(force.hazards[0].missed, ::testing::ElementsAre("ARM.s_A at Warning, Error required"));
  EXPECT_TRUE(has_gap(force, "reaction-missed", trace::Severity::Error));
  EXPECT_TRUE(a.has_error_gap());
  EXPECT_FALSE(analyze("tests/data/verify/level_rule.fixed.json").has_error_gap());
}

TEST_F(Analyze, ACoordinatorsLossReachesTheInterfacesItFeedsAndBlindsTheHazardsItDetects) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& robot = mode(a, "lost:robot");
  EXPECT_EQ(robot.kind, ModeKind::CoordinatorLost);
  EXPECT_EQ(level_at(robot.effects, "PENDANT.s_R.Status"), State::Error);  // the ui's view
  EXPECT_EQ(level_at(robot.effects, "JR3.s_F"), State::Error);             // the supervisor's view
  std::vector<std::string> blinded;
  for (const HazardLink& l : robot.hazards) {
    if (l.role == "blinds") blinded.push_back(l.id);
  }
  EXPECT_THAT(blinded, ::testing::IsSupersetOf({"H-2", "H-3", "H-4", "H-5", "H-6"}));
  const FailureMode& ui = mode(a, "lost:ui");
  EXPECT_EQ(level_at(ui.effects, "SERVO"), State::Normal);  // nothing the robot needs comes from the ui
}

TEST_F(Analyze, TheSupervisorsLossWarnsEveryComponentsFramework) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& s = mode(a, "lost:supervisor");
  for (const char* c : {"JR3.s_F", "BMM.s_F", "CONTROL.s_F", "SERVO.s_F", "PENDANT.s_F"})
    EXPECT_EQ(level_at(s.effects, c), State::Warning) << c;
  // A one-process system has no coordinator or supervisor to lose.
  const Analysis single = analyze("tests/data/verify/level_rule.json");
  EXPECT_TRUE(std::none_of(single.modes.begin(), single.modes.end(), [](const FailureMode& m) {
    return m.kind == ModeKind::CoordinatorLost || m.kind == ModeKind::SupervisorLost;
  }));
}

TEST_F(Analyze, AStaleWatchedSignalBlindsTheHazardsOfEveryFilterDownstreamOfIt) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& stale = mode(a, "stale:JR3.Force");
  EXPECT_EQ(stale.event, "EVT_FORCE_STALE");
  EXPECT_THAT(stale.detection, HasSubstr("force_stale"));
  // force_limit reads JR3.ForceNorm, which force_norm computes from JR3.Force.
  ASSERT_EQ(stale.hazards.size(), 1U);
  EXPECT_EQ(stale.hazards[0].id, "H-3");
  EXPECT_EQ(stale.hazards[0].role, "blinds");
}

TEST_F(Analyze, AMonitoringFaultRaisesInvalidSampleOnItsComponentsFramework) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const FailureMode& fault = mode(a, "fault:force_limit");
  EXPECT_EQ(fault.event, "EVT_INVALID_SAMPLE");
  EXPECT_EQ(fault.local_effect, "JR3.s_F at Error");
  ASSERT_FALSE(fault.hazards.empty());
  EXPECT_EQ(fault.hazards[0].id, "H-3");
}

TEST_F(Analyze, AScenarioThatRaisesAModeIsItsEvidenceWithItsVerdict) {
  const Analysis a = analyze("tests/data/trace/arm.json",
                             {"tests/data/trace/covered.scenario.json", "tests/data/trace/failing.scenario.json"});
  bool some_evidence = false;
  for (const FailureMode& m : a.modes) {
    for (const Evidence& e : m.tests) {
      some_evidence = true;
      if (e.scenario == "tests/data/trace/failing.scenario.json") {
        EXPECT_FALSE(e.passed);
        EXPECT_TRUE(has_gap(m, "test-failed", trace::Severity::Error));
      }
      if (e.scenario == "tests/data/trace/covered.scenario.json") {
        EXPECT_TRUE(e.passed);
      }
    }
  }
  EXPECT_TRUE(some_evidence);
}

TEST_F(Analyze, AReactionIsProvedOnlyByVerifysHoldsVerdict) {
  const Analysis a = analyze("tests/data/trace/arm.json", {}, {}, "tests/data/trace/verify_holds.jsonl");
  for (const FailureMode& m : a.modes) {
    for (const HazardLink& l : m.hazards) {
      if (l.role == "detected") {
        EXPECT_EQ(l.verified, trace::Verdict::Holds) << m.name;
      }
    }
    EXPECT_FALSE(has_gap(m, "reaction-not-proved", trace::Severity::Warning)) << m.name;
  }
  const Analysis v = analyze("tests/data/trace/arm.json", {}, {}, "tests/data/trace/verify_violated.jsonl");
  EXPECT_TRUE(v.has_error_gap());
}

// ---- the fault trees --------------------------------------------------------------------------------

TEST_F(Analyze, EachHazardsReactionAddressIsATopEventAndTopAddsOne) {
  const Analysis a =
      analyze("examples/robodoc/robodoc.json", {}, {{"SERVO", State::Error}, {"BMM.s_A", State::Warning}});
  std::vector<std::string> tops;
  for (const TopEvent& t : a.trees.tops) tops.push_back(t.address + "=" + std::string(to_string(t.level)));
  // H-3, H-5 and H-6 all ask SERVO at Error: one top, naming the three; --top SERVO=Error joins it.
  EXPECT_THAT(tops, ::testing::ElementsAre("SERVO=Warning", "CONTROL=Error", "SERVO=Error", "CONTROL=Warning",
                                           "PENDANT=Warning", "BMM.s_A=Warning"));
  EXPECT_THAT(a.trees.tops[2].why, HasSubstr("H-3"));
  EXPECT_THAT(a.trees.tops[2].why, HasSubstr("--top"));
  EXPECT_THAT(a.trees.mef, HasSubstr("<define-gate name=\"TOP6\">"));
}

TEST_F(Analyze, AnEscalationIsAnAndOfTheOnsetAndWhatPutsItsMachineAtWarningFirst) {
  const Analysis a = analyze("tests/data/analyze/escalation.json");
  ASSERT_EQ(a.trees.tops.size(), 1U);
  const std::string drift = mode(a, "EVT_DRIFT@SENSOR.s_A").id, conflict = mode(a, "EVT_CONFLICT@ARM.s_R.Data").id;
  const auto& cuts = a.trees.tops[0].cut_sets;
  EXPECT_TRUE(std::any_of(cuts.begin(), cuts.end(), [&](const CutSet& c) {
    return c.modes == std::vector<std::string>{drift, conflict};
  }));
  EXPECT_TRUE(std::none_of(cuts.begin(), cuts.end(), [&](const CutSet& c) {
    return c.modes == std::vector<std::string>{drift} || c.modes == std::vector<std::string>{conflict};
  }));
  EXPECT_THAT(a.trees.mef, HasSubstr("<and><basic-event name=\"" + conflict + "\"/><gate name=\"PRE_" + conflict));
}

/// Whether raising `ids` in some order puts `top` at `level` or worse (the engine, reset after).
bool reaches(Engine& engine, const ModeSet& set, std::vector<std::size_t> ids, const Address& top, State level) {
  std::sort(ids.begin(), ids.end());
  do {
    for (std::size_t k : ids) EXPECT_TRUE(engine.raise_and_hold(set.raises[k]).has_value());
    const bool hit = engine.state(top) >= level;
    engine.reset();
    if (hit) return true;
  } while (std::next_permutation(ids.begin(), ids.end()));
  return false;
}

TEST_F(Analyze, ScramsMinimalCutSetsAreWhatTheEngineDoesOnEverySystem) {
  for (const char* system : kSystems) {
    SCOPED_TRACE(system);
    const Analysis a = analyze(system);
    // The same modes, in the same order, with what each raises.
    trace::TraceOptions to;
    to.system = system;
    auto traced = trace::build_trace(to, registry_);
    ASSERT_TRUE(traced.has_value());
    auto instance = spec::open_instance(system, registry_);
    ASSERT_TRUE(instance.has_value());
    Engine engine(std::move(*instance));
    auto set = failure_modes(engine.spec(), *traced, engine);
    ASSERT_TRUE(set.has_value());
    ASSERT_EQ(set->modes.size(), a.modes.size());
    std::map<std::string, std::size_t> index;
    for (std::size_t k = 0; k < set->modes.size(); ++k) index[set->modes[k].id] = k;
    for (const TopEvent& t : a.trees.tops) {
      SCOPED_TRACE(t.address);
      auto top = engine.resolve(t.address);
      ASSERT_TRUE(top.has_value());
      // Each cut set reaches the top together, and without any one of its modes does not.
      for (const CutSet& c : t.cut_sets) {
        std::vector<std::size_t> ids;
        for (const std::string& id : c.modes) ids.push_back(index.at(id));
        EXPECT_TRUE(reaches(engine, *set, ids, *top, t.level)) << ::testing::PrintToString(c.modes);
        for (std::size_t drop = 0; drop < ids.size(); ++drop) {
          std::vector<std::size_t> rest = ids;
          rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(drop));
          EXPECT_FALSE(reaches(engine, *set, rest, *top, t.level)) << ::testing::PrintToString(c.modes);
        }
      }
      // And nothing is missing: every pair of modes that reaches the top contains a cut set.
      const auto covered = [&](std::vector<std::string> modes) {
        return std::any_of(t.cut_sets.begin(), t.cut_sets.end(), [&](const CutSet& c) {
          return std::all_of(c.modes.begin(), c.modes.end(), [&](const std::string& id) {
            return std::find(modes.begin(), modes.end(), id) != modes.end();
          });
        });
      };
      for (std::size_t i = 0; i < set->modes.size(); ++i) {
        for (std::size_t j = i; j < set->modes.size(); ++j) {
          if (!reaches(engine, *set, i == j ? std::vector<std::size_t>{i} : std::vector<std::size_t>{i, j}, *top,
                       t.level))
            continue;
          EXPECT_TRUE(covered({set->modes[i].id, set->modes[j].id}))
              << set->modes[i].name << " + " << set->modes[j].name << " reach it; no cut set says so";
        }
      }
    }
  }
}

TEST_F(Analyze, AReliabilitySectionGivesScramsTopEventProbabilityAndImportances) {
  const Analysis a = analyze("tests/data/analyze/rates.json");
  EXPECT_EQ(a.trees.unquantified, "");
  EXPECT_DOUBLE_EQ(a.trees.mission_time, 1000.0);
  ASSERT_EQ(a.trees.tops.size(), 1U);
  const TopEvent& t = a.trees.tops[0];
  ASSERT_TRUE(t.probability.has_value());
  // Worked by hand in the file's comment: the BDD's answer is exact.
  EXPECT_NEAR(*t.probability, 0.0110540, 1e-7);
  EXPECT_EQ(t.importance.size(), 9U);
  for (const CutSet& c : t.cut_sets) EXPECT_TRUE(c.probability.has_value());
  EXPECT_THAT(a.trees.mef, HasSubstr("<exponential><float value=\"1.0005e-06\"/><system-mission-time/>"));
}

TEST_F(Analyze, AnEntryNamingAnEventAppliesToEachOfItsModesAndAnEntryNamingOneModeWins) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  std::vector<FailureMode> modes = a.modes;
  spec::ReliabilitySpec r;
  r.modes.push_back({"EVT_FORCE_ERROR", 1e-5, std::nullopt, {}});
  r.modes.push_back({"JR3.s_F", std::nullopt, 0.01, {}});
  ASSERT_TRUE(apply_reliability(r, modes).has_value());
  for (const FailureMode& m : modes) {
    if (m.event == "EVT_FORCE_ERROR" && m.kind == ModeKind::Onset) {
      EXPECT_EQ(m.rate, 1e-5);
    }
    if (m.name == "JR3.s_F") {
      EXPECT_EQ(m.probability, 0.01);
    }
  }
  // Not every mode has one: the trees are not quantified, and the text says which are missing.
  const FaultTrees trees = fault_trees(modes, {}, {}, 3, r);
  EXPECT_THAT(trees.unquantified, HasSubstr("have no rate or probability: FM1 (EVT_FORCE_HIGH@JR3.s_A)"));
}

TEST_F(Analyze, AReliabilityEntryThatIsNoFailureModeOfTheAnalysisIsAnErrorAtItsPosition) {
  // The validator accepts it (the event and the machine exist), but nothing raises it there.
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  std::vector<FailureMode> modes = a.modes;
  spec::ReliabilitySpec r;
  r.modes.push_back({"EVT_FORCE_ERROR@SERVO.s_A", 1e-5, std::nullopt, {"robodoc.json", 12, 7}});
  auto applied = apply_reliability(r, modes);
  ASSERT_FALSE(applied.has_value());
  EXPECT_EQ(applied.error()[0].where.line, 12);
  EXPECT_THAT(applied.error()[0].message, HasSubstr("'EVT_FORCE_ERROR@SERVO.s_A' is no failure mode"));
  EXPECT_FALSE(modes[1].rate.has_value());  // nothing changed
}

TEST_F(Analyze, ATopThatIsNotAnAddressOrLevelIsRefusedAndNothingIsAnalysed) {
  EXPECT_FALSE(parse_top("SERVO").has_value());
  EXPECT_FALSE(parse_top("=Error").has_value());
  EXPECT_THAT(parse_top("SERVO=Normal").error().message, HasSubstr("Warning or Error"));
  EXPECT_EQ(parse_top("SERVO.s_F=Warning")->level, State::Warning);
  AnalyzeOptions o;
  o.system = "examples/robodoc/robodoc.json";
  o.tops = {{"SERV0", State::Error}};
  auto a = build_analysis(o, registry_);
  ASSERT_FALSE(a.has_value());
  EXPECT_EQ(a.error()[0].where.file, "--top");
  EXPECT_THAT(a.error()[0].message, HasSubstr("'SERV0' is not an address of robodoc"));
}

TEST_F(Analyze, AMissingScramIsAClearErrorNotAnEmptyTree) {
  AnalyzeOptions o;
  o.system = "examples/robodoc/robodoc.json";
  o.scram = "/nonexistent/scram";
  auto a = build_analysis(o, registry_);
  ASSERT_FALSE(a.has_value());
  EXPECT_THAT(a.error()[0].message, HasSubstr("SCRAM ('/nonexistent/scram') does not run"));
}

TEST_F(Analyze, ABadSystemIsReportedAtItsFileLineAndColumn) {
  AnalyzeOptions o;
  o.system = "tests/data/bad_specs/unknown_event.json";
  auto a = build_analysis(o, registry_);
  ASSERT_FALSE(a.has_value());
  EXPECT_EQ(a.error()[0].where.file, "tests/data/bad_specs/unknown_event.json");
  EXPECT_GT(a.error()[0].where.line, 0);
}

// ---- the safety case --------------------------------------------------------------------------------

TEST_F(Analyze, TheSafetyCaseArguesEachHazardOverDetectionReactionAndTestAndMarksEachGapUndeveloped) {
  const Analysis a = analyze("tests/data/trace/undetected.json");
  ASSERT_FALSE(a.safety_case.nodes.empty());
  EXPECT_EQ(a.safety_case.nodes.front().type, "goal");
  EXPECT_THAT(a.safety_case.nodes.front().text, HasSubstr("acceptably mitigated"));
  bool undetected = false;
  for (const GsnNode& n : a.safety_case.nodes) {
    if (n.text.find("is detected by the monitoring") != std::string::npos && n.undeveloped) undetected = true;
    if (n.type == "strategy") {
      EXPECT_FALSE(n.parts.empty()) << n.id;
    }
  }
  EXPECT_TRUE(undetected);
  // Proved, detected and tested: every goal of arm's hazard is developed.
  const Analysis arm = analyze("tests/data/trace/arm.json", {"tests/data/trace/covered.scenario.json"}, {},
                               "tests/data/trace/verify_holds.jsonl");
  for (const GsnNode& n : arm.safety_case.nodes) EXPECT_FALSE(n.undeveloped) << n.id << " " << n.text;
}

// ---- the formats ------------------------------------------------------------------------------------

TEST_F(Analyze, TheCsvHasOneRowPerFailureModeAndTheJsonEverything) {
  const Analysis a = analyze("examples/robodoc/robodoc.json");
  const std::string csv = fmea_csv(a);
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), a.modes.size() + 1);
  EXPECT_EQ(csv.rfind("id,name,kind,failure,", 0), 0U);
  const std::string json = analysis_json(a);
  EXPECT_THAT(json, HasSubstr("\"fmea\":"));
  EXPECT_THAT(json, HasSubstr("\"cut_sets\":"));
  EXPECT_THAT(json, HasSubstr("\"notation\":\"GSN Community Standard v3\""));
}

}  // namespace
}  // namespace safecass::analyze
