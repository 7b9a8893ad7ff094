// `analyze now` (introspect/coverage.hpp, docs/analyze.md "At run time"): which hazards the
// running system cannot detect now, judged from its event list, filter list and lost coordinators;
// and the answer's text and JSON.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "safecass/introspect/coverage.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"

namespace safecass::introspect {
namespace {

using std::chrono::milliseconds;

EventRow onset(std::string name, std::string hazard) {
  EventRow e;
  e.name = std::move(name);
  e.onset = true;
  e.hazard = std::move(hazard);
  return e;
}

/// A filter that raises `raises` from `input`, enabled, sampled and not injected: it can detect.
FilterRow filter(std::string name, std::string raises, std::string input, std::string output = "") {
  FilterRow f;
  f.name = std::move(name);
  f.type = "Threshold";
  f.onset = std::move(raises);
  f.inputs = {{std::move(input), 1}};
  if (!output.empty()) f.outputs = {{std::move(output), 1}};
  f.last_sample = milliseconds(5);
  f.evaluations = 5;
  return f;
}

FilterRow watchdog(std::string name, std::string input, bool detected) {
  FilterRow f = filter(std::move(name), "EVT_STALE", std::move(input));
  f.type = "Watchdog";
  f.detected = detected;
  return f;
}

/// `filters` as the filters of one live process.
std::vector<ProcessFilters> here(std::vector<FilterRow> filters) {
  return {ProcessFilters{"robot", false, std::move(filters)}};
}

/// The reasons of `hazard`'s gaps, "ONSET: reason" each; "covered" when it has none.
std::string gaps_of(const CoverageNow& c, const std::string& hazard) {
  for (const HazardCoverage& h : c.hazards) {
    if (h.hazard != hazard) continue;
    if (h.covered()) return "covered";
    std::string out;
    for (const CoverageGap& g : h.gaps) out += (out.empty() ? "" : " | ") + g.onset + ": " + g.reason;
    return out;
  }
  return "no such hazard";
}

const std::vector<EventRow> kEvents = {onset("EVT_FORCE", "H1"), onset("EVT_TRACKING", "H1"), onset("EVT_BONE", "H2"),
                                       onset("EVT_UNLINKED", "")};

TEST(CoverageNow, AHazardIsCoveredWhileEachOfItsOnsetsHasAFilterThatCanDetect) {
  const auto c =
      coverage_now(kEvents,
                   here({filter("force_limit", "EVT_FORCE", "JR3.Force"),
                         filter("tracking", "EVT_TRACKING", "SERVO.error"), filter("bone", "EVT_BONE", "BMM.x")}),
                   {}, milliseconds(6));
  ASSERT_EQ(c.hazards.size(), 2U) << "one entry per hazard, none for an onset without one";
  EXPECT_EQ(c.hazards[0].onsets, (std::vector<std::string>{"EVT_FORCE", "EVT_TRACKING"}));
  EXPECT_EQ(gaps_of(c, "H1"), "covered");
  EXPECT_EQ(gaps_of(c, "H2"), "covered");
  EXPECT_EQ(c.uncovered(), 0U);
}

TEST(CoverageNow, AnOnsetWhoseOnlyFilterIsDisabledInjectedOrWithoutASampleLeavesItsHazardUncovered) {
  FilterRow disabled = filter("force_limit", "EVT_FORCE", "JR3.Force");
  disabled.enabled = false;
  FilterRow injected = filter("tracking", "EVT_TRACKING", "SERVO.error");
  injected.injected = true;
  FilterRow unsampled = filter("bone", "EVT_BONE", "BMM.x");
  unsampled.last_sample.reset();
  const auto c = coverage_now(kEvents, here({disabled, injected, unsampled}), {}, milliseconds(6));
  EXPECT_EQ(gaps_of(c, "H1"),
            "EVT_FORCE: filter force_limit is disabled | EVT_TRACKING: filter tracking judges injected samples");
  EXPECT_EQ(gaps_of(c, "H2"), "EVT_BONE: filter bone has judged no sample yet");
  EXPECT_EQ(c.uncovered(), 2U);
}

TEST(CoverageNow, AnOnsetStaysCoveredWhileOneOfItsFiltersCanStillDetect) {
  FilterRow disabled = filter("force_limit", "EVT_FORCE", "JR3.Force");
  disabled.enabled = false;
  const auto c = coverage_now({onset("EVT_FORCE", "H1")},
                              here({disabled, filter("force_backup", "EVT_FORCE", "JR3.Force")}), {}, milliseconds(6));
  EXPECT_EQ(gaps_of(c, "H1"), "covered");
}

TEST(CoverageNow, ASignalADetectedWatchdogWatchesBlindsItsReadersAndEveryFilterDownstreamOfThem) {
  // JR3.Force → mean (writes JR3.mean) → force_limit (EVT_FORCE); the watchdog sees JR3.Force stale.
  FilterRow mean = filter("mean", "", "JR3.Force", "JR3.mean");
  mean.type = "MovingAverage";
  const std::vector<FilterRow> filters = {watchdog("force_stale", "JR3.Force", true), mean,
                                          filter("force_limit", "EVT_FORCE", "JR3.mean")};
  EXPECT_EQ(stale_signals(filters), (std::vector<std::string>{"JR3.Force", "JR3.mean"}));
  const auto c = coverage_now({onset("EVT_FORCE", "H1"), onset("EVT_STALE", "H9")}, here(filters), {}, milliseconds(6));
  EXPECT_EQ(gaps_of(c, "H1"), "EVT_FORCE: filter force_limit reads JR3.mean, which is stale");
  EXPECT_EQ(gaps_of(c, "H9"), "covered") << "a Watchdog detects the absence of samples: staleness is what it sees";

  const std::vector<FilterRow> quiet = {watchdog("force_stale", "JR3.Force", false), mean,
                                        filter("force_limit", "EVT_FORCE", "JR3.mean")};
  EXPECT_TRUE(stale_signals(quiet).empty());
}

TEST(CoverageNow, AWatchdogWithoutASampleCanStillDetectButNotWhenDisabled) {
  FilterRow fresh = watchdog("force_stale", "JR3.Force", false);
  fresh.last_sample.reset();
  EXPECT_EQ(blind_reason(fresh, {}), "");
  fresh.enabled = false;
  EXPECT_EQ(blind_reason(fresh, {}), "filter force_stale is disabled");
}

TEST(CoverageNow, AFilterOfAProcessWhoseCoordinatorIsLostCannotDetect) {
  const std::vector<EventRow> events = {onset("EVT_FORCE", "H1"), onset("EVT_BONE", "H2")};
  const std::vector<ProcessFilters> processes = {
      ProcessFilters{"jr3", true, {filter("force_limit", "EVT_FORCE", "JR3.Force")}},
      ProcessFilters{"bmm", false, {filter("bone", "EVT_BONE", "BMM.x")}}};
  const auto c = coverage_now(events, processes, {}, milliseconds(6));
  EXPECT_EQ(gaps_of(c, "H1"), "EVT_FORCE: filter force_limit runs in jr3, whose coordinator is lost");
  EXPECT_EQ(gaps_of(c, "H2"), "covered");
}

TEST(CoverageNow, AnOnsetNoFilterHereRaisesIsUncoveredOnlyWhileACoordinatorIsLost) {
  const std::vector<EventRow> events = {onset("EVT_REMOTE", "H3")};
  EXPECT_EQ(gaps_of(coverage_now(events, {}, {}, milliseconds(6)), "H3"), "covered")
      << "raised by the component's code, or by a live process";
  EXPECT_EQ(gaps_of(coverage_now(events, {}, {"JR3", "SERVO"}, milliseconds(6)), "H3"),
            "EVT_REMOTE: no filter here raises it, and the coordinator of JR3, SERVO is lost");
}

CoverageNow one_uncovered() {
  CoverageNow c;
  c.now = milliseconds(1500);
  c.hazards = {HazardCoverage{"H1", {"EVT_FORCE", "EVT_TRACKING"}, {{"EVT_FORCE", "filter force_limit is disabled"}}},
               HazardCoverage{"H2", {"EVT_BONE"}, {}}};
  return c;
}

TEST(CoverageNowFormat, ItsTextNamesEachHazardAndEachGapAndCountsTheUncovered) {
  EXPECT_EQ(coverage_now_text(one_uncovered()),
            "hazard H1: UNCOVERED\n"
            "  EVT_FORCE: filter force_limit is disabled\n"
            "hazard H2: covered (EVT_BONE)\n"
            "2 hazards, 1 uncovered now\n");
  EXPECT_EQ(coverage_now_text(CoverageNow{}), "no onset names a hazard: nothing to judge\n");
}

TEST(CoverageNowFormat, ItsJsonIsOneLineThatReadsBackToTheSameValue) {
  const std::string json = coverage_now_json(one_uncovered());
  EXPECT_EQ(json, R"({"t":1.500000,"uncovered":1,"hazards":[{"hazard":"H1","covered":false,)"
                  R"("onsets":["EVT_FORCE","EVT_TRACKING"],"gaps":[{"onset":"EVT_FORCE",)"
                  R"("reason":"filter force_limit is disabled"}]},{"hazard":"H2","covered":true,)"
                  R"("onsets":["EVT_BONE"],"gaps":[]}]})"
                  "\n");
  auto back = coverage_now_from_json(json);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, one_uncovered());
  auto text = read_text("analyze now", json);
  ASSERT_TRUE(text) << text.error().message;
  EXPECT_EQ(*text, coverage_now_text(one_uncovered()));
}

// Found by the read_answer fuzz target: a time finer than the microsecond (written with six
// decimals) read back as another time once written again.
TEST(CoverageNowFormat, ATimeFinerThanAMicrosecondIsReadToTheMicrosecondSoItReadsBackTheSameWrittenAgain) {
  auto first = coverage_now_from_json(R"({"t":12.58888888888888888888,"uncovered":0,"hazards":[]})");
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_EQ(first->now, std::chrono::microseconds(12'588'889));
  auto again = coverage_now_from_json(coverage_now_json(*first));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(*again, *first);
  auto negative = coverage_now_from_json(R"({"t":-0.0000015,"uncovered":0,"hazards":[]})");
  ASSERT_TRUE(negative);
  EXPECT_EQ(negative->now, std::chrono::microseconds(-2)) << "half a microsecond rounds away from zero";
}

TEST(CoverageNowFormat, AnAnswerThatIsNotACoverageIsAParseErrorThatSaysSo) {
  for (const char* bad : {"", "[]", R"({"hazards":[]})", R"({"t":1,"hazards":[{"hazard":"H1","onsets":[]}]})",
                          R"({"t":1,"hazards":[{"hazard":"H1","onsets":[3],"gaps":[]}]})",
                          R"({"t":1,"hazards":[{"hazard":"H1","onsets":[],"gaps":[{"onset":"E"}]}]})"}) {
    auto parsed = coverage_now_from_json(bad);
    ASSERT_FALSE(parsed) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::Parse) << bad;
    EXPECT_NE(parsed.error().message.find("analyze now"), std::string::npos) << bad;
  }
}

TEST(CoverageNowFormat, AnAnswerWhoseTimeTheClockCannotHoldIsAParseError) {
  // Found while extending read_answer_fuzz to every named read: "t" of 1e300 s was converted to
  // nanoseconds with undefined behaviour (a double beyond 64 bits; float-cast-overflow).
  for (const char* bad : {R"({"t":1e300,"hazards":[]})", R"({"t":-5e9,"hazards":[]})"}) {
    auto parsed = coverage_now_from_json(bad);
    ASSERT_FALSE(parsed) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::Parse) << bad;
    EXPECT_EQ(parsed.error().message, "analyze now: t must be a time in seconds of at most 4e9 in magnitude") << bad;
  }
  auto edge = coverage_now_from_json(R"({"t":4e9,"hazards":[]})");
  ASSERT_TRUE(edge) << edge.error().message;
  EXPECT_EQ(edge->now, seconds_to_time(4e9));
}

}  // namespace
}  // namespace safecass::introspect
