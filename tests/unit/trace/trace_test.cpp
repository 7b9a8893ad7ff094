// `safecass trace` (tools/trace, docs/trace.md): the chain hazard → events → filters → reaction →
// scenarios → verify, built from the specification and real scenario runs, and every gap with its
// severity.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "safecass/filters/registry.hpp"
#include "safecass/trace/trace.hpp"

namespace safecass::trace {
namespace {

using ::testing::HasSubstr;

class TraceTest : public ::testing::Test {
protected:
  TraceTest() { register_builtin_filters(registry_); }

  Trace build(const std::string& system, std::vector<std::string> scenarios, const std::string& verify = {},
              bool histories = false) {
    TraceOptions o;
    o.system = system;
    o.scenarios = std::move(scenarios);
    o.verify_json = verify;
    o.histories = histories;
    auto t = build_trace(o, registry_);
    if (!t) {
      std::string text;
      for (const auto& d : t.error()) text += spec::format(d) + "\n";
      ADD_FAILURE() << text;
      return {};
    }
    return std::move(*t);
  }

  std::vector<spec::Diagnostic> fail(const std::string& system, std::vector<std::string> scenarios,
                                     const std::string& verify = {}) {
    TraceOptions o;
    o.system = system;
    o.scenarios = std::move(scenarios);
    o.verify_json = verify;
    auto t = build_trace(o, registry_);
    EXPECT_FALSE(t.has_value());
    return t ? std::vector<spec::Diagnostic>{} : t.error();
  }

  static const Gap* find_gap(const Trace& t, const std::string& kind, const std::string& subject) {
    for (const Gap& g : t.gaps) {
      if (g.kind == kind && g.subject == subject) return &g;
    }
    return nullptr;
  }
  static const HazardTrace* hazard(const Trace& t, const std::string& id) {
    for (const HazardTrace& h : t.hazards) {
      if (h.id == id) return &h;
    }
    return nullptr;
  }
  static const EventLink* event(const HazardTrace& h, const std::string& name) {
    for (const EventLink& e : h.events) {
      if (e.name == name) return &e;
    }
    return nullptr;
  }

  FilterRegistry registry_;
};

const std::vector<std::string> kRobodocScenarios{"examples/robodoc/story.json", "examples/robodoc/injection.json",
                                                 "examples/robodoc/warnings.json", "examples/robodoc/overload.json"};

TEST_F(TraceTest, RobodocTracesEveryHazardWithNoErrorSeverityGap) {
  const Trace t = build("examples/robodoc/robodoc.json", kRobodocScenarios);
  EXPECT_EQ(t.system, "robodoc");
  EXPECT_FALSE(t.has_error_gap());
  for (const Gap& g : t.gaps) EXPECT_NE(g.severity, Severity::Error) << g.message;
  for (const char* id : {"H-3", "H-5", "H-6"}) ASSERT_NE(hazard(t, id), nullptr) << id;
  // Every scenario ran and passed.
  ASSERT_EQ(t.scenarios.size(), 4u);
  for (const ScenarioResult& s : t.scenarios) EXPECT_TRUE(s.passed) << s.path;
  // Every spec file is named with its SHA-256: the system file and the five component files.
  EXPECT_EQ(t.files.size(), 6u);
  for (const SpecFile& f : t.files) EXPECT_EQ(f.sha256.size(), 64u) << f.path;
}

TEST_F(TraceTest, ForceHazardChainNamesTheThresholdFilterItsTargetAndTheScenariosThatFireAndCheckIt) {
  const Trace t = build("examples/robodoc/robodoc.json", kRobodocScenarios);
  const HazardTrace* h3 = hazard(t, "H-3");
  ASSERT_NE(h3, nullptr);
  const EventLink* onset = event(*h3, "EVT_FORCE_ERROR");
  ASSERT_NE(onset, nullptr);
  EXPECT_TRUE(onset->onset);
  EXPECT_EQ(onset->severity, 50);
  EXPECT_EQ(onset->level, "Error");
  EXPECT_EQ(onset->component, "JR3");
  EXPECT_EQ(onset->targets, std::vector<std::string>{"JR3.s_A"});
  ASSERT_EQ(onset->filters.size(), 1u);
  const FilterLink& f = onset->filters[0];
  EXPECT_EQ(f.name, "force_limit");
  EXPECT_EQ(f.type, "Threshold");
  EXPECT_EQ(f.threshold, "30");
  EXPECT_EQ(f.execution, "ACTIVE");
  EXPECT_EQ(f.pipeline, "force_check");
  EXPECT_THAT(f.period, HasSubstr("0.001 s"));
  EXPECT_THAT(f.parameters, ::testing::Contains("hysteresis=2"));
  EXPECT_EQ(f.where.file, "examples/robodoc/jr3.json");
  // The story fires it (the force passes the warning first: W2E); the completion follows it.
  const auto story = std::find_if(onset->fired_by.begin(), onset->fired_by.end(),
                                  [](const ScenarioUse& u) { return u.scenario == "examples/robodoc/story.json"; });
  ASSERT_NE(story, onset->fired_by.end());
  EXPECT_THAT(story->transitions, ::testing::Contains("W2E"));
  EXPECT_FALSE(onset->cleared_by.empty());
  ASSERT_NE(event(*h3, "/EVT_FORCE_ERROR"), nullptr);
  // The reaction: CONTROL and SERVO at Error, both checked by the story after the onset.
  ASSERT_EQ(h3->reaction.size(), 2u);
  for (const ReactionLink& r : h3->reaction) {
    EXPECT_EQ(r.level, "Error");
    EXPECT_THAT(r.checked_by, ::testing::Contains("examples/robodoc/story.json")) << r.address;
  }
  // No verify result given: not run.
  EXPECT_EQ(h3->verified, Verdict::NotRun);
}

TEST_F(TraceTest, LatchedBoneMotionIsClearedOnlyByTheResetAndWatchdogIsPassiveAtTheMonitorPeriod) {
  const Trace t = build("examples/robodoc/robodoc.json", kRobodocScenarios);
  const HazardTrace* h5 = hazard(t, "H-5");
  ASSERT_NE(h5, nullptr);
  const EventLink* bone = event(*h5, "EVT_BONE_MOTION");
  ASSERT_NE(bone, nullptr);
  EXPECT_TRUE(bone->latched);
  EXPECT_EQ(bone->cleared_by, std::vector<std::string>{"examples/robodoc/story.json"});
  // A latched onset's completion is ignored by design: never "not fired".
  EXPECT_EQ(find_gap(t, "event-not-fired", "/EVT_BONE_MOTION"), nullptr);
  const HazardTrace* h6 = hazard(t, "H-6");
  ASSERT_NE(h6, nullptr);
  const EventLink* stale = event(*h6, "EVT_FORCE_STALE");
  ASSERT_NE(stale, nullptr);
  ASSERT_EQ(stale->filters.size(), 1u);
  EXPECT_EQ(stale->filters[0].execution, "PASSIVE");
  EXPECT_EQ(stale->filters[0].type, "Watchdog");
  EXPECT_EQ(stale->filters[0].target, "JR3.s_F");
  EXPECT_THAT(stale->filters[0].period, HasSubstr("0.005 s (monitor)"));
}

TEST_F(TraceTest, HazardThatNothingDetectsIsAnErrorGapNamingIt) {
  const Trace t = build("tests/data/trace/undetected.json", {});
  ASSERT_TRUE(t.has_error_gap());
  const Gap* h9 = find_gap(t, "hazard-undetected", "H-9");
  ASSERT_NE(h9, nullptr);
  EXPECT_EQ(h9->severity, Severity::Error);
  EXPECT_THAT(h9->message, HasSubstr("no filter generates"));
  EXPECT_THAT(h9->message, HasSubstr("EVT_COLLISION"));
  EXPECT_EQ(h9->where.file, "tests/data/trace/undetected.json");
  EXPECT_GT(h9->where.line, 0);
  const Gap* h8 = find_gap(t, "hazard-undetected", "H-8");
  ASSERT_NE(h8, nullptr);
  EXPECT_THAT(h8->message, HasSubstr("no event names it"));
  // H-1 has its filter: not undetected.
  EXPECT_EQ(find_gap(t, "hazard-undetected", "H-1"), nullptr);
  // The validation warning (a hazard with no linked event) is kept as a note.
  EXPECT_TRUE(std::any_of(t.notes.begin(), t.notes.end(),
                          [](const spec::Diagnostic& d) { return d.message.find("H-8") != std::string::npos; }));
  // Errors come first.
  EXPECT_EQ(t.gaps.front().severity, Severity::Error);
}

TEST_F(TraceTest, FullyCoveredHazardHasNoGapButTheFilterWithoutHazardIsInfo) {
  const Trace t = build("tests/data/trace/arm.json", {"tests/data/trace/covered.scenario.json"});
  EXPECT_FALSE(t.has_error_gap());
  for (const Gap& g : t.gaps) {
    if (g.hazard == "H-1") ADD_FAILURE() << g.kind << ": " << g.message;
  }
  const Gap* info = find_gap(t, "filter-without-hazard", "force_warning");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->severity, Severity::Info);
  ASSERT_EQ(t.unlinked.size(), 1u);
  EXPECT_EQ(t.unlinked[0].name, "EVT_FORCE_HIGH");
  // EVT_OVERHEAT has no filter: not a "filter without hazard".
  EXPECT_EQ(find_gap(t, "filter-without-hazard", "EVT_OVERHEAT"), nullptr);
}

TEST_F(TraceTest, ExpectBeforeTheOnsetDoesNotCheckTheReactionAndUnclearedOnsetIsAWarning) {
  const Trace t = build("tests/data/trace/arm.json", {"tests/data/trace/unchecked.scenario.json"});
  EXPECT_FALSE(t.has_error_gap());
  const Gap* unchecked = find_gap(t, "reaction-unchecked", "ARM");
  ASSERT_NE(unchecked, nullptr);
  EXPECT_EQ(unchecked->severity, Severity::Warning);
  EXPECT_EQ(unchecked->hazard, "H-1");
  const Gap* uncleared = find_gap(t, "onset-not-cleared", "EVT_FORCE");
  ASSERT_NE(uncleared, nullptr);
  EXPECT_EQ(uncleared->severity, Severity::Warning);
  const Gap* completion = find_gap(t, "event-not-fired", "/EVT_FORCE");
  ASSERT_NE(completion, nullptr);
  EXPECT_EQ(completion->severity, Severity::Warning);
}

TEST_F(TraceTest, EventThatNoScenarioFiresIsAWarningGap) {
  const Trace t = build("tests/data/trace/arm.json", {});
  const Gap* g = find_gap(t, "event-not-fired", "EVT_FORCE");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->severity, Severity::Warning);
  EXPECT_EQ(g->where.file, "tests/data/trace/arm.json");
  EXPECT_NE(find_gap(t, "reaction-unchecked", "ARM"), nullptr);
  EXPECT_FALSE(t.has_error_gap());
}

TEST_F(TraceTest, FailingScenarioIsAnErrorGapAndItsEvidenceIsStillListed) {
  const Trace t = build("tests/data/trace/arm.json", {"tests/data/trace/failing.scenario.json"});
  ASSERT_TRUE(t.has_error_gap());
  const Gap* g = find_gap(t, "scenario-failed", "tests/data/trace/failing.scenario.json");
  ASSERT_NE(g, nullptr);
  EXPECT_THAT(g->message, HasSubstr("ARM is Error, expected Normal"));
}

TEST_F(TraceTest, VerifyResultGivesEachHazardItsVerdictAndAViolationIsAnErrorGap) {
  const Trace holds = build("tests/data/trace/arm.json", {"tests/data/trace/covered.scenario.json"},
                            "tests/data/trace/verify_holds.jsonl");
  ASSERT_NE(hazard(holds, "H-1"), nullptr);
  EXPECT_EQ(hazard(holds, "H-1")->verified, Verdict::Holds);
  EXPECT_FALSE(holds.has_error_gap());
  const Trace violated = build("tests/data/trace/arm.json", {"tests/data/trace/covered.scenario.json"},
                               "tests/data/trace/verify_violated.jsonl");
  EXPECT_EQ(hazard(violated, "H-1")->verified, Verdict::Violated);
  const Gap* g = find_gap(violated, "reaction-violated", "H-1");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->severity, Severity::Error);
}

TEST_F(TraceTest, MalformedVerifyFileIsBadInputNamingItsLine) {
  const auto errors = fail("tests/data/trace/arm.json", {}, "tests/data/trace/verify_malformed.jsonl");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where.file, "tests/data/trace/verify_malformed.jsonl");
  EXPECT_EQ(errors[0].where.line, 2);
}

TEST_F(TraceTest, ScenarioNamingWhatTheSystemLacksIsBadInputWithItsPosition) {
  // The robodoc scenario's signals do not exist in the arm.
  const auto errors = fail("tests/data/trace/arm.json", {"examples/robodoc/warnings.json"});
  ASSERT_FALSE(errors.empty());
  EXPECT_EQ(errors[0].where.file, "examples/robodoc/warnings.json");
  EXPECT_GT(errors[0].where.line, 0);
}

TEST_F(TraceTest, MissingSystemIsBadInput) {
  const auto errors = fail("tests/data/trace/none.json", {});
  ASSERT_FALSE(errors.empty());
  EXPECT_THAT(spec::format(errors[0]), HasSubstr("none.json"));
}

TEST_F(TraceTest, CsvHasOneRowPerHazardEventAndFilterQuotedPerRfc4180) {
  const Trace t = build("examples/robodoc/robodoc.json", kRobodocScenarios);
  const std::string csv = trace_csv(t);
  // Header + rows, every line ends with CRLF.
  std::vector<std::string> lines;
  std::size_t pos = 0;
  while (pos < csv.size()) {
    const std::size_t end = csv.find("\r\n", pos);
    ASSERT_NE(end, std::string::npos) << "a line without CRLF";
    lines.push_back(csv.substr(pos, end - pos));
    pos = end + 2;
  }
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0].rfind("hazard,hazard_description,reaction,", 0), 0u);
  std::size_t expected = 0;
  for (const HazardTrace& h : t.hazards) {
    if (h.events.empty()) ++expected;
    for (const EventLink& e : h.events) expected += std::max<std::size_t>(1, e.filters.size());
  }
  for (const EventLink& e : t.unlinked) expected += std::max<std::size_t>(1, e.filters.size());
  EXPECT_EQ(lines.size(), expected + 1);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& l) {
    return l.rfind("H-3,", 0) == 0 && l.find("EVT_FORCE_ERROR,onset,JR3,50,Error") != std::string::npos &&
           l.find(",force_limit,") != std::string::npos;
  }));
}

TEST_F(TraceTest, CsvQuotesCommasAndDoublesQuotes) {
  const Trace t = build("tests/data/trace/arm.json", {"tests/data/trace/covered.scenario.json"});
  const std::string csv = trace_csv(t);
  EXPECT_THAT(csv, HasSubstr("H-1,\"excessive force, on the \"\"patient\"\", of the arm\",ARM>=Error,"));
}

TEST_F(TraceTest, JsonHasTheChainTheGapsAndTheErrorFlag) {
  const Trace t = build("tests/data/trace/undetected.json", {});
  const std::string json = trace_json(t);
  EXPECT_THAT(json, HasSubstr("\"kind\":\"hazard-undetected\",\"hazard\":\"H-9\""));
  EXPECT_THAT(json, HasSubstr("\"error_gaps\":true"));
  EXPECT_THAT(json, HasSubstr("\"verify\":\"not run\""));
}

TEST_F(TraceTest, Sha256MatchesTheStandardTestVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST_F(TraceTest, ReportHasHeaderHashesMatrixGapMarkersExcerptsAndCoverage) {
  const Trace t = build("examples/robodoc/robodoc.json", kRobodocScenarios, {}, true);
  const std::string page = render_trace_page(t, "2026-01-02 03:04:05 UTC");
  EXPECT_THAT(page, HasSubstr("<span id=\"system-name\">robodoc</span>"));
  EXPECT_THAT(page, HasSubstr("2026-01-02 03:04:05 UTC"));
  EXPECT_THAT(page, HasSubstr("safecass " + std::string(tool_version())));
  for (const SpecFile& f : t.files) EXPECT_THAT(page, HasSubstr(f.sha256)) << f.path;
  for (const HazardTrace& h : t.hazards) {
    EXPECT_THAT(page, HasSubstr("<tbody class=\"hazard\" data-hazard=\"" + h.id + "\">"));
    // An excerpt for each hazard a scenario exercises; the others say that none does.
    if (h.excerpt_scenario.empty()) {
      EXPECT_THAT(page, HasSubstr("data-excerpt-missing=\"" + h.id + "\"")) << h.id;
    } else {
      EXPECT_THAT(page, HasSubstr("<figure class=\"excerpt\" data-hazard=\"" + h.id + "\"")) << h.id;
    }
  }
  for (const char* id : {"H-3", "H-5", "H-6"}) EXPECT_FALSE(hazard(t, id)->excerpt_scenario.empty()) << id;
  EXPECT_THAT(page, HasSubstr("No gap of error severity."));
  EXPECT_THAT(page, HasSubstr("id=\"coverage-table\""));
  EXPECT_THAT(page, HasSubstr("SafecassTimeline"));  // the timeline's renderer draws the excerpts
  EXPECT_EQ(page.find("http://"), page.find("http://www.w3.org/2000/svg"));  // no network resource
}

TEST_F(TraceTest, ReportOfAnUndetectedHazardMarksItAsAnError) {
  const Trace t = build("tests/data/trace/undetected.json", {}, {}, true);
  const std::string page = render_trace_page(t, "today");
  EXPECT_THAT(page, HasSubstr("data-gap=\"hazard-undetected\">ERROR: no detecting filter"));
  EXPECT_THAT(page, HasSubstr("class=\"verdict fail\""));
  EXPECT_THAT(page, HasSubstr("data-excerpt-missing=\"H-9\""));
}

}  // namespace
}  // namespace safecass::trace
