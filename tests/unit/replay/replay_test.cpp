// `safecass replay`: a CSV log and a recording replay through a system and print its transitions
// as `run` does; every bad log is refused with where and why and nothing runs (golden diagnostics,
// tests/data/replay/*.expected); --diff names the intervals where two systems' states differ.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/native/system.hpp"
#include "safecass/record/input_log.hpp"
#include "safecass/record/input_recorder.hpp"
#include "safecass/replay/replay.hpp"
#include "safecass/runner/scenario_runner.hpp"

namespace safecass::replay {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

const std::string kData = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/replay/";
const std::string kRobodoc = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/";

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string scratch(const std::string& name) { return ::testing::TempDir() + "safecass_replay_" + name; }

struct Ran {
  int code = 0;
  std::string out;
  std::string err;
};

std::string drain(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}

Ran replay(ReplayOptions o, const std::string& diff_b = "") {
  FilterRegistry registry;
  register_builtin_filters(registry);
  o.out = std::tmpfile();
  o.err = std::tmpfile();
  Ran r;
  r.code = diff_b.empty() ? run_replay(o, registry) : run_replay_diff(diff_b, o, registry);
  r.out = drain(o.out);
  r.err = drain(o.err);
  return r;
}

ReplayOptions options(const std::string& system, const std::string& input) {
  ReplayOptions o;
  o.system = system;
  o.input = input;
  return o;
}

TEST(ReplayCsv, ACsvLogReplaysThroughTheSystemAndPrintsItsTransitionsWithCauses) {
  const Ran r = replay(options(kData + "arm.json", kData + "arm_ok.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "t=0.003000  ARM.s_A  Normal -> Error  EVT_FORCE_ERROR  [filter force_limit, ARM.ForceNorm = 35]\n"
            "t=0.005000  ARM.s_A  Error -> Normal  /EVT_FORCE_ERROR  <- ARM.s_A:EVT_FORCE_ERROR  [filter force_limit, "
            "ARM.ForceNorm = 35]\n");
  // Rows hold 2, 1, 2, 1, 1, 2 and 1 samples: an empty cell is no sample.
  EXPECT_THAT(r.err, HasSubstr("replayed 10 samples and 0 actions"));
}

TEST(ReplayCsv, ReplayingFromAndToFeedsOnlyTheWindow) {
  ReplayOptions o = options(kData + "arm.json", kData + "arm_ok.csv");
  o.from = 0.004;
  const Ran r = replay(o);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("t=0.004000  ARM.s_A  Normal -> Error"));
  o.from.reset();
  o.to = 0.002;
  const Ran early = replay(o);
  ASSERT_EQ(early.code, 0) << early.err;
  EXPECT_EQ(early.out, "");
}

// Found by the csv fuzz target (its time property assumed times of zero or more): field data may
// start before zero (a pre-trigger window); such rows replay in their order, from their first time.
TEST(ReplayCsv, RowsBeforeTimeZeroReplayInOrderFromTheFirstRowsTime) {
  const std::string path = ::testing::TempDir() + "safecass-negative-times-" + std::to_string(::getpid()) + ".csv";
  std::ofstream(path) << "time,ARM.Temperature\n-01,20\n0,10\n1,22\n";
  const Ran r = replay(options(kData + "arm.json", path));
  std::remove(path.c_str());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("replayed 3 samples and 0 actions"));
  EXPECT_THAT(r.err, HasSubstr("-1.000000 s to 1.000000 s"));
}

TEST(ReplayCoverage, ReplaySaysWhenEachHazardWasUncoveredAndWhy) {
  // The force stops at 0.004 s: once the Watchdog fires, the force limit reads a stale norm and
  // H-1 cannot be detected until the end of the log.
  ReplayOptions o = options(kData + "arm_watched.json", kData + "arm_silent.csv");
  o.coverage = true;
  const Ran r = replay(o);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("ARM.s_F  Normal -> Warning  EVT_FORCE_STALE")) << r.out;
  EXPECT_THAT(r.out, HasSubstr("coverage: hazard H-1 uncovered 0.007000 .. 0.010000 (the end) s: EVT_FORCE_ERROR: "
                               "filter force_limit reads ARM.ForceNorm, which is stale\n"))
      << r.out;
  o.json = true;
  const Ran json = replay(o);
  ASSERT_EQ(json.code, 0) << json.err;
  EXPECT_THAT(json.out, HasSubstr(R"({"kind":"uncovered","hazard":"H-1","from":0.007000,"to":null,)")) << json.out;

  // Without a hazard, the replay says there was nothing to judge.
  ReplayOptions plain = options(kData + "arm.json", kData + "arm_ok.csv");
  plain.coverage = true;
  EXPECT_THAT(replay(plain).out, HasSubstr("coverage: no onset names a hazard\n"));
}

class BadCsv : public ::testing::TestWithParam<const char*> {};

TEST_P(BadCsv, IsRefusedWithWhereAndWhyAndNothingRuns) {
  const std::string file = kData + GetParam();
  ReplayOptions o = options(kData + "arm.json", file);
  o.record = scratch(std::string(GetParam()) + ".jsonl");
  std::remove(o.record.c_str());
  const Ran r = replay(o);
  EXPECT_EQ(r.code, 2);
  std::string expected = read_text(file + ".expected");
  expected.replace(expected.find("{file}"), 6, file);
  EXPECT_EQ(r.err, expected);
  EXPECT_EQ(r.out, "") << "nothing ran";
  EXPECT_FALSE(std::ifstream(o.record).good()) << "nothing was written";
}

INSTANTIATE_TEST_SUITE_P(GoldenDiagnostics, BadCsv,
                         ::testing::Values("missing_time.csv", "missing_element.csv", "unknown_signal.csv",
                                           "computed_signal.csv", "non_monotonic.csv", "malformed_number.csv",
                                           "extra_cell.csv", "partial_vector.csv", "not_finite.csv",
                                           "time_out_of_range.csv"),
                         [](const auto& param_info) {
                           std::string n = param_info.param;
                           return n.substr(0, n.find('.'));
                         });

/// The story of the demo, run with its inputs recorded.
std::string record_story(const std::string& name, std::string* printed = nullptr) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  runner::RunOptions o;
  o.record_path = scratch(name + ".jsonl");
  std::FILE* out = std::tmpfile();
  o.out = out;
  runner::RunResult result;
  EXPECT_EQ(runner::run_scenario_file(kRobodoc + "story.json", registry, o, &result), 0);
  const std::string text = drain(out);
  if (printed != nullptr) *printed = text;
  return scratch(name + ".inputs");
}

TEST(ReplayRecording, TheRecordingOfARunReplaysToTheSameTransitionsAndTheSameHistoryByteForByte) {
  std::string printed;
  const std::string inputs = record_story("story", &printed);
  ReplayOptions o = options(kRobodoc + "robodoc.json", inputs);
  o.record = scratch("story-replay.jsonl");
  o.record_inputs = scratch("story-replay.inputs");
  const Ran r = replay(o);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("JR3.s_A  Warning -> Error"));
  EXPECT_EQ(r.out, printed);
  EXPECT_EQ(read_text(o.record), read_text(scratch("story.jsonl"))) << "the histories differ";
  EXPECT_EQ(read_text(o.record_inputs), read_text(inputs)) << "the replay's own recording differs";
}

/// Counts what a LocalQuery tells its observer.
struct CountedWrites final : introspect::ActionObserver {
  std::vector<std::string> told;
  void applied(const introspect::Action& a, Time) override {
    const auto* target = std::get_if<introspect::GenerateEvent>(&a);
    const auto* reset = std::get_if<introspect::ResetState>(&a);
    told.push_back(std::string(introspect::action_name(a)) +
                   (target != nullptr ? " " + target->event + " " + target->target : "") +
                   (reset != nullptr ? " " + reset->target : ""));
  }
};

TEST(ReadModelWrites, OnlyAWriteThatWasAppliedIsToldToTheActionObserver) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto system = native::open_system(kRobodoc + "robodoc.json", registry);
  ASSERT_TRUE(system.has_value());
  CountedWrites observer;
  introspect::LocalOptions lo;
  lo.actions = &observer;
  introspect::LocalQuery query((*system)->coordinator(), (*system)->monitor(), registry, lo);
  EXPECT_FALSE(query.apply(introspect::GenerateEvent{"EVT_NO_SUCH_EVENT", "JR3.s_A"}).has_value());
  EXPECT_FALSE(query.apply(introspect::InjectShallow{"no_such_filter", {{1.0}}}).has_value());
  EXPECT_FALSE(query.apply(introspect::InjectDeep{"JR3.NoSuchSignal", {{1.0}}}).has_value());
  EXPECT_TRUE(observer.told.empty()) << "refused writes were told: " << observer.told.size();
  ASSERT_TRUE(query.apply(introspect::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"}).has_value());
  ASSERT_TRUE(query.apply(introspect::ResetState{"JR3.s_A", "operator", "cleared"}).has_value());
  EXPECT_THAT(observer.told, ::testing::ElementsAre("generate EVT_FORCE_ERROR JR3.s_A", "reset JR3.s_A"));
}

TEST(ReplayRecording, AnOperatorsWritesThroughTheReadModelAreRecordedAsActionsAndReplayAtTheirTimes) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  const std::string path = scratch("operator.inputs");
  {
    auto system = native::open_system(kRobodoc + "robodoc.json", registry);
    ASSERT_TRUE(system.has_value());
    SimulatedClock& clock = *(*system)->simulated_clock();
    auto inputs = InputRecorder::open((*system)->monitor(), path);
    ASSERT_TRUE(inputs.has_value()) << inputs.error().message;
    introspect::LocalOptions lo;
    lo.actions = inputs->get();
    introspect::LocalQuery query((*system)->coordinator(), (*system)->monitor(), registry, lo);
    clock.set(std::chrono::milliseconds(250));
    ASSERT_TRUE(query.apply(introspect::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"}).has_value());
    EXPECT_FALSE(query.apply(introspect::GenerateEvent{"EVT_NO_SUCH_EVENT", "JR3.s_A"}).has_value());  // not recorded
    clock.set(std::chrono::milliseconds(500));
    ASSERT_TRUE(query.apply(introspect::GenerateEvent{"/EVT_FORCE_ERROR", "JR3.s_A"}).has_value());
    (*inputs)->close(std::chrono::milliseconds(600));
    EXPECT_EQ((*inputs)->status().actions, 2u);
  }
  const Ran r = replay(options(kRobodoc + "robodoc.json", path));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("t=0.250000  JR3.s_A  Normal -> Error  EVT_FORCE_ERROR"));
  EXPECT_THAT(r.out, HasSubstr("t=0.500000  JR3.s_A  Error -> Normal  /EVT_FORCE_ERROR"));
  EXPECT_THAT(r.err, HasSubstr("2 actions"));
}

TEST(ReplayRecording, AScenariosResetOfACoordinatorIsRecordedAsResetsOfItsComponentsAndReplays) {
  // A coordinator of the system file ("robot") is not an address of the in-process coordinator:
  // the runner applies (and records) a reset of each of its components, which a replay applies.
  const std::string scenario = scratch("reset-robot.json");
  std::ofstream(scenario)
      << "{ \"system\": \"" << kRobodoc << "robodoc.json\", \"period\": 0.001, \"duration\": 0.01,\n"
      << "  \"steps\": [\n"
      << "    { \"at\": 0.001, \"generate\": { \"event\": \"EVT_FORCE_ERROR\", \"target\": \"JR3.s_A\" } },\n"
      << "    { \"at\": 0.005, \"reset\": { \"target\": \"robot\", \"reason\": \"operator\" } } ] }\n";
  const std::string inputs = scratch("reset-robot.inputs");
  runner::RunOptions ro;
  ro.quiet = true;
  ro.inputs_path = inputs;
  runner::RunResult result;
  ASSERT_EQ(runner::run_scenario_file(scenario, builtin_filters(), ro, &result), 0);
  ASSERT_TRUE(result.inputs.has_value());
  EXPECT_EQ(result.inputs->actions, 5u) << "the generate and one reset of each of robot's 4 components";
  const Ran r = replay(options(kRobodoc + "robodoc.json", inputs));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("t=0.001000  JR3.s_A  Normal -> Error  EVT_FORCE_ERROR"));
  EXPECT_THAT(r.out, HasSubstr("t=0.005000  JR3.s_A  Error -> Normal"));
  EXPECT_THAT(r.err, HasSubstr("5 actions"));
}

TEST(ReplayCsv, ALogThatCannotBeReadIsAnIoErrorWithThePathAndReason) {
  const Ran r = replay(options(kData + "arm.json", kData + "no_such_log.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "cannot read log '" + kData + "no_such_log.csv': No such file or directory\n");
  EXPECT_EQ(r.out, "");
}

TEST(ReplayRecording, ATruncatedRecordingReplaysUpToItsLastWholeRecordAndSaysSo) {
  const std::string inputs = record_story("cut");
  std::string bytes = read_text(inputs);
  bytes.resize(bytes.size() * 2 / 3 + 1);
  const std::string cut = scratch("cut-short.inputs");
  std::ofstream(cut, std::ios::binary) << bytes;
  const Ran r = replay(options(kRobodoc + "robodoc.json", cut));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("note: " + cut + ": the recording ends inside a record"));
}

TEST(ReplayRecording, ARecordingOfSignalsTheSystemDoesNotHaveIsRefused) {
  const std::string inputs = record_story("other");
  const Ran r = replay(options(kData + "arm.json", inputs));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr(inputs + ": record "));
  EXPECT_THAT(r.err, HasSubstr("unknown signal 'JR3.Fx': the system has no such signal"));
  EXPECT_EQ(r.out, "");
}

TEST(ReplayDiff, ALowerForceLimitDiffersFromTheOriginalExactlyWhereTheForceIsBetweenTheTwoLimits) {
  const std::string inputs = record_story("diff");
  const Ran r = replay(options(kRobodoc + "robodoc.json", inputs), kData + "robodoc_low_limit.json");
  EXPECT_EQ(r.code, 1) << r.err;
  // The force ramps 5 → 40 N over 0.2..0.6 s and back over 0.6..1.0 s: above 27 N from 0.452 s,
  // above 30 N from 0.486 s; down to 28 N at 0.738 s (A clears), to 25 N at 0.772 s (B clears).
  EXPECT_THAT(r.out,
              HasSubstr("JR3.s_A\n"
                        "  0.452000 .. 0.486000 s  B Error, A Warning  first cause (B): JR3.s_A:EVT_FORCE_ERROR "
                        "[filter force_limit, JR3.ForceNorm = 27.05]\n"
                        "  0.738000 .. 0.772000 s  B Error, A Warning  first cause (B): JR3.s_A:EVT_FORCE_ERROR "));
  EXPECT_THAT(r.out, HasSubstr("CONTROL\n  0.452000 .. 0.486000 s  B Error, A Normal"));
  EXPECT_THAT(r.out, Not(HasSubstr("BMM")));
  EXPECT_THAT(r.out, HasSubstr("differ at "));
}

TEST(ReplayDiff, ASystemComparedWithItselfNeverDiffers) {
  const Ran r = replay(options(kData + "arm.json", kData + "arm_ok.csv"), kData + "arm.json");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("never differ"));
}

long peak_rss_kib() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

/// A log of `ticks` milliseconds of ARM.Force and ARM.Temperature, as a recording and as CSV.
void write_large_logs(int ticks, const std::string& recording, const std::string& csv) {
  std::ofstream rec(recording, std::ios::binary);
  std::FILE* c = std::fopen(csv.c_str(), "w");
  std::fprintf(c, "time,ARM.Force[0],ARM.Force[1],ARM.Force[2],ARM.Temperature\n");
  std::string out;
  InputLogHeader h;
  h.period = std::chrono::milliseconds(1);
  input_log::put_header(out, h);
  input_log::put_signal(out, 0, 3, "ARM.Force");
  input_log::put_signal(out, 1, 1, "ARM.Temperature");
  for (int t = 0; t < ticks; ++t) {
    const double force[3] = {0.0, 0.0, 10.0 + (t % 100) * 0.01};
    const double temperature = 20.0;
    input_log::put_time(out, std::chrono::milliseconds(t));
    input_log::put_sample(out, 0, force, 3);
    input_log::put_sample(out, 1, &temperature, 1);
    std::fprintf(c, "%.3f,0,0,%.2f,20\n", t * 0.001, force[2]);
    if (out.size() > (1 << 20)) {
      rec << out;
      out.clear();
    }
  }
  rec << out;
  std::fclose(c);
}

TEST(ReplayMemory, ALogIsStreamedMemoryStaysBoundedWhateverItsSize) {
  const std::string recording = scratch("large.inputs");
  const std::string csv = scratch("large.csv");
  write_large_logs(1000000, recording, csv);  // about 47 MB and 24 MB: 1000 s of log
  const Ran warm = replay(options(kData + "arm.json", kData + "arm_ok.csv"));
  ASSERT_EQ(warm.code, 0) << warm.err;
  const long before = peak_rss_kib();
  const Ran r = replay(options(kData + "arm.json", recording));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("replayed 2000000 samples"));
  const Ran c = replay(options(kData + "arm.json", csv));
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_THAT(c.err, HasSubstr("replayed 2000000 samples"));
  const long grown = peak_rss_kib() - before;
  // Loading either log whole would take tens of megabytes; streaming takes a few buffers.
  EXPECT_LT(grown, 8 * 1024) << "the peak resident size grew by " << grown << " KiB";
  std::remove(recording.c_str());
  std::remove(csv.c_str());
}

}  // namespace
}  // namespace safecass::replay
