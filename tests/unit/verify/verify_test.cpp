// `safecass verify` (docs/verify.md): robodoc's hazards are proved; each deliberately broken spec
// of tests/data/verify/ is violated, its counterexample scenario makes `safecass run` fail at the
// same address, and its fixed version (NAME.fixed.json) passes both; the specification's own
// properties; limits; the command's exit codes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "safecass/filters/registry.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/verify.hpp"
#include "verify_command.hpp"
#include "verify_test_support.hpp"

namespace safecass::verify {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

fs::path test_root() { return fs::temp_directory_path() / ("safecass-verify-test-" + std::to_string(::getpid())); }

/// Removes the counterexamples written under the temporary directory once every test has run.
class CounterexampleFiles : public ::testing::Environment {
public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(test_root(), ec);
  }
};
const auto* const kCounterexampleFiles = ::testing::AddGlobalTestEnvironment(new CounterexampleFiles);

spec::SystemSpec load(const std::string& path) {
  spec::LoadResult r = spec::load_system(path, builtin_filters());
  EXPECT_TRUE(r.ok()) << path << ": " << (r.diagnostics.empty() ? "" : spec::format(r.diagnostics[0]));
  return r.system ? *r.system : spec::SystemSpec{};
}

spec::SystemSpec load_text(const std::string& text) {
  spec::LoadResult r = spec::load_system_from_text(text, "generated.json", builtin_filters());
  EXPECT_TRUE(r.ok()) << (r.diagnostics.empty() ? "" : spec::format(r.diagnostics[0]));
  return r.system ? *r.system : spec::SystemSpec{};
}

/// A fresh directory for the counterexamples of one test.
std::string out_dir(const std::string& name) {
  const fs::path dir = test_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

const PropertyResult* find(const Report& r, PropertyResult::Kind kind, const std::string& name) {
  for (const PropertyResult& p : r.properties) {
    if (p.kind == kind && p.name == name) return &p;
  }
  return nullptr;
}

TEST(Verify, RobodocProvesEveryHazardReactionAndItsInvariant) {
  const spec::SystemSpec system = load("examples/robodoc/robodoc.json");
  auto report = verify(system, builtin_filters(), Options{});
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->exit_code(), 0);
  for (const char* h : {"H-2", "H-3", "H-4", "H-5", "H-6"}) {
    const PropertyResult* p = find(*report, PropertyResult::Kind::Reaction, h);
    ASSERT_NE(p, nullptr) << h;
    EXPECT_EQ(p->verdict, PropertyResult::Verdict::Holds) << h << ": " << p->message;
    EXPECT_GT(p->states, 0u) << h;
    EXPECT_GT(p->memory_mb, 0.0) << h;
    EXPECT_EQ(p->onsets_total, 7u) << "every onset of robodoc is in the model";
  }
  const PropertyResult* inv = find(*report, PropertyResult::Kind::Invariant, "servo_follows_control");
  ASSERT_NE(inv, nullptr);
  EXPECT_EQ(inv->verdict, PropertyResult::Verdict::Holds);
}

TEST(Verify, AHazardWhoseReactionIsTooStrongIsViolatedWithAShortestCounterexample) {
  // EVT_FORCE_HIGH is a warning of JR3; ForceData passes errors only, so CONTROL stays Normal.
  spec::SystemSpec system = load("examples/robodoc/robodoc.json");
  for (spec::ComponentSpec& c : system.components) {
    for (EventDef& e : c.events) {
      if (e.name == "EVT_FORCE_HIGH") e.hazard = "H-3";
    }
  }
  Options options;
  options.out_dir = out_dir("robodoc-force-high");
  options.property = "H-3";
  auto report = verify(system, builtin_filters(), options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->exit_code(), 1);
  ASSERT_EQ(report->properties.size(), 1u) << "--property checks that property only";
  const PropertyResult& p = report->properties[0];
  EXPECT_EQ(p.verdict, PropertyResult::Verdict::Violated);
  EXPECT_THAT(p.message, HasSubstr("EVT_FORCE_HIGH on JR3.s_A is active, CONTROL is Normal, not at least Error"));
  ASSERT_FALSE(p.scenario.empty());
  runner::RunOptions run;
  run.quiet = true;
  runner::RunResult result;
  std::FILE* sink = std::tmpfile();
  EXPECT_EQ(runner::run_scenario_file(p.scenario, builtin_filters(), run, &result, sink), 1);
  ASSERT_FALSE(result.failures.empty());
  EXPECT_THAT(result.failures[0], HasSubstr("CONTROL is Normal, expected Error"));
  std::ifstream in(p.scenario);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().find("\"generate\""), text.str().rfind("\"generate\"")) << "one onset suffices:\n" << text.str();
  std::fclose(sink);
}

/// The broken specs: each is violated, its scenario fails at the address the violation names,
/// and the fixed spec passes verify and the same scenario.
class BrokenSpec : public ::testing::TestWithParam<const char*> {};

TEST_P(BrokenSpec, VerifyFailsTheScenarioReproducesItAndTheFixedSpecPassesBoth) {
  const std::string name = GetParam();
  const std::string broken_path = "tests/data/verify/" + name + ".json";
  const std::string fixed_path = "tests/data/verify/" + name + ".fixed.json";
  Options options;
  options.out_dir = out_dir(name);
  auto broken = verify(load(broken_path), builtin_filters(), options);
  ASSERT_TRUE(broken) << broken.error().message;
  EXPECT_EQ(broken->exit_code(), 1);
  const PropertyResult* violated = nullptr;
  for (const PropertyResult& p : broken->properties) {
    if ((p.kind == PropertyResult::Kind::Reaction || p.kind == PropertyResult::Kind::Invariant) &&
        p.verdict == PropertyResult::Verdict::Violated) {
      violated = &p;
    }
  }
  ASSERT_NE(violated, nullptr);
  ASSERT_FALSE(violated->scenario.empty());
  EXPECT_EQ(violated->scenario, options.out_dir + "/" + violated->name + ".scenario.json");

  // The scenario fails at its last step, at the address the verdict names.
  std::FILE* sink = std::tmpfile();
  runner::RunOptions run;
  run.quiet = true;
  runner::RunResult result;
  EXPECT_EQ(runner::run_scenario_file(violated->scenario, builtin_filters(), run, &result, sink), 1)
      << violated->scenario;
  ASSERT_FALSE(result.failures.empty());
  const std::string failure = result.failures.front();
  const std::string address = failure.substr(failure.find(": ", failure.find("expectation failed")) + 2,
                                             failure.find(" is ", failure.find("expectation failed")) -
                                                 failure.find(": ", failure.find("expectation failed")) - 2);
  EXPECT_THAT(violated->message, HasSubstr(address + " is ")) << failure;

  // Fixed: verify passes, and the same scenario passes against the fixed system.
  auto fixed = verify(load(fixed_path), builtin_filters(), Options{});
  ASSERT_TRUE(fixed) << fixed.error().message;
  for (const PropertyResult& p : fixed->properties) {
    if (p.kind == PropertyResult::Kind::Reaction || p.kind == PropertyResult::Kind::Invariant) {
      EXPECT_EQ(p.verdict, PropertyResult::Verdict::Holds) << p.name << ": " << p.message;
    }
  }
  EXPECT_EQ(fixed->exit_code(), 0);
  run.system_override = fixed_path;
  runner::RunResult again;
  EXPECT_EQ(runner::run_scenario_file(violated->scenario, builtin_filters(), run, &again, sink), 0);
  EXPECT_TRUE(again.failures.empty()) << again.failures.front();
  std::fclose(sink);
}

INSTANTIATE_TEST_SUITE_P(Corpus, BrokenSpec,
                         ::testing::Values("level_rule", "missing_dependency", "propagation_level", "invariant",
                                           "broadcast"));

TEST(Verify, TheLevelRuleDependsOnTheStateWhenTheOnsetArrives) {
  // {N2W, W2E}: from Normal a Warning, from Warning an Error. With EVT_SLOW (a Warning) active
  // first, EVT_FORCE becomes an Error: the model must keep the state at onset.
  spec::SystemSpec system = load("tests/data/verify/level_rule.json");
  system.invariants.push_back(spec::InvariantSpec{"never_error", "[] ARM.s_A != Error", "", {}});
  Options options;
  options.property = "never_error";
  options.out_dir = out_dir("level-rule-state");
  auto report = verify(system, builtin_filters(), options);
  ASSERT_TRUE(report) << report.error().message;
  ASSERT_EQ(report->properties.size(), 1u);
  const PropertyResult& p = report->properties[0];
  EXPECT_EQ(p.verdict, PropertyResult::Verdict::Violated);
  std::ifstream in(p.scenario);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  EXPECT_LT(s.find("EVT_SLOW"), s.find("EVT_FORCE")) << "the shortest way to an Error is a warning first:\n" << s;
  EXPECT_THAT(s, HasSubstr("\"expect\": { \"ARM.s_A\": \"Warning\" }")) << s;
}

TEST(Verify, LatchedConditionsClearOnlyByReset) {
  // CTRL's EVT_FREEZE is latched and has no completion: once raised, CTRL.s_A leaves Error only
  // by a reset of CTRL.s_A.
  spec::SystemSpec system = load("tests/data/verify/missing_dependency.fixed.json");
  system.invariants.push_back(
      spec::InvariantSpec{"freeze_stays", "[] (CTRL.s_A == Error -> [] (CTRL.s_A == Error))", "", {}});
  Options options;
  options.property = "freeze_stays";
  auto report = verify(system, builtin_filters(), options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->properties.at(0).verdict, PropertyResult::Verdict::Violated)
      << "a reset clears a latched condition";
  EXPECT_THAT(report->properties.at(0).message, HasSubstr("violates the formula"));
}

TEST(Verify, ReportsTheSpecificationsOwnPropertiesWithTheirPositions) {
  auto report = verify(load("tests/data/verify/findings.json"), builtin_filters(), Options{});
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->exit_code(), 0) << "findings about the specification are warnings";
  const PropertyResult* needs_reset = find(*report, PropertyResult::Kind::NeedsReset, "EVT_JAM@GRIPPER.s_A");
  ASSERT_NE(needs_reset, nullptr);
  EXPECT_EQ(needs_reset->where.file, "tests/data/verify/findings.json");
  EXPECT_EQ(needs_reset->where.line, 12);
  EXPECT_THAT(needs_reset->message, HasSubstr("nothing but a reset can clear it"));
  const PropertyResult* undetectable = find(*report, PropertyResult::Kind::Undetectable, "H-7");
  ASSERT_NE(undetectable, nullptr);
  EXPECT_EQ(undetectable->where.line, 9);
  const PropertyResult* normal = find(*report, PropertyResult::Kind::NeverLeavesNormal, "AXIS");
  ASSERT_NE(normal, nullptr);
  EXPECT_GT(normal->where.line, 0);
  EXPECT_EQ(find(*report, PropertyResult::Kind::NeverLeavesNormal, "GRIPPER"), nullptr);
  EXPECT_EQ(find(*report, PropertyResult::Kind::Reaction, "H-1")->verdict, PropertyResult::Verdict::Holds);
}

TEST(Verify, AnUnknownPropertyIsBadInput) {
  Options options;
  options.property = "H-99";
  auto report = verify(load("examples/robodoc/robodoc.json"), builtin_filters(), options);
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().code, ErrorCode::NotFound);
  EXPECT_THAT(report.error().message, HasSubstr("H-3"));
}

/// `n` components, each with three onsets of their own hazard on s_A: 3n independent onsets.
std::string wide_system(int n) {
  std::string s = R"({"safecass": 1, "system": "wide", "hazards": [)";
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < 3; ++j)
      s += std::string(k + j ? "," : "") + R"({"id": "H-)" + std::to_string(k) + "-" + std::to_string(j) + R"("})";
  }
  s += R"x(], "invariants": [{"name": "everything", "formula": "[] (SYSTEM <= Error)"}], "components": [)x";
  for (int k = 0; k < n; ++k) {
    s += std::string(k ? "," : "") + R"({"component": "C)" + std::to_string(k) + R"(", "event": [)";
    for (int j = 0; j < 3; ++j) {
      const std::string e = "EVT_" + std::to_string(k) + "_" + std::to_string(j);
      s += std::string(j ? "," : "") + R"({"name": ")" + e +
           R"(", "severity": 10, "state_transition": ["N2W", "W2E"], "hazard": "H-)" + std::to_string(k) + "-" +
           std::to_string(j) + R"("}, {"name": "/)" + e + R"(", "severity": 10, "state_transition": ["W2N", "E2N"]})";
    }
    s += "]}";
  }
  return s + "]}";
}

TEST(Verify, PastTheMemoryBoundAPropertyIsUndecidedWithAdviceNotACrash) {
  Options options;
  options.property = "everything";
  options.memory_mb = 64;
  auto report = verify(load_text(wide_system(12)), builtin_filters(), options);
  ASSERT_TRUE(report) << report.error().message;
  ASSERT_EQ(report->properties.size(), 1u);
  const PropertyResult& p = report->properties[0];
  EXPECT_EQ(p.verdict, PropertyResult::Verdict::Undecided) << p.message;
  EXPECT_THAT(p.message, HasSubstr("memory bound (64 MB)"));
  EXPECT_THAT(p.advice, HasSubstr("split an invariant"));
  EXPECT_EQ(report->exit_code(), 3);
}

TEST(Verify, InterchangeableOnsetsAreCountedNotTracked) {
  // Three onsets with the same machine, transitions, completion and hazard: one class.
  std::string s = R"({"safecass": 1, "system": "s", "hazards": [{"id": "H-1", "reaction": {"A": "Error"}}],
    "components": [{"component": "A", "event": [)";
  for (int j = 0; j < 3; ++j) {
    s += std::string(j ? "," : "") + R"({"name": "EVT_)" + std::to_string(j) +
         R"(", "severity": 50, "state_transition": ["N2E"], "hazard": "H-1"},
         {"name": "/EVT_)" +
         std::to_string(j) + R"(", "severity": 50, "state_transition": ["E2N"]})";
  }
  s += "]}]}";
  const spec::SystemSpec system = load_text(s);
  auto merged = verify(system, builtin_filters(), Options{});
  ASSERT_TRUE(merged);
  Options separate;
  separate.merge = false;
  auto tracked = verify(system, builtin_filters(), separate);
  ASSERT_TRUE(tracked);
  const PropertyResult* m = find(*merged, PropertyResult::Kind::Reaction, "H-1");
  const PropertyResult* t = find(*tracked, PropertyResult::Kind::Reaction, "H-1");
  EXPECT_EQ(m->verdict, PropertyResult::Verdict::Holds);
  EXPECT_EQ(t->verdict, PropertyResult::Verdict::Holds);
  EXPECT_EQ(m->onsets, 1u);
  EXPECT_EQ(t->onsets, 3u);
  EXPECT_EQ(m->states, 4u) << "0 to 3 active";
  EXPECT_EQ(t->states, 8u) << "each on or off";
}

TEST(Verify, WithoutSpinOrACompilerItSaysWhatToInstall) {
  const spec::SystemSpec system = load("examples/robodoc/robodoc.json");
  Options no_spin;
  no_spin.spin = "/nonexistent/spin";
  auto a = verify(system, builtin_filters(), no_spin);
  ASSERT_FALSE(a);
  EXPECT_EQ(a.error().code, ErrorCode::Io);
  EXPECT_THAT(a.error().message, HasSubstr("install the Debian package 'spin'"));
  Options no_cc;
  no_cc.cc = "/nonexistent/cc";
  auto b = verify(system, builtin_filters(), no_cc);
  ASSERT_FALSE(b);
  EXPECT_THAT(b.error().message, HasSubstr("C compiler"));
}

// ---- the command ---------------------------------------------------------------------------

int command(const std::string& system, const std::string& property = {}, const std::string& out = {}) {
  Options options;
  options.property = property;
  options.out_dir = out;
  std::fflush(stdout);
  return tools::run_verify(system, options, true);
}

TEST(VerifyCommand, ExitsZeroWhenEverythingHoldsOneOnAViolationTwoOnBadInput) {
  EXPECT_EQ(command("examples/robodoc/robodoc.json"), 0);
  EXPECT_EQ(command("tests/data/verify/level_rule.json", "", out_dir("command")), 1);
  EXPECT_EQ(command("tests/data/bad_specs/hazard_unknown_id.json"), 2);
  EXPECT_EQ(command("examples/robodoc/robodoc.json", "H-99"), 2);
  EXPECT_EQ(command("tests/data/verify/no_such_file.json"), 2);
}

}  // namespace
}  // namespace safecass::verify
