// The scenario runner (tools/runner): a history that cannot be written fails the run after the
// whole run, and a scenario built in C++ follows the injection rule of every path.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::runner {
namespace {

using ::testing::HasSubstr;

const std::string kForceSensor = std::string(SAFECASS_SOURCE_DIR) + "/examples/force_sensor/scenario.json";

/// What run_scenario_file() printed on its `err`.
struct Captured {
  char* text = nullptr;
  std::size_t size = 0;
  std::FILE* file = ::open_memstream(&text, &size);
  std::string str() {
    std::fflush(file);
    return std::string(text, size);
  }
  ~Captured() {
    std::fclose(file);
    std::free(text);
  }
};

TEST(ScenarioRunner, AHistoryThatCannotBeWrittenFailsTheRunAfterTheWholeRunAndSaysWhy) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  RunOptions options;
  options.quiet = true;
  options.record_path = "/dev/full";
  RunResult result;
  Captured err;
  const int code = run_scenario_file(kForceSensor, registry, options, &result, err.file);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(result.passed()) << "every expectation was still checked and met";
  EXPECT_EQ(result.checks, 10);
  ASSERT_TRUE(result.record.has_value());
  EXPECT_FALSE(result.history_complete());
  EXPECT_EQ(result.record->write_error, "No space left on device");
  EXPECT_GT(result.record->unwritten, 0u);
  EXPECT_THAT(err.str(), HasSubstr("history file '/dev/full': write error after 0 records: No space left on device"));
}

TEST(ScenarioRunner, ACompleteHistoryIsSaidCompleteAndChangesNothing) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  RunOptions options;
  options.quiet = true;
  options.record_path = ::testing::TempDir() + "/runner_history.jsonl";
  RunResult result;
  Captured err;
  EXPECT_EQ(run_scenario_file(kForceSensor, registry, options, &result, err.file), 0);
  ASSERT_TRUE(result.record.has_value());
  EXPECT_TRUE(result.history_complete());
  EXPECT_GT(result.record->written, 0u);
  EXPECT_EQ(err.str(), "");
  std::remove(options.record_path.c_str());
}

TEST(ScenarioRunner, AnInjectionOfANonFiniteValueBuiltInCppIsAnErrorAtItsStep) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  spec::ScenarioLoad load = spec::load_scenario(kForceSensor);
  ASSERT_TRUE(load.scenario);
  spec::LoadResult system = spec::load_system(load.scenario->system, registry);
  ASSERT_TRUE(system.ok());
  spec::ScenarioStep step;
  step.kind = spec::ScenarioStep::Kind::Inject;
  step.at = 0.5;
  auto action = std::make_shared<spec::StepAction>();
  action->filter = "force_limit";
  action->values = {{10.0}, {std::numeric_limits<double>::infinity()}};
  step.action = action;
  step.index = 9;
  step.line = 3;
  step.column = 7;
  load.scenario->steps.push_back(step);
  const std::string path = load.scenario->path;
  auto opened = ScenarioRunner::open(std::move(*load.scenario), std::move(*system.system), registry);
  ASSERT_FALSE(opened) << "a scenario with a bad step is not opened";
  const spec::Diagnostics& problems = opened.error();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(spec::format(problems[0]), path +
                                           ":3:7: error: an injected value is not a finite number: injected values "
                                           "must be finite [/steps/9/inject]");
}

}  // namespace
}  // namespace safecass::runner

namespace safecass::runner {
namespace {

/// A scenario of robodoc (period 1 ms, 10 ms) with `steps`, run by run_scenario_file(): its exit
/// code, what it printed on `err`, its result; the file is written under `name` and removed.
struct RobodocRun {
  std::string path;
  int code = 0;
  std::string err;
  RunResult result;
};
RobodocRun run_robodoc_steps(const std::string& name, const std::string& steps) {
  RobodocRun run;
  run.path = ::testing::TempDir() + name + "-" + std::to_string(::getpid()) + ".json";
  if (std::FILE* f = std::fopen(run.path.c_str(), "w"); f != nullptr) {
    std::fprintf(f,
                 "{ \"system\": \"%s/examples/robodoc/robodoc.json\", \"period\": 0.001, \"duration\": 0.01,\n"
                 "  \"steps\": [\n%s ] }\n",
                 SAFECASS_SOURCE_DIR, steps.c_str());
    std::fclose(f);
  }
  FilterRegistry registry;
  register_builtin_filters(registry);
  RunOptions options;
  options.quiet = true;
  Captured err;
  run.code = run_scenario_file(run.path, registry, options, &run.result, err.file);
  run.err = err.str();
  std::remove(run.path.c_str());
  return run;
}

TEST(ScenarioRunner, AResetOfAServiceStateIsRefusedAtLoadWithItsPlaceAndNothingRuns) {
  // A service state is derived (DESIGN §2.2): the coordinator and the console refuse to reset
  // one. The runner used to accept the step and then do nothing.
  const RobodocRun run = run_robodoc_steps(
      "reset-service",
      "    { \"at\": 0.0, \"reset\": { \"target\": \"JR3.s_S.ForceData\", \"reason\": \"operator\" } }");
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_THAT(run.err, HasSubstr(run.path + ":3:27: error: cannot reset service state 'JR3.s_S.ForceData': it is "
                                            "derived; reset its component or a machine [/steps/0/reset]"));
  EXPECT_EQ(run.result.checks, 0) << "nothing ran";
}

TEST(ScenarioRunner, ADeepInjectionOfMoreSamplesThanTheSignalHoldsIsRefusedAtItsStepAndNothingRuns) {
  // Found by the scenario format's documentation: the runner used to accept the step, and the
  // injection then refused it at its tick without a word: nothing injected, nothing recorded.
  std::string values = "1";
  for (int i = 1; i < 1025; ++i) values += ",1";
  const RobodocRun run = run_robodoc_steps(
      "deep-overflow",
      "    { \"at\": 0.0, \"inject\": { \"signal\": \"JR3.Fx\", \"deep\": true, \"values\": [" + values + "] } }");
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_THAT(run.err, HasSubstr(run.path + ":3:28: error: deep injection into signal JR3.Fx: 1025 samples would "
                                            "overflow its history (1023 samples): inject fewer at once "
                                            "[/steps/0/inject]"));
  EXPECT_EQ(run.result.checks, 0) << "nothing ran";
}

}  // namespace
}  // namespace safecass::runner
