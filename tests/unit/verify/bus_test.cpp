// `safecass verify --bus` (docs/verify.md "The bus"): the bus protocol's model, generated from the
// system file, meets P1-P5 on robodoc and on a second deployment; every mutant of a rule is caught
// by a property, with a trace as bus messages; bad options are refused with a reason.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/bus.hpp"
#include "verify_command.hpp"

namespace safecass::verify {
namespace {

using ::testing::HasSubstr;

spec::SystemSpec load_bus(const std::string& path) {
  spec::LoadResult r = spec::load_system(std::string(SAFECASS_SOURCE_DIR) + "/" + path, builtin_filters());
  EXPECT_TRUE(r.ok()) << path;
  return r.system ? *r.system : spec::SystemSpec{};
}

void expect_proved(const BusReport& r) {
  EXPECT_EQ(r.exit_code(), 0);
  ASSERT_EQ(r.properties.size(), 5u);
  for (const BusProperty& p : r.properties) {
    EXPECT_EQ(p.verdict, BusVerdict::Holds) << p.name;
    EXPECT_GT(p.states, 100'000u) << p.name << ": searched, not assumed";
  }
  for (const BusSearch& s : r.searches) {
    EXPECT_EQ(s.verdict, BusVerdict::Holds)
        << r.patterns[s.pattern].pairs.front() << " " << s.fault_class << ": " << s.property << s.detail;
  }
}

TEST(BusVerify, PatternsComeFromTheSystemFilesCoordinatorsConnectionsAndTheSupervisor) {
  auto patterns = bus_patterns(load_bus("examples/robodoc/robodoc.json"), BusOptions{});
  ASSERT_TRUE(patterns) << patterns.error().message;
  ASSERT_EQ(patterns->size(), 4u);
  EXPECT_THAT((*patterns)[0].pairs, ::testing::ElementsAre("robot -> ui"));
  EXPECT_EQ((*patterns)[0].streams, 1u) << "the ui holds CONTROL.Status of the robot";
  EXPECT_EQ((*patterns)[0].bound_ticks, 6) << "3 periods of 100 ms in ticks of 50 ms";
  EXPECT_THAT((*patterns)[1].pairs, ::testing::ElementsAre("robot -> supervisor"));
  EXPECT_EQ((*patterns)[1].streams_total, 4u) << "the supervisor holds every interface the robot provides";
  EXPECT_EQ((*patterns)[1].streams, 2u) << "two modelled: their interaction is what a third would add";
  EXPECT_EQ((*patterns)[1].bound_ticks, 12) << "the supervisor's 600 ms";
  EXPECT_THAT((*patterns)[3].pairs, ::testing::ElementsAre("supervisor -> robot", "supervisor -> ui"))
      << "pairs that differ in nothing the protocol reads are one pattern";
  EXPECT_TRUE((*patterns)[3].forget);
  EXPECT_EQ((*patterns)[3].loss_level, State::Warning) << "EVT_SUPERVISOR_LOST is a Warning";
  BusOptions alone;
  alone.supervisor = false;
  EXPECT_EQ(bus_patterns(load_bus("examples/robodoc/robodoc.json"), alone)->size(), 1u);
}

TEST(BusVerify, RobodocsDeploymentMeetsP1ToP5InEveryFaultClassExhaustively) {
  auto r = verify_bus(load_bus("examples/robodoc/robodoc.json"), BusOptions{});
  ASSERT_TRUE(r) << r.error().message;
  expect_proved(*r);
  EXPECT_EQ(r->searches.size(), 4u * 7u + 1u) << "seven classes per pattern, two streams for the supervisor's";
  for (const BusSearch& s : r->searches) EXPECT_LE(s.memory_mb, 1024.0) << s.fault_class;
}

TEST(BusVerify, ASecondDeploymentWithTwoStreamsBetweenCoordinatorsMeetsP1ToP5) {
  // Its one-stream classes are the very models of robodoc's robot -> ui (proved above; `verify
  // --bus` searches a model once): the two-stream class is what this deployment adds.
  BusOptions options;
  options.supervisor = false;
  options.fault_class = "two-streams";
  auto r = verify_bus(load_bus("tests/data/bus/cell.json"), options);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->patterns.size(), 2u);
  EXPECT_EQ(r->patterns[0].streams, 2u) << "sensing feeds control two interfaces";
  ASSERT_EQ(r->searches.size(), 1u) << "control -> hmi holds one stream: no two-stream search";
  EXPECT_EQ(r->searches.front().fault_class, "two-streams");
  expect_proved(*r);
}

/// The mutation table of docs/verify.md: each mutant, the fault class that exposes it and the
/// property that catches it. The searches stop at the depth-first search's violation, in about a
/// fifth of the time. One row also takes the breadth-first search for a shortest trail, as
/// `--mutants` does: its shortest trail breaks P5, where its depth-first one breaks P3, as the
/// table says.
struct MutantCase {
  const char* mutant;
  const char* fault_class;
  const char* property;
  bool shortest = false;
};

class BusMutants : public ::testing::TestWithParam<MutantCase> {};

TEST_P(BusMutants, EachWeakenedRuleIsCaughtByAPropertyWithATraceOfBusMessages) {
  const MutantCase& c = GetParam();
  BusOptions options;
  options.supervisor = false;
  options.mutant = c.mutant;
  options.fault_class = c.fault_class;
  options.shortest_trail = c.shortest;
  auto r = verify_bus(load_bus("examples/robodoc/robodoc.json"), options);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->exit_code(), 1);
  ASSERT_FALSE(r->searches.empty());
  const BusSearch& s = r->searches.front();
  EXPECT_EQ(s.verdict, BusVerdict::Violated);
  EXPECT_EQ(s.property, c.property);
  ASSERT_FALSE(s.trace.empty());
  EXPECT_THAT(s.trace.front(), HasSubstr(" ms: ")) << "each step says when";
  bool decision = false;
  for (const std::string& line : s.trace) decision = decision || line.find("-> ") != std::string::npos;
  EXPECT_TRUE(decision) << "the trace shows what the receiver decided of each message";
}

INSTANTIATE_TEST_SUITE_P(
    Table, BusMutants,
    ::testing::Values(MutantCase{"unproven-heartbeat", "restarts", "P2"},
                      MutantCase{"no-catch-up", "restarts", "P5", true}, MutantCase{"no-jump-limit", "members", "P3"},
                      MutantCase{"no-incarnation-bound", "members", "P5"},
                      MutantCase{"no-resubscribe", "unsubscribed", "P5"},
                      MutantCase{"no-renewal-while-lost", "unsubscribed", "P5"},
                      MutantCase{"no-ownership", "members", "P4"}, MutantCase{"no-reproof", "restarts", "P2"},
                      MutantCase{"arrival-time", "cut", "P1"}, MutantCase{"no-settle-hold", "settle", "P5"}),
    [](const ::testing::TestParamInfo<MutantCase>& param) {
      std::string n = param.param.mutant;
      for (char& ch : n) ch = ch == '-' ? '_' : ch;
      return n;
    });

TEST(BusVerify, EveryMutantOfTheModelIsInTheTable) {
  EXPECT_EQ(bus_mutants().size(), 10u) << "a new mutant needs its row in the table above and in docs/verify.md";
}

TEST(BusVerify, ALossBoundThatIsNotAWholeNumberOfHalfPeriodsIsRefusedWithTheReason) {
  BusOptions options;
  options.lost_after = std::chrono::milliseconds(275);
  auto r = bus_patterns(load_bus("examples/robodoc/robodoc.json"), options);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_THAT(r.error().message,
              HasSubstr("the coordinators' loss bound (275 ms) must be a whole number of half periods"));
  options.lost_after = std::chrono::milliseconds(5000);
  EXPECT_THAT(bus_patterns(load_bus("examples/robodoc/robodoc.json"), options).error().message,
              HasSubstr("must be between"));
}

TEST(BusVerify, AnUnknownMutantOrFaultClassIsAnErrorThatNamesTheKnownOnes) {
  BusOptions options;
  options.mutant = "no-such-rule";
  auto r = verify_bus(load_bus("examples/robodoc/robodoc.json"), options);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_THAT(r.error().message, HasSubstr("unproven-heartbeat"));
  options.mutant.clear();
  options.fault_class = "earthquake";
  EXPECT_EQ(verify_bus(load_bus("examples/robodoc/robodoc.json"), options).error().code, ErrorCode::NotFound);
}

TEST(BusVerify, AOneProcessSystemHasNoBusToCheckAndExitsZero) {
  testing::internal::CaptureStdout();
  const int code = tools::run_verify_bus(std::string(SAFECASS_SOURCE_DIR) + "/examples/force_sensor/force_sensor.json",
                                         BusOptions{}, false, false);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
  EXPECT_THAT(out, HasSubstr("no bus to check"));
}

}  // namespace
}  // namespace safecass::verify
