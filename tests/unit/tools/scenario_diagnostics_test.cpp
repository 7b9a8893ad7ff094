// Scenario files get the diagnostics of validation (docs/tools.md, "Scenario diagnostics"): every
// problem at once, format and names in one pass, in file order, each with file:line:col, and
// "did you mean" for unknown signals, filters, events and addresses. Each file in
// tests/data/bad_scenarios/ holds one kind of mistake; its diagnostics must equal, byte for byte,
// the golden file next to it (name.json.expected). SAFECASS_UPDATE_GOLDEN=1 rewrites them.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "safecass/filters/registry.hpp"
#include "safecass/runner/scenario_runner.hpp"

namespace safecass::runner {
namespace {

constexpr const char* kCorpus = "tests/data/bad_scenarios";

class InSourceRoot : public ::testing::Environment {
public:
  void SetUp() override { std::filesystem::current_path(SAFECASS_SOURCE_DIR); }
};
const auto* const kRoot = ::testing::AddGlobalTestEnvironment(new InSourceRoot);

const FilterRegistry& registry() {
  static const FilterRegistry r = [] {
    FilterRegistry x;
    register_builtin_filters(x);
    return x;
  }();
  return r;
}

std::vector<std::string> cases() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(std::string(SAFECASS_SOURCE_DIR) + "/" + kCorpus, ec)) {
    if (e.is_regular_file() && e.path().extension() == ".json") out.push_back(e.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class BadScenario : public ::testing::TestWithParam<std::string> {};

TEST_P(BadScenario, DiagnosticsMatchTheGoldenFile) {
  const std::string path = std::string(kCorpus) + "/" + GetParam();
  const std::vector<spec::Diagnostic> found = check_scenario(path, registry());
  std::string actual;
  for (const spec::Diagnostic& d : found) actual += spec::format(d) + "\n";
  const std::string golden = path + ".expected";
  const char* update = std::getenv("SAFECASS_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(golden, std::ios::binary) << actual;
    GTEST_SKIP() << "rewrote " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << golden << " is missing; run with SAFECASS_UPDATE_GOLDEN=1";
  EXPECT_EQ(actual, read_text(golden));
  EXPECT_FALSE(found.empty());
  for (std::size_t i = 1; i < found.size(); ++i) {
    const auto& a = found[i - 1].where;
    const auto& b = found[i].where;
    EXPECT_TRUE(a.line < b.line || (a.line == b.line && a.column <= b.column)) << "in file order: " << actual;
  }
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param.substr(0, info.param.find('.'));
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadScenario, ::testing::ValuesIn(cases()), test_name);

TEST(ScenarioDiagnostics, FormatAndNameProblemsAreReportedInOnePass) {
  const auto found = check_scenario(std::string(kCorpus) + "/format_and_name_errors_together.json", registry());
  ASSERT_GE(found.size(), 3u);
  std::string all;
  for (const auto& d : found) all += spec::format(d) + "\n";
  EXPECT_THAT(all, ::testing::HasSubstr("\"at\" must be a number")) << "a format problem";
  EXPECT_THAT(all, ::testing::HasSubstr("no signal 'ARM.Forse'; did you mean 'ARM.Force'?"))
      << "and a name problem, together";
}

TEST(ScenarioDiagnostics, AnExpectationAfterTheDurationIsAnInputErrorThatSaysSo) {
  const std::string path = std::string(kCorpus) + "/expectation_after_duration.json";
  const auto found = check_scenario(path, registry());
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(spec::format(found[0]), path +
                                        ":7:28: error: expectation at t=0.5 is after the duration (0.1 s): it would "
                                        "never be checked; move it or lengthen \"duration\" [/steps/2/expect]");
  std::FILE* err = std::tmpfile();
  RunResult result;
  RunOptions options;
  options.quiet = true;
  EXPECT_EQ(run_scenario_file(path, registry(), options, &result, err), 2) << "invalid input: nothing runs";
  EXPECT_EQ(result.checks, 0);
  std::fclose(err);
}

TEST(ScenarioReset, AResetOfACoordinatorByNameResetsEveryComponentItRuns) {
  const std::string dir = std::filesystem::temp_directory_path() / ("safecass-reset-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/reset.json";
  std::ofstream(path) << R"({ "system": ")" << SAFECASS_SOURCE_DIR << R"(/tests/data/bad_scenarios/system/cell.json",
    "duration": 0.05,
    "steps": [
      { "at": 0.01, "sample": { "ARM.Force": 40 } },
      { "at": 0.01, "expect": { "ARM": "Error", "robot": "Error", "CART": "Error", "base": "Error" } },
      { "at": 0.02, "sample": { "ARM.Force": 45 } },
      { "at": 0.03, "reset": { "target": "robot", "reason": "operator" } },
      { "at": 0.03, "expect": { "ARM": "Normal", "robot": "Normal", "CART": "Normal", "SYSTEM": "Normal" } } ] })";
  std::FILE* err = std::tmpfile();
  RunResult result;
  RunOptions options;
  options.quiet = true;
  const int code = run_scenario_file(path, registry(), options, &result, err);
  std::rewind(err);
  char buf[4096] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, err);
  std::fclose(err);
  EXPECT_EQ(code, 0) << std::string(buf, n);
  EXPECT_EQ(result.checks, 8);
  EXPECT_TRUE(result.failures.empty());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace safecass::runner
