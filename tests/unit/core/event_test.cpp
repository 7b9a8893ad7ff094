// DESIGN §2.3: event definitions (onset vs completion, severity, `completes`, `latched`, names)
// and the onset-level rule.

#include <gtest/gtest.h>

#include <string>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/event.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

using test::completion;
using test::Gcm;
using test::kFromError;
using test::kFromWarning;
using test::kToError;
using test::kToWarning;
using test::onset;

using test::E;
using test::N;
using test::N2E;
using test::N2W;
using test::W;
using test::W2E;

// ---- the onset-level rule, exhaustively ---------------------------------------------------------

// Written out by hand from DESIGN §2.3: "from N, E if N2E is listed else W; from W, E if W2E is
// listed; otherwise the highest level its transitions reach" (N2W reaches W, N2E and W2E reach E).
// {W2E} from Normal: N2E is not listed, so Warning (docs/semantics.md, Decision D12).
struct LevelRow {
  const char* name;
  TransitionSet transitions;
  State from_normal;
  State from_warning;
  State from_error;
};
const LevelRow kLevelTable[] = {
    //  transitions                       from N  from W  from E
    {"N2W", {N2W}, W, W, W},
    {"N2E", {N2E}, E, E, E},
    {"W2E", {W2E}, W, E, E},
    {"N2W,N2E", {N2W, N2E}, E, E, E},
    {"N2W,W2E", {N2W, W2E}, W, E, E},
    {"N2E,W2E", {N2E, W2E}, E, E, E},
    {"N2W,N2E,W2E", {N2W, N2E, W2E}, E, E, E},
};

TEST(OnsetLevel, MatchesTheDesignTableForEverySubsetOfWorseningTransitionsInEveryState) {
  int cases = 0;
  for (const LevelRow& row : kLevelTable) {
    EXPECT_EQ(onset_level(row.transitions, N), row.from_normal) << row.name << " from Normal";
    EXPECT_EQ(onset_level(row.transitions, W), row.from_warning) << row.name << " from Warning";
    EXPECT_EQ(onset_level(row.transitions, E), row.from_error) << row.name << " from Error";
    cases += 3;
  }
  EXPECT_EQ(cases, 21);
}

TEST(OnsetLevel, TheTableCoversEveryNonEmptySubsetOfWorseningTransitionsExactlyOnce) {
  unsigned seen = 0;
  for (const LevelRow& row : kLevelTable) {
    ASSERT_TRUE(row.transitions.worsening_only()) << row.name;
    const unsigned bit = 1u << row.transitions.bits();
    EXPECT_EQ(seen & bit, 0u) << row.name << " listed twice";
    seen |= bit;
  }
  // Bits 1..7 (the seven non-empty subsets of {N2W, N2E, W2E}).
  EXPECT_EQ(seen, 0b11111110u);
}

TEST(OnsetLevel, AnOnsetAlwaysReachesAtLeastWarning) {
  for (const LevelRow& row : kLevelTable) {
    for (State s : {N, W, E}) EXPECT_GE(onset_level(row.transitions, s), W) << row.name;
  }
}

TEST(OnsetLevel, IsUsableInConstantExpressions) {
  static_assert(onset_level(TransitionSet{N2W, W2E}, State::Warning) == State::Error);
  static_assert(onset_level(TransitionSet{N2W, W2E}, State::Normal) == State::Warning);
  SUCCEED();
}

// ---- definitions --------------------------------------------------------------------------------

TEST(EventDefinition, WorseningTransitionsOnlyMakeAnOnset) {
  Gcm g;
  const EventId id = g.event(onset("EVT_A", 10, {N2W, N2E, W2E}));
  EXPECT_TRUE(g.co.structure().event(id).is_onset);
  EXPECT_EQ(g.co.structure().event(id).name, "EVT_A");
  EXPECT_EQ(g.co.structure().event(id).severity, 10);
  EXPECT_EQ(g.co.structure().event(id).transitions, (TransitionSet{N2W, N2E, W2E}));
}

TEST(EventDefinition, ImprovingTransitionsOnlyMakeACompletion) {
  Gcm g;
  g.event(onset("EVT_A", 10, kToError));
  const EventId id = g.event(completion("/EVT_A", 10, {Transition::W2N, Transition::E2N, Transition::E2W}));
  EXPECT_FALSE(g.co.structure().event(id).is_onset);
}

TEST(EventDefinition, MixingWorseningAndImprovingTransitionsIsAnError) {
  Gcm g;
  for (Transition worse : {N2W, N2E, W2E}) {
    for (Transition better : {Transition::W2N, Transition::E2N, Transition::E2W}) {
      const std::size_t before = g.co.structure().event_count();
      const auto r = g.co.add_event(onset("EVT_MIXED", 10, {worse, better}));
      ASSERT_FALSE(r) << to_string(worse) << "+" << to_string(better);
      EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
      EXPECT_NE(r.error().message.find("EVT_MIXED"), std::string::npos) << r.error().message;
      EXPECT_NE(r.error().message.find("mixes"), std::string::npos) << r.error().message;
      EXPECT_EQ(g.co.structure().event_count(), before);
    }
  }
  EXPECT_FALSE(g.co.structure().find_event("EVT_MIXED"));
}

TEST(EventDefinition, AnEmptyTransitionListIsAnError) {
  Gcm g;
  const auto r = g.co.add_event(onset("EVT_NOTHING", 10, {}));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("EVT_NOTHING"), std::string::npos);
}

TEST(EventDefinition, SeverityOutsideOneTo255IsAnError) {
  Gcm g;
  for (int severity : {0, 256, -1, 1000, -255}) {
    const std::size_t before = g.co.structure().event_count();
    const auto r = g.co.add_event(onset("EVT_S", severity, kToError));
    ASSERT_FALSE(r) << severity;
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(r.error().message.find("EVT_S"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(std::to_string(severity)), std::string::npos) << r.error().message;
    EXPECT_EQ(g.co.structure().event_count(), before);
  }
}

TEST(EventDefinition, SeverityBoundsOneAnd255AreAccepted) {
  Gcm g;
  EXPECT_EQ(g.co.structure().event(g.event(onset("EVT_LOW", 1, kToError))).severity, 1);
  EXPECT_EQ(g.co.structure().event(g.event(onset("EVT_HIGH", 255, kToError))).severity, 255);
}

TEST(EventDefinition, Severities251To255AreBroadcastsAndBelowAreNot) {
  Gcm g;
  for (int s : {1, 200, 201, 250}) {
    EXPECT_FALSE(g.co.structure().event(g.event(onset("EVT_" + std::to_string(s), s, kToError))).is_broadcast()) << s;
  }
  for (int s : {251, 255}) {
    EXPECT_TRUE(g.co.structure().event(g.event(onset("EVT_" + std::to_string(s), s, kToError))).is_broadcast()) << s;
  }
}

TEST(EventDefinition, CompletionNamedSlashXCompletesXByDefault) {
  Gcm g;
  const EventId on = g.event(onset("EVT_FORCE", 50, kToError));
  const EventId off = g.event(completion("/EVT_FORCE", 50, kFromError));
  EXPECT_EQ(g.co.structure().event(off).completes, "EVT_FORCE");
  EXPECT_EQ(g.co.structure().event(off).counterpart, on);
  EXPECT_EQ(g.co.structure().event(on).counterpart, off);
}

TEST(EventDefinition, ExplicitCompletesNamesTheOnsetItClears) {
  Gcm g;
  const EventId on = g.event(onset("EVT_TOO_HOT", 50, kToError));
  const EventId off = g.event(completion("EVT_COOLED_DOWN", 50, kFromError, "EVT_TOO_HOT"));
  EXPECT_FALSE(g.co.structure().event(off).is_onset);
  EXPECT_EQ(g.co.structure().event(off).completes, "EVT_TOO_HOT");
  EXPECT_EQ(g.co.structure().event(off).counterpart, on);
  EXPECT_EQ(g.co.structure().event(on).counterpart, off);
  // And it clears it.
  g.component("C");
  g.gen("EVT_TOO_HOT", "C.s_A");
  EXPECT_EQ(g.at("C.s_A"), State::Error);
  g.gen("EVT_COOLED_DOWN", "C.s_A");
  EXPECT_EQ(g.at("C.s_A"), State::Normal);
}

TEST(EventDefinition, ExplicitCompletesWinsOverTheSlashName) {
  Gcm g;
  const EventId a = g.event(onset("EVT_A", 50, kToError));
  g.event(onset("EVT_B", 50, kToError));
  const EventId off = g.event(completion("/EVT_B", 50, kFromError, "EVT_A"));
  EXPECT_EQ(g.co.structure().event(off).completes, "EVT_A");
  EXPECT_EQ(g.co.structure().event(off).counterpart, a);
}

TEST(EventDefinition, CompletionMayBeDefinedBeforeItsOnset) {
  Gcm g;
  const EventId off = g.event(completion("/EVT_LATE", 50, kFromError));
  EXPECT_EQ(g.co.structure().event(off).counterpart, kNoEvent);
  const EventId on = g.event(onset("EVT_LATE", 50, kToError));
  EXPECT_EQ(g.co.structure().event(off).counterpart, on);
  EXPECT_EQ(g.co.structure().event(on).counterpart, off);
  g.component("C");
  g.gen("EVT_LATE", "C.s_A");
  g.gen("/EVT_LATE", "C.s_A");
  EXPECT_EQ(g.at("C.s_A"), State::Normal);
}

TEST(EventDefinition, ExplicitCompletionMayBeDefinedBeforeItsOnset) {
  Gcm g;
  const EventId off = g.event(completion("EVT_OK", 50, kFromError, "EVT_LATER"));
  const EventId on = g.event(onset("EVT_LATER", 50, kToError));
  EXPECT_EQ(g.co.structure().event(off).counterpart, on);
  EXPECT_EQ(g.co.structure().event(on).counterpart, off);
}

TEST(EventDefinition, GeneratingACompletionWhoseOnsetWasNeverDefinedIsAnError) {
  Gcm g;
  g.component("C");
  g.event(completion("/EVT_GHOST", 50, kFromError));
  const auto r = generate(g.co, "/EVT_GHOST", "C.s_A");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidState);
  EXPECT_NE(r.error().message.find("EVT_GHOST"), std::string::npos);
}

TEST(EventDefinition, ACompletionWithoutSlashNameOrCompletesIsAnError) {
  Gcm g;
  const auto r = g.co.add_event(completion("EVT_CLEAR", 50, kFromError));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("EVT_CLEAR"), std::string::npos);
  const auto slash_only = g.co.add_event(completion("/", 50, kFromError));
  EXPECT_FALSE(slash_only);
}

TEST(EventDefinition, ACompletionCannotCompleteAnotherCompletion) {
  Gcm g;
  g.pair("EVT_A", 50, State::Error);
  const auto r = g.co.add_event(completion("//EVT_A", 50, kFromError));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("not an onset"), std::string::npos) << r.error().message;
}

TEST(EventDefinition, AnOnsetCannotSayWhatItCompletes) {
  Gcm g;
  EventDef d = onset("EVT_A", 50, kToError);
  d.completes = "EVT_B";
  const auto r = g.co.add_event(d);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("EVT_A"), std::string::npos);
}

TEST(EventDefinition, LatchedIsAllowedOnOnsets) {
  Gcm g;
  EXPECT_TRUE(g.co.structure().event(g.event(onset("EVT_L", 50, kToError, true))).latched);
  EXPECT_FALSE(g.co.structure().event(g.event(onset("EVT_U", 50, kToError, false))).latched);
}

TEST(EventDefinition, LatchedOnACompletionIsAnError) {
  Gcm g;
  g.event(onset("EVT_L", 50, kToError));
  EventDef d = completion("/EVT_L", 50, kFromError);
  d.latched = true;
  const std::size_t before = g.co.structure().event_count();
  const auto r = g.co.add_event(d);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("/EVT_L"), std::string::npos);
  EXPECT_NE(r.error().message.find("latched"), std::string::npos);
  EXPECT_EQ(g.co.structure().event_count(), before);
}

TEST(EventDefinition, DuplicateNamesAreAnErrorAndKeepTheFirstDefinition) {
  Gcm g;
  const EventId first = g.event(onset("EVT_DUP", 50, kToError));
  const std::size_t before = g.co.structure().event_count();
  for (const EventDef& again : {onset("EVT_DUP", 60, kToWarning), completion("EVT_DUP", 50, kFromError, "EVT_X")}) {
    const auto r = g.co.add_event(again);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::Duplicate);
    EXPECT_NE(r.error().message.find("EVT_DUP"), std::string::npos);
  }
  EXPECT_EQ(g.co.structure().event_count(), before);
  EXPECT_EQ(g.co.structure().event(first).severity, 50);
  EXPECT_EQ(g.id("EVT_DUP"), first);
}

TEST(EventDefinition, FrameworkEventNamesAreTakenAlready) {
  Gcm g;
  const auto r = g.co.add_event(onset("EVT_SERVICE_FAILURE", 10, kToError));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Duplicate);
}

TEST(EventDefinition, AnEventNeedsAName) {
  Gcm g;
  const auto r = g.co.add_event(onset("", 10, kToError));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
}

TEST(EventDefinition, HazardAndDescriptionAreKept) {
  Gcm g;
  EventDef d = onset("EVT_FORCE", 50, kToError, false, "H-3");
  d.description = "force above the limit";
  const EventId id = g.event(d);
  EXPECT_EQ(g.co.structure().event(id).hazard, "H-3");
  EXPECT_EQ(g.co.structure().event(id).description, "force above the limit");
}

TEST(EventDefinition, UnknownEventNamesAreNotFound) {
  Gcm g;
  const auto r = g.co.structure().find_event("EVT_NOPE");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_NE(r.error().message.find("EVT_NOPE"), std::string::npos);
}

TEST(EventDefinition, TheLevelOfAnOnsetDependsOnTheStateItIsProcessedIn) {
  // EVT_ESC lists N2W and W2E: a warning from Normal, an error once the machine is in Warning.
  Gcm g;
  g.component("C");
  g.event(onset("EVT_ESC", 50, {N2W, W2E}));
  g.pair("EVT_W", 10, State::Warning);
  g.gen("EVT_ESC", "C.s_A");
  EXPECT_EQ(g.at("C.s_A"), State::Warning);

  Gcm h;
  h.component("C");
  h.event(onset("EVT_ESC", 50, {N2W, W2E}));
  h.pair("EVT_W", 10, State::Warning);
  h.gen("EVT_W", "C.s_A");
  h.gen("EVT_ESC", "C.s_A");
  EXPECT_EQ(h.at("C.s_A"), State::Error);
}

}  // namespace
}  // namespace safecass
