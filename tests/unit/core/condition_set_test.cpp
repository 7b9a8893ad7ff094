// DESIGN §2.4 as a table: the condition set of one machine (ConditionSet), driven directly, for
// every machine state (Normal, Warning, Error) × every kind of onset and completion × the subject
// condition X being absent, active, active and latched, or present only as a mirror.
//
// Each row gives the set before, the event, and the expected outcome, state, set and outstanding
// condition after. Sets are written as tokens NAME:LEVEL:
//   B  a background root condition (severity 40) that gives the machine its state;
//   X  the subject: the root condition of the onset the row's event is about;
//   M  a mirror (severity 220 at Error, 215 at Warning) whose event is X's event: a completion of X
//      must never clear it (Decision D4), a reset must leave it (D5).
// The rows are written out, not computed: the expectations are the specification.

#include <gtest/gtest.h>

#include <algorithm>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/condition_set.hpp"

namespace safecass {
namespace {

using test::E;
using test::N;
using test::W;

constexpr EventId kX{100};
constexpr EventId kB{200};
constexpr EventId kMirrorRoot{300};
constexpr Time kNow{std::chrono::seconds(7)};

/// The event of a row (DESIGN §2.3 for the levels: onset_level()).
enum class Op {
  WarningOnset,               ///< X {N2W}, severity 60
  ErrorOnset,                 ///< X {N2E, W2E}, severity 60
  EscalatingOnset,            ///< X {N2W, W2E}, severity 60: Warning from Normal, Error from Warning
  LowerSeverityWarningOnset,  ///< X {N2W}, severity 20
  LowerSeverityErrorOnset,    ///< X {N2E, W2E}, severity 20
  EqualSeverityErrorOnset,    ///< X {N2E, W2E}, severity 40 (= the background's)
  WarningCompletion,          ///< completion of X {N2W}, severity 60
  ErrorCompletion,            ///< completion of X {N2E, W2E}, severity 60
  UndefinedCompletion,        ///< a completion whose onset is not defined
  Reset,                      ///< reset of the machine
};
constexpr Op kAllOps[] = {Op::WarningOnset,
                          Op::ErrorOnset,
                          Op::EscalatingOnset,
                          Op::LowerSeverityWarningOnset,
                          Op::LowerSeverityErrorOnset,
                          Op::EqualSeverityErrorOnset,
                          Op::WarningCompletion,
                          Op::ErrorCompletion,
                          Op::UndefinedCompletion,
                          Op::Reset};

/// The subject condition X before the event.
enum class Subject { Absent, Active, Latched, Mirrored };
constexpr Subject kAllSubjects[] = {Subject::Absent, Subject::Active, Subject::Latched, Subject::Mirrored};

struct RuleRow {
  const char* rule;  ///< the test's name: state, event, subject, what happens
  Subject subject;
  Op op;
  const char* before;  ///< the set before (tokens)
  Outcome outcome;     ///< None: a refresh (onset) or a reset that removed nothing
  State after;
  const char* set_after;
  const char* outstanding;  ///< B, X, M or "-" (none)
  const char* reason;       ///< ignored completions: the recorded reason
};

void PrintTo(const RuleRow& row, std::ostream* os) { *os << row.rule; }

constexpr Outcome Raised = Outcome::Raised;
constexpr Outcome Override = Outcome::Override;
constexpr Outcome Joined = Outcome::Joined;
constexpr Outcome Masked = Outcome::Masked;
constexpr Outcome Cleared = Outcome::Cleared;
constexpr Outcome Ignored = Outcome::Ignored;
constexpr Outcome Refreshed = Outcome::None;

constexpr const char* kNotActive = "not active";
constexpr const char* kLatched = "latched: needs reset";
constexpr const char* kUndefined = "completes an onset that is not defined";

using S = Subject;
using O = Op;

// clang-format off
const RuleRow kRows[] = {
  // ---- onset of a Warning-level event (X {N2W}, severity 60) -------------------------------------
  {"Normal_WarningOnset_Absent_RaisesToWarning",                S::Absent,   O::WarningOnset, "",        Raised,    W, "X:W",     "X", ""},
  {"Warning_WarningOnset_Absent_HigherSeverityOverrides",       S::Absent,   O::WarningOnset, "B:W",     Override,  W, "B:W X:W", "X", ""},
  {"Error_WarningOnset_Absent_IsMaskedButKept",                 S::Absent,   O::WarningOnset, "B:E",     Masked,    E, "B:E X:W", "B", ""},
  {"Warning_WarningOnset_Active_OnlyRefreshes",                 S::Active,   O::WarningOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_WarningOnset_Active_OnlyRefreshes",                   S::Active,   O::WarningOnset, "B:E X:W", Refreshed, E, "B:E X:W", "B", ""},
  {"Warning_WarningOnset_Latched_OnlyRefreshes",                S::Latched,  O::WarningOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_WarningOnset_Latched_OnlyRefreshes",                  S::Latched,  O::WarningOnset, "B:E X:W", Refreshed, E, "B:E X:W", "B", ""},
  {"Warning_WarningOnset_Mirrored_AddsARootBesideTheMirror",    S::Mirrored, O::WarningOnset, "M:W",     Joined,    W, "M:W X:W", "M", ""},
  {"Error_WarningOnset_Mirrored_AddsAMaskedRoot",               S::Mirrored, O::WarningOnset, "M:E",     Masked,    E, "M:E X:W", "M", ""},

  // ---- onset of an Error-level event (X {N2E, W2E}, severity 60) ---------------------------------
  {"Normal_ErrorOnset_Absent_RaisesToError",                    S::Absent,   O::ErrorOnset, "",        Raised,    E, "X:E",     "X", ""},
  {"Warning_ErrorOnset_Absent_RaisesToError",                   S::Absent,   O::ErrorOnset, "B:W",     Raised,    E, "B:W X:E", "X", ""},
  {"Error_ErrorOnset_Absent_HigherSeverityOverrides",           S::Absent,   O::ErrorOnset, "B:E",     Override,  E, "B:E X:E", "X", ""},
  {"Error_ErrorOnset_Active_OnlyRefreshes",                     S::Active,   O::ErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Error_ErrorOnset_Latched_OnlyRefreshes",                    S::Latched,  O::ErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Warning_ErrorOnset_Mirrored_RaisesToError",                 S::Mirrored, O::ErrorOnset, "M:W",     Raised,    E, "M:W X:E", "X", ""},
  {"Error_ErrorOnset_Mirrored_JoinsBelowTheMirrorsSeverity",    S::Mirrored, O::ErrorOnset, "M:E",     Joined,    E, "M:E X:E", "M", ""},

  // ---- onset listing N2W and W2E (X, severity 60): its level depends on the state ----------------
  {"Normal_EscalatingOnset_Absent_RaisesToWarning",             S::Absent,   O::EscalatingOnset, "",        Raised,    W, "X:W",     "X", ""},
  {"Warning_EscalatingOnset_Absent_RaisesToError",              S::Absent,   O::EscalatingOnset, "B:W",     Raised,    E, "B:W X:E", "X", ""},
  {"Error_EscalatingOnset_Absent_TakesErrorAndOverrides",       S::Absent,   O::EscalatingOnset, "B:E",     Override,  E, "B:E X:E", "X", ""},
  {"Warning_EscalatingOnset_Active_OnlyRefreshesAndStaysWarning", S::Active, O::EscalatingOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_EscalatingOnset_Active_OnlyRefreshes",                S::Active,   O::EscalatingOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Warning_EscalatingOnset_Latched_OnlyRefreshes",             S::Latched,  O::EscalatingOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_EscalatingOnset_Latched_OnlyRefreshes",               S::Latched,  O::EscalatingOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Warning_EscalatingOnset_Mirrored_RaisesToError",            S::Mirrored, O::EscalatingOnset, "M:W",     Raised,    E, "M:W X:E", "X", ""},
  {"Error_EscalatingOnset_Mirrored_Joins",                      S::Mirrored, O::EscalatingOnset, "M:E",     Joined,    E, "M:E X:E", "M", ""},

  // ---- onset of a Warning-level event of lower severity (X {N2W}, severity 20) -------------------
  {"Normal_LowerSeverityWarningOnset_Absent_RaisesToWarning",   S::Absent,   O::LowerSeverityWarningOnset, "",        Raised,    W, "X:W",     "X", ""},
  {"Warning_LowerSeverityWarningOnset_Absent_JoinsWithoutOverriding", S::Absent, O::LowerSeverityWarningOnset, "B:W", Joined,  W, "B:W X:W", "B", ""},
  {"Error_LowerSeverityWarningOnset_Absent_IsMasked",           S::Absent,   O::LowerSeverityWarningOnset, "B:E",     Masked,    E, "B:E X:W", "B", ""},
  {"Warning_LowerSeverityWarningOnset_Active_OnlyRefreshes",    S::Active,   O::LowerSeverityWarningOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_LowerSeverityWarningOnset_Active_OnlyRefreshes",      S::Active,   O::LowerSeverityWarningOnset, "B:E X:W", Refreshed, E, "B:E X:W", "B", ""},
  {"Warning_LowerSeverityWarningOnset_Latched_OnlyRefreshes",   S::Latched,  O::LowerSeverityWarningOnset, "X:W",     Refreshed, W, "X:W",     "X", ""},
  {"Error_LowerSeverityWarningOnset_Latched_OnlyRefreshes",     S::Latched,  O::LowerSeverityWarningOnset, "B:E X:W", Refreshed, E, "B:E X:W", "B", ""},
  {"Warning_LowerSeverityWarningOnset_Mirrored_Joins",          S::Mirrored, O::LowerSeverityWarningOnset, "M:W",     Joined,    W, "M:W X:W", "M", ""},
  {"Error_LowerSeverityWarningOnset_Mirrored_IsMasked",         S::Mirrored, O::LowerSeverityWarningOnset, "M:E",     Masked,    E, "M:E X:W", "M", ""},

  // ---- onset of an Error-level event of lower severity (X {N2E, W2E}, severity 20) ---------------
  {"Normal_LowerSeverityErrorOnset_Absent_RaisesToError",       S::Absent,   O::LowerSeverityErrorOnset, "",        Raised,    E, "X:E",     "X", ""},
  {"Warning_LowerSeverityErrorOnset_Absent_RaisesWhateverItsSeverity", S::Absent, O::LowerSeverityErrorOnset, "B:W", Raised,  E, "B:W X:E", "X", ""},
  {"Error_LowerSeverityErrorOnset_Absent_JoinsWithoutOverriding", S::Absent, O::LowerSeverityErrorOnset, "B:E",     Joined,    E, "B:E X:E", "B", ""},
  {"Error_LowerSeverityErrorOnset_Active_OnlyRefreshes",        S::Active,   O::LowerSeverityErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Error_LowerSeverityErrorOnset_Latched_OnlyRefreshes",       S::Latched,  O::LowerSeverityErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Warning_LowerSeverityErrorOnset_Mirrored_RaisesToError",    S::Mirrored, O::LowerSeverityErrorOnset, "M:W",     Raised,    E, "M:W X:E", "X", ""},
  {"Error_LowerSeverityErrorOnset_Mirrored_Joins",              S::Mirrored, O::LowerSeverityErrorOnset, "M:E",     Joined,    E, "M:E X:E", "M", ""},

  // ---- onset of an Error-level event of equal severity (X {N2E, W2E}, severity 40) ---------------
  {"Normal_EqualSeverityErrorOnset_Absent_RaisesToError",       S::Absent,   O::EqualSeverityErrorOnset, "",        Raised,    E, "X:E",     "X", ""},
  {"Warning_EqualSeverityErrorOnset_Absent_RaisesToError",      S::Absent,   O::EqualSeverityErrorOnset, "B:W",     Raised,    E, "B:W X:E", "X", ""},
  {"Error_EqualSeverityErrorOnset_Absent_TieOverridesAsMostRecent", S::Absent, O::EqualSeverityErrorOnset, "B:E",   Override,  E, "B:E X:E", "X", ""},
  {"Error_EqualSeverityErrorOnset_Active_OnlyRefreshes",        S::Active,   O::EqualSeverityErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Error_EqualSeverityErrorOnset_Latched_OnlyRefreshes",       S::Latched,  O::EqualSeverityErrorOnset, "B:W X:E", Refreshed, E, "B:W X:E", "X", ""},
  {"Warning_EqualSeverityErrorOnset_Mirrored_RaisesToError",    S::Mirrored, O::EqualSeverityErrorOnset, "M:W",     Raised,    E, "M:W X:E", "X", ""},
  {"Error_EqualSeverityErrorOnset_Mirrored_JoinsBelowTheMirrorsSeverity", S::Mirrored, O::EqualSeverityErrorOnset, "M:E", Joined, E, "M:E X:E", "M", ""},

  // ---- completion of a Warning-level onset ---------------------------------------------------------
  {"Normal_WarningCompletion_Absent_IsIgnoredAsNotActive",      S::Absent,   O::WarningCompletion, "",        Ignored, N, "",        "-", kNotActive},
  {"Warning_WarningCompletion_Absent_IsIgnoredAsNotActive",     S::Absent,   O::WarningCompletion, "B:W",     Ignored, W, "B:W",     "B", kNotActive},
  {"Error_WarningCompletion_Absent_IsIgnoredAsNotActive",       S::Absent,   O::WarningCompletion, "B:E",     Ignored, E, "B:E",     "B", kNotActive},
  {"Warning_WarningCompletion_Active_ClearsToNormal",           S::Active,   O::WarningCompletion, "X:W",     Cleared, N, "",        "-", ""},
  {"Error_WarningCompletion_Active_ClearsAndStaysError",        S::Active,   O::WarningCompletion, "B:E X:W", Cleared, E, "B:E",     "B", ""},
  {"Warning_WarningCompletion_Latched_IsIgnoredUntilReset",     S::Latched,  O::WarningCompletion, "X:W",     Ignored, W, "X:W",     "X", kLatched},
  {"Error_WarningCompletion_Latched_IsIgnoredUntilReset",       S::Latched,  O::WarningCompletion, "B:E X:W", Ignored, E, "B:E X:W", "B", kLatched},
  {"Warning_WarningCompletion_Mirrored_NeverClearsAMirror",     S::Mirrored, O::WarningCompletion, "M:W",     Ignored, W, "M:W",     "M", kNotActive},
  {"Error_WarningCompletion_Mirrored_NeverClearsAMirror",       S::Mirrored, O::WarningCompletion, "M:E",     Ignored, E, "M:E",     "M", kNotActive},

  // ---- completion of an Error-level onset ----------------------------------------------------------
  {"Normal_ErrorCompletion_Absent_IsIgnoredAsNotActive",        S::Absent,   O::ErrorCompletion, "",        Ignored, N, "",        "-", kNotActive},
  {"Warning_ErrorCompletion_Absent_IsIgnoredAsNotActive",       S::Absent,   O::ErrorCompletion, "B:W",     Ignored, W, "B:W",     "B", kNotActive},
  {"Error_ErrorCompletion_Absent_IsIgnoredAsNotActive",         S::Absent,   O::ErrorCompletion, "B:E",     Ignored, E, "B:E",     "B", kNotActive},
  {"Error_ErrorCompletion_Active_ClearsToNormalWhenNothingRemains", S::Active, O::ErrorCompletion, "X:E",   Cleared, N, "",        "-", ""},
  {"Error_ErrorCompletion_Active_ReestablishesAWarningStillPresent", S::Active, O::ErrorCompletion, "B:W X:E", Cleared, W, "B:W", "B", ""},
  {"Error_ErrorCompletion_Active_StaysErrorWhileAnotherErrorRemains", S::Active, O::ErrorCompletion, "B:E X:E", Cleared, E, "B:E", "B", ""},
  {"Error_ErrorCompletion_Latched_IsIgnoredUntilReset",         S::Latched,  O::ErrorCompletion, "B:W X:E", Ignored, E, "B:W X:E", "X", kLatched},
  {"Warning_ErrorCompletion_Mirrored_NeverClearsAMirror",       S::Mirrored, O::ErrorCompletion, "M:W",     Ignored, W, "M:W",     "M", kNotActive},
  {"Error_ErrorCompletion_Mirrored_NeverClearsAMirror",         S::Mirrored, O::ErrorCompletion, "M:E",     Ignored, E, "M:E",     "M", kNotActive},

  // ---- completion whose onset is not defined -------------------------------------------------------
  {"Normal_UndefinedCompletion_Absent_IsIgnored",               S::Absent,   O::UndefinedCompletion, "",        Ignored, N, "",        "-", kUndefined},
  {"Warning_UndefinedCompletion_Absent_IsIgnored",              S::Absent,   O::UndefinedCompletion, "B:W",     Ignored, W, "B:W",     "B", kUndefined},
  {"Error_UndefinedCompletion_Absent_IsIgnored",                S::Absent,   O::UndefinedCompletion, "B:E",     Ignored, E, "B:E",     "B", kUndefined},
  {"Warning_UndefinedCompletion_Active_IsIgnored",              S::Active,   O::UndefinedCompletion, "X:W",     Ignored, W, "X:W",     "X", kUndefined},
  {"Error_UndefinedCompletion_Active_IsIgnored",                S::Active,   O::UndefinedCompletion, "B:W X:E", Ignored, E, "B:W X:E", "X", kUndefined},
  {"Warning_UndefinedCompletion_Latched_IsIgnored",             S::Latched,  O::UndefinedCompletion, "X:W",     Ignored, W, "X:W",     "X", kUndefined},
  {"Error_UndefinedCompletion_Latched_IsIgnored",               S::Latched,  O::UndefinedCompletion, "B:W X:E", Ignored, E, "B:W X:E", "X", kUndefined},
  {"Warning_UndefinedCompletion_Mirrored_IsIgnored",            S::Mirrored, O::UndefinedCompletion, "M:W",     Ignored, W, "M:W",     "M", kUndefined},
  {"Error_UndefinedCompletion_Mirrored_IsIgnored",              S::Mirrored, O::UndefinedCompletion, "M:E",     Ignored, E, "M:E",     "M", kUndefined},

  // ---- reset --------------------------------------------------------------------------------------
  {"Normal_Reset_Absent_ChangesNothing",                        S::Absent,   O::Reset, "",        Refreshed, N, "",    "-", ""},
  {"Warning_Reset_Absent_ClearsEveryRoot",                      S::Absent,   O::Reset, "B:W",     Cleared,   N, "",    "-", ""},
  {"Error_Reset_Absent_ClearsEveryRoot",                        S::Absent,   O::Reset, "B:E",     Cleared,   N, "",    "-", ""},
  {"Warning_Reset_Active_ClearsEveryRoot",                      S::Active,   O::Reset, "X:W",     Cleared,   N, "",    "-", ""},
  {"Error_Reset_Active_ClearsEveryRoot",                        S::Active,   O::Reset, "B:W X:E", Cleared,   N, "",    "-", ""},
  {"Warning_Reset_Latched_ClearsLatchedRootsToo",               S::Latched,  O::Reset, "X:W",     Cleared,   N, "",    "-", ""},
  {"Error_Reset_Latched_ClearsLatchedRootsToo",                 S::Latched,  O::Reset, "B:W X:E", Cleared,   N, "",    "-", ""},
  {"Warning_Reset_Mirrored_KeepsAMirrorWhoseRootIsElsewhere",   S::Mirrored, O::Reset, "M:W",     Refreshed, W, "M:W", "M", ""},
  {"Error_Reset_Mirrored_KeepsAMirrorWhoseRootIsElsewhere",     S::Mirrored, O::Reset, "M:E",     Refreshed, E, "M:E", "M", ""},
  {"Error_Reset_Mirrored_ClearsTheRootsAndLeavesTheMirrorsLevel", S::Mirrored, O::Reset, "B:E M:W", Cleared,  W, "M:W", "M", ""},
};
// clang-format on

Event onset_event(Op op, bool latched) {
  Event e;
  e.id = kX;
  e.name = "X";
  e.is_onset = true;
  e.latched = latched;
  e.severity = 60;
  switch (op) {
    case Op::WarningOnset:
    case Op::WarningCompletion: e.transitions = TransitionSet{Transition::N2W}; break;
    case Op::LowerSeverityWarningOnset:
      e.transitions = TransitionSet{Transition::N2W};
      e.severity = 20;
      break;
    case Op::ErrorOnset:
    case Op::ErrorCompletion:
    case Op::UndefinedCompletion:
    case Op::Reset: e.transitions = TransitionSet{Transition::N2E, Transition::W2E}; break;
    case Op::EscalatingOnset: e.transitions = TransitionSet{Transition::N2W, Transition::W2E}; break;
    case Op::LowerSeverityErrorOnset:
      e.transitions = TransitionSet{Transition::N2E, Transition::W2E};
      e.severity = 20;
      break;
    case Op::EqualSeverityErrorOnset:
      e.transitions = TransitionSet{Transition::N2E, Transition::W2E};
      e.severity = 40;
      break;
  }
  return e;
}

bool is_onset(Op op) {
  return op != Op::WarningCompletion && op != Op::ErrorCompletion && op != Op::UndefinedCompletion && op != Op::Reset;
}

std::vector<std::string> tokens(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

State level_of(char c) { return c == 'E' ? E : W; }

/// Builds the set a row starts from; conditions are activated in the order written.
ConditionSet build(const std::string& text, std::uint8_t x_severity, std::uint64_t& activations) {
  ConditionSet set;
  for (const std::string& t : tokens(text)) {
    Condition c;
    c.level = level_of(t.at(2));
    c.first = c.last = Time{std::chrono::seconds(1)};
    c.seq = ++activations;
    switch (t.at(0)) {
      case 'B':
        c.event = kB;
        c.severity = 40;
        c.root = RootCause{kB, MachineId{1}, c.first, {}};
        break;
      case 'X':
        c.event = kX;
        c.severity = x_severity;
        c.root = RootCause{kX, MachineId{1}, c.first, {}};
        break;
      case 'M':
        c.event = kX;  // a mirror carrying the subject's event: only roots may be completed
        c.severity = c.level == E ? 220 : 215;
        c.mirror = true;
        c.via = ConnectionId{0};
        c.root = RootCause{kMirrorRoot, MachineId{9}, c.first, {}};
        break;
      default: ADD_FAILURE() << "bad token " << t;
    }
    set.add(c);
  }
  return set;
}

std::string name_of(const Condition& c) {
  if (c.mirror) return "M";
  return c.event == kX ? "X" : "B";
}

std::multiset<std::string> describe(const ConditionSet& set) {
  std::multiset<std::string> out;
  for (const Condition& c : set) out.insert(name_of(c) + ":" + (c.level == E ? "E" : "W"));
  return out;
}

std::multiset<std::string> expected_set(const char* text) {
  const std::vector<std::string> t = tokens(text);
  return {t.begin(), t.end()};
}

State highest_level(const ConditionSet& set) {
  State s = N;
  for (const Condition& c : set) s = std::max(s, c.level);
  return s;
}

class ConditionSetTable : public ::testing::TestWithParam<RuleRow> {};

TEST_P(ConditionSetTable, FollowsTheSeverityPolicy) {
  const RuleRow& row = GetParam();
  const Event onset = onset_event(row.op, row.subject == Subject::Latched);
  std::uint64_t activations = 0;
  ConditionSet set = build(row.before, onset.severity, activations);
  const State before = set.state();
  const std::size_t x_index = static_cast<std::size_t>(std::max(set.find_root(kX), 0));

  ConditionChange change;
  std::size_t removed_by_reset = 0;
  if (is_onset(row.op)) {
    change = set.onset(onset, RootCause{kX, MachineId{1}, kNow, {}}, kNow, activations);
  } else if (row.op == Op::Reset) {
    removed_by_reset = set.reset();
  } else {
    change = set.complete(row.op == Op::UndefinedCompletion ? nullptr : &onset);
  }

  EXPECT_EQ(describe(set), expected_set(row.set_after));
  EXPECT_EQ(set.state(), row.after);
  EXPECT_EQ(set.state(), highest_level(set)) << "state = highest level held";
  const Condition* out = set.outstanding();
  EXPECT_EQ(out == nullptr ? std::string("-") : name_of(*out), row.outstanding);
  EXPECT_EQ(set.outstanding_event(), out == nullptr ? kNoEvent : out->event);
  for (State level : {W, E}) {
    EXPECT_EQ(set.count_at(level),
              static_cast<std::uint32_t>(
                  std::count_if(set.begin(), set.end(), [level](const Condition& c) { return c.level == level; })));
  }

  if (row.op == Op::Reset) {
    EXPECT_EQ(removed_by_reset > 0 ? Outcome::Cleared : Outcome::None, row.outcome);
    return;
  }
  EXPECT_EQ(change.outcome, row.outcome);
  EXPECT_EQ(change.from, before);
  EXPECT_EQ(change.to, row.after);
  EXPECT_EQ(std::string(change.reason), row.reason);
  switch (change.outcome) {
    case Outcome::None: {  // a refresh: count and last time only
      const Condition& x = set[x_index];
      EXPECT_EQ(x.count, 2u);
      EXPECT_EQ(x.last, kNow);
      EXPECT_EQ(x.first, Time{std::chrono::seconds(1)});
      EXPECT_EQ(activations, tokens(row.before).size()) << "a refresh is not an activation";
      break;
    }
    case Outcome::Raised:
    case Outcome::Override:
    case Outcome::Joined:
    case Outcome::Masked: {
      ASSERT_GE(change.index, 0);
      const Condition& added = set[static_cast<std::size_t>(change.index)];
      EXPECT_EQ(added.event, kX);
      EXPECT_FALSE(added.mirror);
      EXPECT_EQ(added.severity, onset.severity);
      EXPECT_EQ(added.seq, activations);
      EXPECT_EQ(added.first, kNow);
      EXPECT_EQ(added.root.event, kX);
      break;
    }
    case Outcome::Cleared:
      EXPECT_EQ(change.removed.event, kX);
      EXPECT_FALSE(change.removed.mirror);
      break;
    case Outcome::Ignored:
      if (row.reason == std::string(kLatched)) {
        ASSERT_GE(change.index, 0);
        EXPECT_EQ(set[static_cast<std::size_t>(change.index)].event, kX) << "the record names the condition that stays";
      } else {
        EXPECT_EQ(change.index, -1);
      }
      break;
    default: ADD_FAILURE() << "unexpected outcome";
  }
}

INSTANTIATE_TEST_SUITE_P(Rule, ConditionSetTable, ::testing::ValuesIn(kRows),
                         [](const ::testing::TestParamInfo<RuleRow>& row_info) {
                           return std::string(row_info.param.rule);
                         });

// The table is exhaustive: every machine state × every event kind × every subject condition that
// can exist has at least one row (X active implies a state at or above X's level; a mirror implies
// a state other than Normal).
TEST(ConditionSetTableCoverage, EveryStateEventAndSubjectCombinationHasARow) {
  std::multiset<std::tuple<State, Op, Subject>> seen;
  for (const RuleRow& row : kRows) {
    std::uint64_t activations = 0;
    seen.emplace(build(row.before, 60, activations).state(), row.op, row.subject);
  }
  for (State s : {N, W, E}) {
    for (Op op : kAllOps) {
      for (Subject subject : kAllSubjects) {
        const bool error_level_subject = op == Op::ErrorOnset || op == Op::LowerSeverityErrorOnset ||
                                         op == Op::EqualSeverityErrorOnset || op == Op::ErrorCompletion;
        // An active (or latched) X needs a state at or above its level; a mirror, any state but Normal.
        const bool possible =
            subject == Subject::Absent || s == E || (s == W && (subject == Subject::Mirrored || !error_level_subject));
        EXPECT_EQ(seen.count({s, op, subject}) > 0, possible)
            << "state " << to_string(s) << ", op " << static_cast<int>(op) << ", subject " << static_cast<int>(subject);
      }
    }
  }
}

TEST(ConditionSetTableCoverage, EveryRowStartsFromAConsistentSet) {
  for (const RuleRow& row : kRows) {
    std::uint64_t activations = 0;
    const ConditionSet set = build(row.before, 60, activations);
    const bool has_x = set.find_root(kX) >= 0;
    EXPECT_EQ(has_x, row.subject == Subject::Active || row.subject == Subject::Latched) << row.rule;
    const bool has_mirror = std::any_of(set.begin(), set.end(), [](const Condition& c) { return c.mirror; });
    EXPECT_EQ(has_mirror, row.subject == Subject::Mirrored) << row.rule;
    EXPECT_EQ(std::string(row.rule).rfind(std::string(to_string(set.state())) + "_", 0), 0u)
        << row.rule << ": the name starts with the state before";
  }
}

// ---- rules outside the table ------------------------------------------------------------------------

TEST(ConditionSet, CompletionOfALatchedOnsetThatIsNotActiveIsIgnoredAsNotActive) {
  std::uint64_t activations = 0;
  ConditionSet set = build("B:W", 60, activations);
  const Event latched = onset_event(Op::ErrorOnset, true);
  const ConditionChange change = set.complete(&latched);
  EXPECT_EQ(change.outcome, Outcome::Ignored);
  EXPECT_EQ(change.reason, ConditionSet::kIgnoredNotActive);
}

TEST(ConditionSet, AnEmptySetIsNormalWithNoOutstandingCondition) {
  const ConditionSet set;
  EXPECT_EQ(set.state(), N);
  EXPECT_TRUE(set.empty());
  EXPECT_EQ(set.outstanding(), nullptr);
  EXPECT_EQ(set.outstanding_event(), kNoEvent);
  EXPECT_EQ(set.find_lowest_root(), -1);
}

TEST(ConditionSet, OutstandingFallsBackToTheNextConditionWhenTheOutstandingClears) {
  // docs/semantics.md §4.6: a warning that outlives an error.
  std::uint64_t activations = 0;
  ConditionSet set;
  Event high = onset_event(Op::WarningOnset, false);
  high.id = EventId{1};
  high.severity = 30;
  Event error = onset_event(Op::ErrorOnset, false);
  error.id = EventId{2};
  error.severity = 50;
  EXPECT_EQ(set.onset(high, RootCause{EventId{1}, MachineId{0}, kNow, {}}, kNow, activations).outcome, Outcome::Raised);
  const ConditionChange raised = set.onset(error, RootCause{EventId{2}, MachineId{0}, kNow, {}}, kNow, activations);
  EXPECT_EQ(raised.outcome, Outcome::Raised);
  EXPECT_EQ(raised.from, W);
  EXPECT_EQ(raised.to, E);
  EXPECT_EQ(set.outstanding_event(), EventId{2});
  EXPECT_EQ(set.onset(high, RootCause{EventId{1}, MachineId{0}, kNow, {}}, kNow, activations).outcome, Outcome::None);
  const ConditionChange cleared = set.complete(&error);
  EXPECT_EQ(cleared.outcome, Outcome::Cleared);
  EXPECT_EQ(cleared.to, W);
  EXPECT_EQ(set.outstanding_event(), EventId{1});
  EXPECT_EQ(set.complete(&high).to, N);
  EXPECT_EQ(set.outstanding(), nullptr);
}

TEST(ConditionSet, EqualSeverityTiesGoToTheMostRecentActivationNotTheMostRecentRefresh) {
  std::uint64_t activations = 0;
  ConditionSet set;
  Event a = onset_event(Op::ErrorOnset, false);
  a.id = EventId{1};
  Event b = onset_event(Op::ErrorOnset, false);
  b.id = EventId{2};
  set.onset(a, RootCause{EventId{1}, MachineId{0}, kNow, {}}, kNow, activations);
  set.onset(b, RootCause{EventId{2}, MachineId{0}, kNow, {}}, kNow, activations);
  EXPECT_EQ(set.outstanding_event(), EventId{2});
  set.onset(a, RootCause{EventId{1}, MachineId{0}, kNow, {}}, kNow + std::chrono::seconds(1), activations);  // refresh
  EXPECT_EQ(set.outstanding_event(), EventId{2});
}

TEST(ConditionSet, AMirrorIsFoundByItsRootCauseOnly) {
  std::uint64_t activations = 0;
  ConditionSet set = build("M:E", 60, activations);
  EXPECT_EQ(set.find_mirror(RootCause{kMirrorRoot, MachineId{9}, {}, {}}), 0);
  EXPECT_EQ(set.find_mirror(RootCause{kMirrorRoot, MachineId{8}, {}, {}}), -1) << "another origin";
  EXPECT_EQ(set.find_mirror(RootCause{kX, MachineId{9}, {}, {}}), -1) << "another event";
  RootCause remote{kMirrorRoot, MachineId{9}, {}, {}};
  remote.remote = 3;
  EXPECT_EQ(set.find_mirror(remote), -1) << "another remote root";
  EXPECT_EQ(set.find_root(kX), -1) << "a mirror is not a root";
}

TEST(ConditionSet, ResetRemovesWarningRootsBeforeErrorRoots) {
  std::uint64_t activations = 0;
  ConditionSet set = build("X:E B:W", 60, activations);
  const std::int32_t first = set.find_lowest_root();
  ASSERT_GE(first, 0);
  EXPECT_EQ(set[static_cast<std::size_t>(first)].level, W);
  EXPECT_EQ(set.reset(), 2u);
  EXPECT_EQ(set.state(), N);
}

TEST(ConditionSet, SeededRandomChangesKeepStateAndOutstandingConsistentWhateverTheSize) {
  // Invariants (docs/semantics.md §4.1, §4.4) after every change, with sets growing past the one
  // condition held inline and shrinking back: state = highest level held; outstanding = highest
  // severity at that level, most recent activation on ties; at most one root per event.
  std::uint64_t activations = 0;
  ConditionSet set;
  std::uint32_t seed = 12345;
  auto next = [&seed](std::uint32_t n) {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) % n;
  };
  for (int step = 0; step < 5000; ++step) {
    const EventId id{next(8)};
    Event e;
    e.id = id;
    e.severity = static_cast<std::uint8_t>(10 + 10 * (to_index(id) % 4));
    e.transitions =
        to_index(id) % 2 == 0 ? TransitionSet{Transition::N2W} : TransitionSet{Transition::N2E, Transition::W2E};
    e.latched = id == EventId{7};
    switch (next(4)) {
      case 0:
      case 1: set.onset(e, RootCause{id, MachineId{0}, kNow, {}}, kNow, activations); break;
      case 2: set.complete(&e); break;
      default:
        if (next(20) == 0) set.reset();
        break;
    }
    ASSERT_EQ(set.state(), highest_level(set));
    const Condition* best = nullptr;
    for (const Condition& c : set) {
      if (c.level != set.state()) continue;
      if (best == nullptr || c.severity > best->severity || (c.severity == best->severity && c.seq > best->seq))
        best = &c;
    }
    ASSERT_EQ(set.outstanding(), best);
    std::set<EventId> roots;
    for (const Condition& c : set) ASSERT_TRUE(roots.insert(c.event).second) << "one root per event";
  }
}

TEST(ConditionSet, ACopyIsIndependentOfItsOriginal) {
  std::uint64_t activations = 0;
  ConditionSet one = build("X:E", 60, activations);
  ConditionSet many = build("B:W X:E", 60, activations);
  const ConditionSet one_copy = one;
  const ConditionSet many_copy = many;
  one.reset();
  many.reset();
  EXPECT_EQ(describe(one_copy), expected_set("X:E"));
  EXPECT_EQ(describe(many_copy), expected_set("B:W X:E"));
  EXPECT_EQ(many_copy.outstanding()->event, kX);
  EXPECT_TRUE(one.empty());
  EXPECT_TRUE(many.empty());
}

}  // namespace
}  // namespace safecass
