// DESIGN §2.4: processing an event on a state machine with a set of active conditions — refresh,
// raise, override, join, mask, completion, latching, reset — and the history/observer records.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
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
using test::W;

/// One component C with a catalogue of onsets (name = level + severity) and their completions.
struct Machine : Gcm {
  explicit Machine(CoordinatorOptions options = {}) : Gcm(options) {
    component("C", {"p"}, {"r"});
    component("D");
    pair("W10", 10, W);
    pair("W20", 20, W);
    pair("W200", 200, W);
    pair("E50", 50, E);
    pair("E80", 80, E);
    pair("E80B", 80, E);
    pair("LATCH", 60, E, true);
    pair("LATCHW", 30, W, true);
  }
  Record last_event(std::string_view address = "C.s_A") const {
    const auto records = event_records(address);
    if (records.empty()) {
      ADD_FAILURE() << "no event record on " << address;
      return {};
    }
    return records.back();
  }
  std::size_t transitions(std::string_view address = "C.s_A") const {
    return records_of_kind(address, RecordKind::Transition).size();
  }
  std::vector<Record> stream;
  void observe() {
    co.subscribe([this](const Record& r) { stream.push_back(r); });
  }
};

// ---- onsets ---------------------------------------------------------------------------------------

TEST(ConditionSet, EveryMachineStartsNormalWithoutConditions) {
  Machine m;
  for (const char* a : {"C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r", "D.s_F", "D.s_A"}) {
    EXPECT_EQ(m.at(a), N) << a;
    EXPECT_TRUE(m.co.conditions(m.machine(a)).empty()) << a;
    EXPECT_EQ(m.co.snapshot(m.machine(a)).outstanding, kNoEvent) << a;
    EXPECT_FALSE(m.co.outstanding(m.machine(a)).has_value()) << a;
  }
}

TEST(ConditionSet, RepeatedOnsetRefreshesCountAndLastTimeWithoutNewHistory) {
  Machine m;
  m.observe();
  m.clock.set(seconds_to_time(1.0));
  m.gen("E50", "C.s_A");
  const std::size_t history = m.history("C.s_A").size();
  const std::size_t streamed = m.stream.size();
  m.clock.set(seconds_to_time(2.0));
  m.gen("E50", "C.s_A");
  m.clock.set(seconds_to_time(3.5));
  m.gen("E50", "C.s_A");

  const auto conditions = m.co.conditions(m.machine("C.s_A"));
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].count, 3u);
  EXPECT_EQ(conditions[0].first, seconds_to_time(1.0));
  EXPECT_EQ(conditions[0].last, seconds_to_time(3.5));
  EXPECT_EQ(conditions[0].root.time, seconds_to_time(1.0)) << "the root cause is the first onset";
  EXPECT_EQ(m.history("C.s_A").size(), history) << "a refresh must not flood the history";
  EXPECT_EQ(m.stream.size(), streamed) << "a refresh is not on the observer stream";
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.transitions(), 1u);
}

TEST(ConditionSet, RefreshOfAnOnsetMaskedBelowTheStateDoesNotChangeTheState) {
  Machine m;
  m.gen("E50", "C.s_A");
  m.gen("W20", "C.s_A");
  const std::size_t history = m.history("C.s_A").size();
  m.gen("W20", "C.s_A");
  EXPECT_EQ(m.history("C.s_A").size(), history);
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.outstanding("C.s_A"), "E50");
}

TEST(ConditionSet, HigherLevelOnsetTransitionsAndBecomesOutstanding) {
  Machine m;
  m.gen("W20", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), W);
  EXPECT_EQ(m.outstanding("C.s_A"), "W20");
  Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Raised);
  EXPECT_EQ(r.from, N);
  EXPECT_EQ(r.to, W);

  m.gen("E50", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.outstanding("C.s_A"), "E50");
  EXPECT_EQ(m.co.snapshot(m.machine("C.s_A")).outstanding, m.id("E50"));
  r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Raised);
  EXPECT_EQ(r.event, m.id("E50"));
  EXPECT_EQ(r.from, W);
  EXPECT_EQ(r.to, E);
  EXPECT_EQ(r.level, E);
  EXPECT_EQ(r.severity, 50);

  const auto ts = m.records_of_kind("C.s_A", RecordKind::Transition);
  ASSERT_EQ(ts.size(), 2u);
  EXPECT_EQ(ts[0].from, N);
  EXPECT_EQ(ts[0].to, W);
  EXPECT_EQ(ts[1].from, W);
  EXPECT_EQ(ts[1].to, E);
  EXPECT_EQ(ts[1].event, m.id("E50"));
  EXPECT_EQ(m.co.conditions(m.machine("C.s_A")).size(), 2u) << "the warning stays active underneath";
}

TEST(ConditionSet, SameLevelOnsetWithHigherOrEqualSeverityOverridesOutstanding) {
  Machine m;
  m.gen("E50", "C.s_A");
  m.gen("E80", "C.s_A");
  EXPECT_EQ(m.last_event().outcome, Outcome::Override);
  EXPECT_EQ(m.outstanding("C.s_A"), "E80");
  m.gen("E80B", "C.s_A");  // equal severity: overrides too
  EXPECT_EQ(m.last_event().outcome, Outcome::Override);
  EXPECT_EQ(m.last_event().from, E);
  EXPECT_EQ(m.last_event().to, E);
  EXPECT_EQ(m.outstanding("C.s_A"), "E80B");
  EXPECT_EQ(m.co.snapshot(m.machine("C.s_A")).outstanding, m.id("E80B"));
  EXPECT_EQ(m.transitions(), 1u) << "an override is not a transition";
  EXPECT_EQ(m.co.conditions(m.machine("C.s_A")).size(), 3u);
}

TEST(ConditionSet, SameLevelOnsetWithLowerSeverityJoinsWithoutOverride) {
  Machine m;
  m.gen("E80", "C.s_A");
  m.gen("E50", "C.s_A");
  EXPECT_EQ(m.last_event().outcome, Outcome::Joined);
  EXPECT_EQ(m.last_event().event, m.id("E50"));
  EXPECT_EQ(m.outstanding("C.s_A"), "E80");
  EXPECT_EQ(m.co.conditions(m.machine("C.s_A")).size(), 2u);
  EXPECT_EQ(m.transitions(), 1u);
}

TEST(ConditionSet, LowerLevelOnsetIsMaskedAndRecorded) {
  Machine m;
  m.gen("E50", "C.s_A");
  m.gen("W200", "C.s_A");  // a warning, even of higher severity, is below Error
  const Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Masked);
  EXPECT_EQ(r.event, m.id("W200"));
  EXPECT_EQ(r.level, W);
  EXPECT_EQ(r.from, E);
  EXPECT_EQ(r.to, E);
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.outstanding("C.s_A"), "E50");
  EXPECT_EQ(m.transitions(), 1u);
  // Masked is not forgotten: the warning is an active condition (a worsening is never ignored).
  const auto conditions = m.co.conditions(m.machine("C.s_A"));
  ASSERT_EQ(conditions.size(), 2u);
  EXPECT_TRUE(std::any_of(conditions.begin(), conditions.end(),
                          [&](const Condition& c) { return c.event == m.id("W200") && c.level == W; }));
}

TEST(ConditionSet, AnOnsetAlwaysAddsAConditionWhateverTheState) {
  Machine m;
  const char* onsets[] = {"W10", "E50", "W20", "E80", "W200", "E80B", "LATCH", "LATCHW"};
  std::size_t n = 0;
  for (const char* e : onsets) {
    m.gen(e, "C.s_A");
    ++n;
    EXPECT_EQ(m.co.conditions(m.machine("C.s_A")).size(), n) << e;
    EXPECT_NE(m.last_event().outcome, Outcome::Ignored) << e;
  }
}

// ---- completions ----------------------------------------------------------------------------------

TEST(ConditionSet, CompletionOfInactiveOnsetIsIgnoredWithReason) {
  Machine m;
  m.gen("/E50", "C.s_A");
  Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Ignored);
  EXPECT_EQ(r.event, m.id("/E50"));
  EXPECT_EQ(r.text, "not active");
  EXPECT_EQ(m.at("C.s_A"), N);

  // Active elsewhere is still inactive here.
  m.gen("E50", "C.s_F");
  m.gen("/E50", "C.s_A");
  r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Ignored);
  EXPECT_EQ(r.text, "not active");
  EXPECT_EQ(m.at("C.s_F"), E);
}

TEST(ConditionSet, CompletionOfAnOnsetThatWasNeverDefinedIsIgnoredWithReason) {
  Machine m;
  const EventId orphan = m.event(completion("/NEVER", 10, kFromError));
  m.gen("E50", "C.s_A");
  m.co.generate(orphan, m.machine("C.s_A"));  // the id form cannot refuse it: it records why
  const Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Ignored);
  EXPECT_EQ(r.event, orphan);
  EXPECT_EQ(r.text, "completes an onset that is not defined");
  EXPECT_EQ(m.at("C.s_A"), E);
}

TEST(ConditionSet, CompletionOfLatchedOnsetIsIgnoredUntilReset) {
  Machine m;
  m.gen("LATCH", "C.s_A");
  m.gen("/LATCH", "C.s_A");
  Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Ignored);
  EXPECT_EQ(r.text, "latched: needs reset");
  EXPECT_EQ(r.root.event, m.id("LATCH"));
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.outstanding("C.s_A"), "LATCH");

  m.reset("C.s_A", "operator", "checked the arm");
  EXPECT_EQ(m.at("C.s_A"), N);
  EXPECT_TRUE(m.co.conditions(m.machine("C.s_A")).empty());

  // After the reset the latched onset is no longer active: its completion is ignored as such.
  m.gen("/LATCH", "C.s_A");
  EXPECT_EQ(m.last_event().text, "not active");
  // And it can latch again.
  m.gen("LATCH", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), E);
}

TEST(ConditionSet, CompletionOfErrorReestablishesStillPresentWarning) {
  Machine m;
  std::vector<Transition> seen;
  m.co.on_machine(m.machine("C.s_A"),
                  StateCallbacks{{}, [&](const TransitionInfo& i) { seen.push_back(i.transition); }, {}});
  m.gen("W20", "C.s_A");
  m.gen("E50", "C.s_A");
  m.gen("/E50", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), W);
  EXPECT_EQ(m.outstanding("C.s_A"), "W20");
  const Record r = m.last_event();
  EXPECT_EQ(r.outcome, Outcome::Cleared);
  EXPECT_EQ(r.event, m.id("/E50"));
  EXPECT_EQ(r.from, E);
  EXPECT_EQ(r.to, W);
  const auto ts = m.records_of_kind("C.s_A", RecordKind::Transition);
  ASSERT_EQ(ts.size(), 3u);
  EXPECT_EQ(transition_between(ts[2].from, ts[2].to), Transition::E2W);
  EXPECT_EQ(seen, (std::vector<Transition>{Transition::N2W, Transition::W2E, Transition::E2W}));
}

TEST(ConditionSet, CompletionOfTheLastConditionReturnsToNormal) {
  Machine m;
  m.gen("E50", "C.s_A");
  m.gen("/E50", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), N);
  EXPECT_EQ(m.co.snapshot(m.machine("C.s_A")).outstanding, kNoEvent);
  m.gen("W20", "C.s_A");
  m.gen("/W20", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), N);
  const auto ts = m.records_of_kind("C.s_A", RecordKind::Transition);
  ASSERT_EQ(ts.size(), 4u);
  EXPECT_EQ(transition_between(ts[1].from, ts[1].to), Transition::E2N);
  EXPECT_EQ(transition_between(ts[3].from, ts[3].to), Transition::W2N);
}

TEST(ConditionSet, CompletionOfOneOfTwoErrorsKeepsErrorAndPassesOutstandingOn) {
  Machine m;
  m.gen("E50", "C.s_A");
  m.gen("E80", "C.s_A");
  m.gen("/E80", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_EQ(m.outstanding("C.s_A"), "E50");
  EXPECT_EQ(m.last_event().outcome, Outcome::Cleared);
  EXPECT_EQ(m.transitions(), 1u);
}

// ---- derived state and outstanding ----------------------------------------------------------------

TEST(ConditionSet, StateEqualsMaxLevelOfActiveConditions) {
  Machine m;
  const MachineId a = m.machine("C.s_A");
  const char* events[] = {"W10",  "W20",  "W200",  "E50",  "E80",  "E80B",  "LATCH",  "LATCHW",
                          "/W10", "/W20", "/W200", "/E50", "/E80", "/E80B", "/LATCH", "/LATCHW"};
  std::uint32_t seed = 12345;  // fixed: the sequence is the same on every run
  for (int step = 0; step < 2000; ++step) {
    seed = seed * 1664525u + 1013904223u;
    const std::size_t pick = (seed >> 16) % std::size(events);
    if ((seed >> 8) % 97 == 0) {
      m.reset("C.s_A");
    } else {
      m.gen(events[pick], "C.s_A");
    }
    const auto conditions = m.co.conditions(a);
    State max = N;
    for (const Condition& c : conditions) max = max * c.level;
    ASSERT_EQ(m.co.state(a), max) << "step " << step << " after " << events[pick];
    ASSERT_EQ(m.co.snapshot(a).state, max) << "step " << step;
    ASSERT_EQ(m.co.extended(m.comp("C")).state, max) << "step " << step;
    // Outstanding: highest severity at the current level, most recent activation on a tie.
    const Condition* best = nullptr;
    for (const Condition& c : conditions) {
      if (c.level != max) continue;
      if (best == nullptr || c.severity > best->severity || (c.severity == best->severity && c.seq > best->seq)) {
        best = &c;
      }
    }
    ASSERT_EQ(m.co.snapshot(a).outstanding, best == nullptr ? kNoEvent : best->event) << "step " << step;
  }
}

TEST(ConditionSet, OutstandingIsHighestSeverityAtCurrentLevelMostRecentOnTie) {
  Machine m;
  m.gen("W200", "C.s_A");
  m.gen("E80", "C.s_A");
  m.gen("E50", "C.s_A");
  m.gen("E80B", "C.s_A");
  // W200 has the highest severity but is below the current level; E80 and E80B tie: the most
  // recent (E80B) is outstanding.
  EXPECT_EQ(m.outstanding("C.s_A"), "E80B");
  // A refresh does not make an older condition "more recent": outstanding does not flap with
  // level-triggered filters.
  m.gen("E80", "C.s_A");
  EXPECT_EQ(m.outstanding("C.s_A"), "E80B");
  m.gen("/E80B", "C.s_A");
  EXPECT_EQ(m.outstanding("C.s_A"), "E80");
  m.gen("/E80", "C.s_A");
  EXPECT_EQ(m.outstanding("C.s_A"), "E50");
  m.gen("/E50", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), W);
  EXPECT_EQ(m.outstanding("C.s_A"), "W200");
  EXPECT_EQ(m.co.snapshot(m.machine("C.s_A")).outstanding, m.id("W200"));
}

// ---- exhaustive tables ----------------------------------------------------------------------------

using test::N2E;
using test::N2W;
using test::W2E;

struct OnsetRow {
  const char* transitions_text;
  TransitionSet transitions;
  State start;
  State level;         // level the onset takes (DESIGN §2.3)
  State result;        // machine state after the onset
  Outcome outcome_ge;  // outcome when the onset's severity >= the outstanding's
  Outcome outcome_lt;  // outcome when it is lower
};

// Written out by hand: 7 subsets of worsening transitions × 3 starting states.
const OnsetRow kOnsetTable[] = {
    {"N2W", {N2W}, N, W, W, Outcome::Raised, Outcome::Raised},
    {"N2W", {N2W}, W, W, W, Outcome::Override, Outcome::Joined},
    {"N2W", {N2W}, E, W, E, Outcome::Masked, Outcome::Masked},
    {"N2E", {N2E}, N, E, E, Outcome::Raised, Outcome::Raised},
    {"N2E", {N2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"N2E", {N2E}, E, E, E, Outcome::Override, Outcome::Joined},
    {"W2E", {W2E}, N, W, W, Outcome::Raised, Outcome::Raised},  // Decision D12
    {"W2E", {W2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"W2E", {W2E}, E, E, E, Outcome::Override, Outcome::Joined},
    {"N2W,N2E", {N2W, N2E}, N, E, E, Outcome::Raised, Outcome::Raised},
    {"N2W,N2E", {N2W, N2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"N2W,N2E", {N2W, N2E}, E, E, E, Outcome::Override, Outcome::Joined},
    {"N2W,W2E", {N2W, W2E}, N, W, W, Outcome::Raised, Outcome::Raised},
    {"N2W,W2E", {N2W, W2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"N2W,W2E", {N2W, W2E}, E, E, E, Outcome::Override, Outcome::Joined},
    {"N2E,W2E", {N2E, W2E}, N, E, E, Outcome::Raised, Outcome::Raised},
    {"N2E,W2E", {N2E, W2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"N2E,W2E", {N2E, W2E}, E, E, E, Outcome::Override, Outcome::Joined},
    {"N2W,N2E,W2E", {N2W, N2E, W2E}, N, E, E, Outcome::Raised, Outcome::Raised},
    {"N2W,N2E,W2E", {N2W, N2E, W2E}, W, E, E, Outcome::Raised, Outcome::Raised},
    {"N2W,N2E,W2E", {N2W, N2E, W2E}, E, E, E, Outcome::Override, Outcome::Joined},
};

TEST(ConditionSetTable, EveryOnsetSubsetFromEveryStartingStateGivesTheTabledStateAndOutcome) {
  int cases = 0;
  for (const OnsetRow& row : kOnsetTable) {
    for (const int severity : {100, 150, 1}) {  // helper has 100: equal, higher, lower
      Gcm g;
      g.component("C");
      g.event(onset("H_W", 100, kToWarning));
      g.event(onset("H_E", 100, {N2E}));
      g.event(onset("X", severity, row.transitions));
      if (row.start == W) g.gen("H_W", "C.s_A");
      if (row.start == E) g.gen("H_E", "C.s_A");
      ASSERT_EQ(g.at("C.s_A"), row.start);
      const std::string helper = row.start == N ? "" : row.start == W ? "H_W" : "H_E";
      const std::size_t transitions_before = g.records_of_kind("C.s_A", RecordKind::Transition).size();

      g.gen("X", "C.s_A");

      const std::string where = std::string(row.transitions_text) + " from " + std::string(to_string(row.start)) +
                                " severity " + std::to_string(severity);
      const Outcome expected = severity >= 100 ? row.outcome_ge : row.outcome_lt;
      EXPECT_EQ(g.at("C.s_A"), row.result) << where;
      const auto events = g.event_records("C.s_A");
      ASSERT_FALSE(events.empty()) << where;
      const Record& r = events.back();
      EXPECT_EQ(r.event, g.id("X")) << where;
      EXPECT_EQ(r.outcome, expected) << where << ": " << to_string(r.outcome);
      EXPECT_EQ(r.level, row.level) << where;
      EXPECT_EQ(r.from, row.start) << where;
      EXPECT_EQ(r.to, row.result) << where;
      // The condition is active at its level, whatever the outcome.
      bool found = false;
      for (const Condition& c : g.co.conditions(g.machine("C.s_A"))) {
        if (c.event == g.id("X")) {
          found = true;
          EXPECT_EQ(c.level, row.level) << where;
        }
      }
      EXPECT_TRUE(found) << where;
      // Exactly one transition when raised, none otherwise.
      const auto ts = g.records_of_kind("C.s_A", RecordKind::Transition);
      if (expected == Outcome::Raised) {
        ASSERT_EQ(ts.size(), transitions_before + 1) << where;
        EXPECT_EQ(ts.back().from, row.start) << where;
        EXPECT_EQ(ts.back().to, row.result) << where;
      } else {
        EXPECT_EQ(ts.size(), transitions_before) << where;
      }
      const bool x_outstanding = expected == Outcome::Raised || expected == Outcome::Override;
      EXPECT_EQ(g.outstanding("C.s_A"), x_outstanding ? "X" : helper) << where;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 7 * 3 * 3);
}

struct CompletionRow {
  const char* name;
  std::vector<const char*> active;  // onsets generated first, in order
  const char* completion;
  State before;
  State after;
  Outcome outcome;
  const char* reason;       // text of an ignored record
  std::string outstanding;  // after
};

TEST(ConditionSetTable, EveryCompletionCaseGivesTheTabledStateAndOutcome) {
  const CompletionRow rows[] = {
      {"error completed while a warning is active", {"W20", "E50"}, "/E50", E, W, Outcome::Cleared, "", "W20"},
      {"error completed while nothing else is active", {"E50"}, "/E50", E, N, Outcome::Cleared, "", ""},
      {"warning completed while nothing else is active", {"W20"}, "/W20", W, N, Outcome::Cleared, "", ""},
      {"warning completed under an error", {"E50", "W20"}, "/W20", E, E, Outcome::Cleared, "", "E50"},
      {"error completed under a higher error", {"E50", "E80"}, "/E50", E, E, Outcome::Cleared, "", "E80"},
      {"outstanding error completed under a lower one", {"E50", "E80"}, "/E80", E, E, Outcome::Cleared, "", "E50"},
      {"inactive onset in Normal", {}, "/E50", N, N, Outcome::Ignored, "not active", ""},
      {"inactive onset in Warning", {"W20"}, "/E50", W, W, Outcome::Ignored, "not active", "W20"},
      {"inactive onset in Error", {"E80"}, "/E50", E, E, Outcome::Ignored, "not active", "E80"},
      {"latched error", {"LATCH"}, "/LATCH", E, E, Outcome::Ignored, "latched: needs reset", "LATCH"},
      {"latched warning", {"LATCHW"}, "/LATCHW", W, W, Outcome::Ignored, "latched: needs reset", "LATCHW"},
      {"latched error over a warning",
       {"W20", "LATCH"},
       "/LATCH",
       E,
       E,
       Outcome::Ignored,
       "latched: needs reset",
       "LATCH"},
      {"unlatched error next to a latched one", {"LATCH", "E50"}, "/E50", E, E, Outcome::Cleared, "", "LATCH"},
      {"warning next to a latched warning", {"LATCHW", "W20"}, "/W20", W, W, Outcome::Cleared, "", "LATCHW"},
  };
  for (const CompletionRow& row : rows) {
    Machine m;
    for (const char* e : row.active) m.gen(e, "C.s_A");
    ASSERT_EQ(m.at("C.s_A"), row.before) << row.name;
    const std::size_t conditions_before = m.co.conditions(m.machine("C.s_A")).size();
    const std::size_t transitions_before = m.transitions();
    m.gen(row.completion, "C.s_A");
    EXPECT_EQ(m.at("C.s_A"), row.after) << row.name;
    const Record r = m.last_event();
    EXPECT_EQ(r.event, m.id(row.completion)) << row.name;
    EXPECT_EQ(r.outcome, row.outcome) << row.name << ": " << to_string(r.outcome);
    EXPECT_EQ(r.from, row.before) << row.name;
    EXPECT_EQ(r.to, row.after) << row.name;
    EXPECT_EQ(std::string(r.text), row.reason) << row.name;
    EXPECT_EQ(m.outstanding("C.s_A"), row.outstanding) << row.name;
    EXPECT_EQ(m.co.conditions(m.machine("C.s_A")).size(), conditions_before - (row.outcome == Outcome::Cleared ? 1 : 0))
        << row.name;
    EXPECT_EQ(m.transitions(), transitions_before + (row.before != row.after ? 1 : 0)) << row.name;
  }
}

// ---- reset ----------------------------------------------------------------------------------------

TEST(Reset, ResetOfAMachineClearsItsConditionsLatchedOnesTooAndIsRecordedWithWhoAndWhy) {
  Machine m;
  m.observe();
  m.gen("LATCH", "C.s_A");
  m.gen("W20", "C.s_A");
  m.gen("E50", "C.s_F");
  m.clock.set(seconds_to_time(4.0));
  m.reset("C.s_A", "alice", "sensor replaced");
  EXPECT_EQ(m.at("C.s_A"), N);
  EXPECT_TRUE(m.co.conditions(m.machine("C.s_A")).empty());
  EXPECT_EQ(m.at("C.s_F"), E) << "other machines are not reset";

  const auto resets = m.records_of_kind("C.s_A", RecordKind::Reset);
  ASSERT_EQ(resets.size(), 1u);
  EXPECT_EQ(resets[0].text, "alice: sensor replaced");
  EXPECT_EQ(resets[0].time, seconds_to_time(4.0));
  EXPECT_EQ(resets[0].from, E);
  // Each cleared condition is recorded with the reason too.
  std::size_t cleared = 0;
  for (const Record& r : m.event_records("C.s_A")) {
    if (r.outcome == Outcome::Cleared) {
      ++cleared;
      EXPECT_EQ(r.text, "alice: sensor replaced");
    }
  }
  EXPECT_EQ(cleared, 2u);
  const bool streamed = std::any_of(m.stream.begin(), m.stream.end(), [&](const Record& r) {
    return r.kind == RecordKind::Reset && r.machine == m.machine("C.s_A") && r.text == "alice: sensor replaced";
  });
  EXPECT_TRUE(streamed);
  EXPECT_TRUE(m.records_of_kind("C.s_F", RecordKind::Reset).empty());
}

TEST(Reset, ResetOfAComponentClearsEveryMachineOfThatComponentOnly) {
  Machine m;
  m.gen("LATCH", "C.s_F");
  m.gen("E50", "C.s_A");
  m.gen("LATCHW", "C.s_P.p");
  m.gen("E80", "C.s_R.r");
  m.gen("E50", "D.s_A");
  ASSERT_EQ(m.at("C"), E);
  m.reset("C", "bob", "restart");
  for (const char* a : {"C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r", "C"}) EXPECT_EQ(m.at(a), N) << a;
  for (const char* a : {"C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r"}) {
    const auto resets = m.records_of_kind(a, RecordKind::Reset);
    ASSERT_EQ(resets.size(), 1u) << a;
    EXPECT_EQ(resets[0].text, "bob: restart") << a;
  }
  EXPECT_EQ(m.at("D.s_A"), E);
  EXPECT_TRUE(m.records_of_kind("D.s_A", RecordKind::Reset).empty());
}

TEST(Reset, ResetOfTheSystemClearsEveryComponent) {
  for (const char* system : {"SYSTEM", "robot"}) {
    Machine m;
    m.gen("LATCH", "C.s_F");
    m.gen("LATCHW", "D.s_A");
    m.gen("E50", "C.s_R.r");
    m.reset(system, "carol", "end of procedure");
    EXPECT_EQ(m.at("SYSTEM"), N) << system;
    EXPECT_EQ(m.co.coordinator_state(), N) << system;
    for (const char* a : {"C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r", "D.s_F", "D.s_A"}) {
      EXPECT_TRUE(m.co.conditions(m.machine(a)).empty()) << a;
      const auto resets = m.records_of_kind(a, RecordKind::Reset);
      ASSERT_EQ(resets.size(), 1u) << a;
      EXPECT_EQ(resets[0].text, "carol: end of procedure");
    }
  }
}

TEST(Reset, ResetFiresTheExitTransitionAndEntryCallbacks) {
  Machine m;
  std::vector<std::string> log;
  m.co.on_machine(m.machine("C.s_A"),
                  StateCallbacks{[&](State s) { log.push_back("exit " + std::string(to_string(s))); },
                                 [&](const TransitionInfo& i) {
                                   log.push_back("transition " + std::string(to_string(i.transition)));
                                 },
                                 [&](State s) { log.push_back("entry " + std::string(to_string(s))); }});
  m.gen("LATCH", "C.s_A");
  log.clear();
  m.reset("C.s_A");
  EXPECT_EQ(log, (std::vector<std::string>{"exit Error", "transition E2N", "entry Normal"}));
}

TEST(Reset, AResetGoesStraightToNormalWithoutPassingThroughAWarning) {
  // Whatever order the conditions were raised in, clearing them must not make the machine enter
  // Warning on its way from Error to Normal (callbacks would react to a state that never existed).
  const std::vector<std::vector<const char*>> orders = {
      {"W20", "E50"}, {"E50", "W20"}, {"W10", "LATCH", "W20", "E80"}, {"LATCH", "W200", "E50", "LATCHW"}};
  for (const auto& order : orders) {
    Machine m;
    for (const char* e : order) m.gen(e, "C.s_A");
    ASSERT_EQ(m.at("C.s_A"), E);
    std::vector<Transition> machine_transitions;
    std::vector<Transition> component_transitions;
    m.co.on_machine(
        m.machine("C.s_A"),
        StateCallbacks{{}, [&](const TransitionInfo& i) { machine_transitions.push_back(i.transition); }, {}});
    m.co.on_component(
        m.comp("C"),
        StateCallbacks{{}, [&](const TransitionInfo& i) { component_transitions.push_back(i.transition); }, {}});
    m.reset("C.s_A");
    EXPECT_EQ(machine_transitions, std::vector<Transition>{Transition::E2N}) << order.front();
    EXPECT_EQ(component_transitions, std::vector<Transition>{Transition::E2N}) << order.front();
    EXPECT_EQ(m.at("C.s_A"), N);
  }
}

TEST(Reset, AComponentResetGoesStraightToNormalEvenWhenItsMachinesHoldDifferentLevels) {
  // s_F in Error and s_A in Warning: resetting the component must not show it in Warning on the
  // way down (warnings are cleared in every machine before errors).
  Machine m;
  m.gen("E50", "C.s_F");
  m.gen("W20", "C.s_A");
  ASSERT_EQ(m.co.extended(m.comp("C")).state, E);
  std::vector<Transition> component_transitions;
  m.co.on_component(
      m.comp("C"),
      StateCallbacks{{}, [&](const TransitionInfo& i) { component_transitions.push_back(i.transition); }, {}});
  m.reset("C");
  EXPECT_EQ(component_transitions, std::vector<Transition>{Transition::E2N});
  EXPECT_EQ(m.co.extended(m.comp("C")).state, N);
}

TEST(Reset, ResetOfAServiceStateIsRefusedBecauseItIsDerived) {
  Machine m;
  m.gen("E50", "C.s_A");
  const auto r = reset(m.co, "C.s_S.p", "op", "x");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(r.error().message.find("C.s_S.p"), std::string::npos);
  EXPECT_EQ(m.at("C.s_A"), E);
}

TEST(Reset, ResetOfAnUnknownTargetIsAnErrorAndChangesNothing) {
  Machine m;
  m.gen("E50", "C.s_A");
  const auto r = reset(m.co, "NOPE", "op", "x");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::NotFound);
  EXPECT_NE(r.error().message.find("NOPE"), std::string::npos);
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_TRUE(m.records_of_kind("C.s_A", RecordKind::Reset).empty());
}

// ---- history and observer stream ------------------------------------------------------------------

TEST(History, EveryProcessedIgnoredMaskedOverrideAndResetRecordIsInHistoryAndOnTheObserverStream) {
  Machine m;
  m.observe();
  m.gen("E50", "C.s_A");     // raised
  m.gen("E80", "C.s_A");     // override
  m.gen("E50", "C.s_A");     // refresh: not recorded
  m.gen("E80B", "C.s_A");    // override (equal)
  m.gen("LATCH", "C.s_A");   // joined (60 < 80)
  m.gen("W20", "C.s_A");     // masked
  m.gen("/E80", "C.s_A");    // cleared
  m.gen("/W10", "C.s_A");    // ignored: not active
  m.gen("/LATCH", "C.s_A");  // ignored: latched
  m.reset("C.s_A", "dave", "done");

  const auto history = m.history("C.s_A");
  std::vector<Record> streamed;
  for (const Record& r : m.stream) {
    if (r.machine == m.machine("C.s_A")) streamed.push_back(r);
  }
  ASSERT_EQ(history.size(), streamed.size());
  for (std::size_t i = 0; i < history.size(); ++i) {
    EXPECT_EQ(history[i].seq, streamed[i].seq) << i;
    EXPECT_EQ(history[i].kind, streamed[i].kind) << i;
    EXPECT_EQ(history[i].outcome, streamed[i].outcome) << i;
    EXPECT_EQ(history[i].event, streamed[i].event) << i;
    if (i > 0) {
      EXPECT_GT(history[i].seq, history[i - 1].seq) << "history is oldest first";
    }
  }
  auto count = [&](Outcome o) {
    return std::count_if(history.begin(), history.end(),
                         [o](const Record& r) { return r.kind == RecordKind::Event && r.outcome == o; });
  };
  EXPECT_EQ(count(Outcome::Raised), 1);
  EXPECT_EQ(count(Outcome::Override), 2);
  EXPECT_EQ(count(Outcome::Joined), 1);
  EXPECT_EQ(count(Outcome::Masked), 1);
  EXPECT_EQ(count(Outcome::Ignored), 2);
  // /E80 plus the four conditions the reset removed (E50, E80B, LATCH, W20).
  EXPECT_EQ(count(Outcome::Cleared), 5);
  EXPECT_EQ(std::count_if(history.begin(), history.end(), [](const Record& r) { return r.kind == RecordKind::Reset; }),
            1);
  EXPECT_EQ(
      std::count_if(history.begin(), history.end(), [](const Record& r) { return r.kind == RecordKind::Transition; }),
      2);
  // Component transitions are on the stream too.
  EXPECT_EQ(std::count_if(m.stream.begin(), m.stream.end(),
                          [](const Record& r) { return r.kind == RecordKind::ComponentTransition; }),
            2);
}

/// A component's extended-state transitions still in the history, oldest first.
std::vector<Record> component_history(const Coordinator& co, ComponentId c) {
  return co.history(Address{.kind = Address::Kind::Component, .component = c}, 0, RecordKind::ComponentTransition);
}

TEST(History, RecordsOnTheStreamAreInCoordinatorWideOrder) {
  Machine m;
  m.observe();
  m.gen("E50", "C.s_A");
  m.gen("W20", "D.s_F");
  m.gen("/E50", "C.s_A");
  ASSERT_GE(m.stream.size(), 5u);
  for (std::size_t i = 1; i < m.stream.size(); ++i) EXPECT_GT(m.stream[i].seq, m.stream[i - 1].seq) << i;
}

TEST(History, HistoryIsBoundedByHistoryCapacityAndKeepsTheNewestRecords) {
  CoordinatorOptions options;
  options.history_capacity = 4;
  Machine m(options);
  m.observe();
  m.gen("E50", "C.s_A");   // event + transition
  m.gen("E80", "C.s_A");   // event
  m.gen("/E80", "C.s_A");  // event
  m.gen("/E50", "C.s_A");  // event + transition
  m.gen("W20", "C.s_A");   // event + transition
  std::vector<Record> all;
  for (const Record& r : m.stream) {
    if (r.machine == m.machine("C.s_A")) all.push_back(r);
  }
  ASSERT_EQ(all.size(), 8u);
  const auto history = m.history("C.s_A");
  ASSERT_EQ(history.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(history[i].seq, all[all.size() - 4 + i].seq) << i;
  // The component history is bounded the same way.
  for (int i = 0; i < 5; ++i) {
    m.gen("E50", "C.s_A");
    m.gen("/E50", "C.s_A");
  }
  EXPECT_EQ(component_history(m.co, m.comp("C")).size(), 4u);
}

TEST(History, AZeroCapacityKeepsNoHistoryButStillPublishesEveryRecord) {
  CoordinatorOptions options;
  options.history_capacity = 0;
  Machine m(options);
  m.observe();
  m.gen("E50", "C.s_A");
  EXPECT_TRUE(m.history("C.s_A").empty());
  EXPECT_TRUE(component_history(m.co, m.comp("C")).empty());
  EXPECT_EQ(m.stream.size(), 3u);  // event, transition, component transition
  EXPECT_EQ(m.at("C.s_A"), E);
}

TEST(History, HistoryIsTimestampedFromTheInjectedClock) {
  Machine m;
  m.clock.set(seconds_to_time(1.25));
  m.gen("E50", "C.s_A");
  m.clock.advance(seconds_to_time(0.5));
  m.gen("W20", "C.s_A");
  m.clock.set(seconds_to_time(10.0));
  m.gen("/E50", "C.s_A");
  const auto events = m.event_records("C.s_A");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].time, seconds_to_time(1.25));
  EXPECT_EQ(events[1].time, seconds_to_time(1.75));
  EXPECT_EQ(events[2].time, seconds_to_time(10.0));
  const auto ts = m.records_of_kind("C.s_A", RecordKind::Transition);
  ASSERT_EQ(ts.size(), 2u);
  EXPECT_EQ(ts[0].time, seconds_to_time(1.25));
  EXPECT_EQ(ts[1].time, seconds_to_time(10.0));
  const auto comp = component_history(m.co, m.comp("C"));
  ASSERT_EQ(comp.size(), 2u);
  EXPECT_EQ(comp[0].time, seconds_to_time(1.25));
  EXPECT_EQ(comp[1].time, seconds_to_time(10.0));
  const auto conditions = m.co.conditions(m.machine("C.s_A"));
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].first, seconds_to_time(1.75));
}

TEST(History, ARecordCarriesTheRootCauseAndTheFilterSample) {
  Machine m;
  SampleCause cause;
  cause.filter = m.co.intern("force_limit");
  cause.signal = m.co.intern("C.ForceNorm");
  cause.value = 35.5;
  cause.sample_time = seconds_to_time(0.1);
  m.clock.set(seconds_to_time(0.2));
  m.co.generate(m.id("E50"), m.machine("C.s_A"), cause);
  const Record r = m.last_event();
  EXPECT_EQ(r.root.event, m.id("E50"));
  EXPECT_EQ(r.root.origin, m.machine("C.s_A"));
  EXPECT_EQ(r.root.time, seconds_to_time(0.2));
  EXPECT_EQ(m.co.structure().name_of(r.root.sample.filter), "force_limit");
  EXPECT_EQ(m.co.structure().name_of(r.root.sample.signal), "C.ForceNorm");
  EXPECT_DOUBLE_EQ(r.root.sample.value, 35.5);
  EXPECT_EQ(r.root.sample.sample_time, seconds_to_time(0.1));
}

TEST(History, AnUnsubscribedObserverReceivesNothingMore) {
  Machine m;
  int calls = 0;
  const auto id = m.co.subscribe([&](const Record&) { ++calls; });
  m.gen("E50", "C.s_A");
  const int after_first = calls;
  EXPECT_GT(after_first, 0);
  m.co.unsubscribe(id);
  m.gen("/E50", "C.s_A");
  EXPECT_EQ(calls, after_first);
}

TEST(History, ARegistrationMadeByAnObserverTakesEffectAfterTheRecordsBeingHandedOut) {
  Machine m;
  int first_calls = 0, second_calls = 0;
  std::uint64_t second_first_seq = 0, last_seq_of_first_write = 0;
  Coordinator::SubscriptionId first = 0;
  first = m.co.subscribe([&](const Record& r) {
    ++first_calls;
    last_seq_of_first_write = r.seq;
    if (first_calls > 1) return;
    // The first record of the first write: leave, and bring another observer in.
    m.co.unsubscribe(first);
    (void)m.co.subscribe([&](const Record& later) {
      if (second_calls++ == 0) second_first_seq = later.seq;
    });
  });
  m.gen("E50", "C.s_A");
  const int first_write_records = first_calls;
  EXPECT_GT(first_write_records, 1) << "the first write's records all reach the observer that left during them";
  EXPECT_EQ(second_calls, 0) << "the new observer sees none of the records being handed out";
  m.gen("/E50", "C.s_A");
  EXPECT_EQ(first_calls, first_write_records) << "the observer that left sees nothing of the next write";
  EXPECT_GT(second_calls, 0);
  EXPECT_GT(second_first_seq, last_seq_of_first_write);
}

TEST(History, AThrowingObserverDoesNotStopProcessingOrOtherObservers) {
  Machine m;
  int calls = 0;
  m.co.subscribe([](const Record&) { throw std::runtime_error("observer bug"); });
  m.co.subscribe([&](const Record&) { ++calls; });
  m.gen("E50", "C.s_A");
  EXPECT_EQ(m.at("C.s_A"), E);
  EXPECT_GT(calls, 0);
}

TEST(History, PublishedRecordsGoToTheStreamAndTheNamedMachinesHistory) {
  Machine m;
  m.observe();
  Record injection;
  injection.kind = RecordKind::Injection;
  injection.machine = m.machine("C.s_A");
  injection.time = seconds_to_time(3.0);
  m.co.publish(injection);
  const auto injections = m.records_of_kind("C.s_A", RecordKind::Injection);
  ASSERT_EQ(injections.size(), 1u);
  EXPECT_EQ(injections[0].component, m.comp("C"));
  ASSERT_EQ(m.stream.size(), 1u);
  EXPECT_EQ(m.stream[0].kind, RecordKind::Injection);
}

}  // namespace
}  // namespace safecass
