// The "hazards" and "invariants" sections of a system file (docs/spec-format.md §2.1) and the
// invariant grammar (spec/formula.hpp). The diagnostics of broken sections are golden files in
// tests/data/bad_specs/ (hazard_*.json, invariant_*.json).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "safecass/spec/formula.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

std::string arm_system(const std::string& sections, const std::string& hazard = "H-3") {
  return R"({"safecass": 1, "system": "arm", )" + sections + R"(
  "components": [{"component": "ARM", "interfaces": {"provided": ["Motion"]}, "signals": [{"name": "Force"}],
    "event": [{"name": "EVT_F", "severity": 50, "state_transition": ["N2E"], "hazard": ")" +
         hazard + R"("},
              {"name": "/EVT_F", "severity": 50, "state_transition": ["E2N"]}],
    "filter": [{"class_name": "Threshold", "argument": {"input_signal": "Force", "threshold": 1,
                "event_onset": "EVT_F", "event_completion": "/EVT_F"}}]}]})";
}

TEST(SpecHazards, RobodocDeclaresItsHazardsWithReactionsOnControlAndServo) {
  const LoadResult r = load_system("examples/robodoc/robodoc.json", builtin_registry());
  ASSERT_TRUE(r.ok());
  const SystemSpec& s = *r.system;
  for (const char* id : {"H-3", "H-5", "H-6"}) {
    const HazardSpec* h = s.hazard(id);
    ASSERT_NE(h, nullptr) << id;
    EXPECT_THAT(h->reaction, ::testing::ElementsAre(std::pair<std::string, State>{"CONTROL", State::Error},
                                                    std::pair<std::string, State>{"SERVO", State::Error}))
        << id;
    EXPECT_EQ(h->where.file, "examples/robodoc/robodoc.json");
    EXPECT_GT(h->where.line, 0);
  }
  ASSERT_EQ(s.invariants.size(), 1u);
  EXPECT_EQ(s.invariants[0].name, "servo_follows_control");
  // Every hazard has a linked onset: no "no linked event" warning.
  for (const Diagnostic& d : r.diagnostics)
    EXPECT_EQ(d.message.find("no linked event"), std::string::npos) << format(d);
}

TEST(SpecHazards, EventPositionsAreKeptForEveryEvent) {
  const LoadResult r = load_system("examples/robodoc/robodoc.json", builtin_registry());
  ASSERT_TRUE(r.ok());
  for (const ComponentSpec& c : r.system->components) {
    ASSERT_EQ(c.event_where.size(), c.events.size()) << c.name;
    for (const Position& p : c.event_where) EXPECT_GT(p.line, 0);
  }
}

TEST(SpecHazards, WithoutAHazardsSectionHazardIdsAreFreeText) {
  const LoadResult r = load_system_from_text(arm_system("", "H-anything"), "arm.json", builtin_registry());
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.diagnostics.empty()) << (r.diagnostics.empty() ? "" : format(r.diagnostics[0]));
}

TEST(SpecHazards, UnknownHazardIdIsAnErrorAtTheEventsHazardField) {
  const LoadResult r =
      load_system_from_text(arm_system(R"("hazards": [{"id": "H-3"}],)", "H-4"), "arm.json", builtin_registry());
  ASSERT_EQ(r.errors(), 1u);
  const auto error = std::find_if(r.diagnostics.begin(), r.diagnostics.end(),
                                  [](const Diagnostic& d) { return d.severity == Diagnostic::Severity::Error; });
  EXPECT_THAT(error->message, ::testing::HasSubstr("names hazard 'H-4'"));
  EXPECT_EQ(error->pointer, "/components/0/event/0/hazard");
}

TEST(SpecHazards, ReactionOnAnAddressThatDoesNotExistIsAnError) {
  const LoadResult r = load_system_from_text(
      arm_system(R"("hazards": [{"id": "H-3", "reaction": {"ARM.s_S.Motion": "Error", "ARM.s_P.Nope": "Error"}}],)"),
      "arm.json", builtin_registry());
  ASSERT_EQ(r.errors(), 1u);
  EXPECT_THAT(r.diagnostics[0].message, ::testing::HasSubstr("'ARM.s_P.Nope', which does not exist"));
}

TEST(SpecHazards, HazardWithNoLinkedEventIsOnlyAWarning) {
  const LoadResult r = load_system_from_text(
      arm_system(R"("hazards": [{"id": "H-3"}, {"id": "H-9", "description": "nothing detects it"}],)"), "arm.json",
      builtin_registry());
  EXPECT_TRUE(r.ok());
  ASSERT_EQ(r.warnings(), 1u);
  EXPECT_THAT(r.diagnostics[0].message, ::testing::HasSubstr("hazard 'H-9' has no linked event"));
}

TEST(SpecHazards, InvariantFormulaErrorsPointIntoTheString) {
  const std::string text = arm_system(R"x("invariants": [{"name": "i", "formula": "[] (ARM.s_A == Eror)"}],)x");
  const LoadResult r = load_system_from_text(text, "arm.json", builtin_registry());
  ASSERT_EQ(r.errors(), 1u);
  const Diagnostic& d = r.diagnostics[0];
  EXPECT_THAT(d.message, ::testing::HasSubstr("expected a level"));
  const std::size_t quote = text.find("\"[] (ARM");
  EXPECT_EQ(static_cast<std::size_t>(d.where.column), quote + 1 + 1 + std::string("[] (ARM.s_A == ").size());
}

// ---- the grammar ------------------------------------------------------------------------------

TEST(InvariantGrammar, ImplicationBindsWeakerThanDisjunctionAndConjunction) {
  const auto f = parse_formula("[] (A.s_A == Error && B >= Warning || C != Normal -> D == Error)");
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(to_string(*f), "[](((A.s_A == Error && B >= Warning) || C != Normal) -> D == Error)");
  EXPECT_TRUE(f->is_state_invariant());
}

TEST(InvariantGrammar, ImplicationIsRightAssociativeAndUntilBindsTighterThanAnd) {
  const auto f = parse_formula("a == Error -> b == Error -> c == Error U d == Normal && true");
  ASSERT_TRUE(f);
  EXPECT_EQ(to_string(*f), "(a == Error -> (b == Error -> ((c == Error U d == Normal) && true)))");
}

TEST(InvariantGrammar, UntilNeedsComparisonsOnBothSides) {
  const auto f = parse_formula("c U d == Normal");
  ASSERT_FALSE(f);
  EXPECT_THAT(f.error().message, ::testing::HasSubstr("after address 'c'"));
}

TEST(InvariantGrammar, TemporalFormulasAreNotStateInvariants) {
  const auto f = parse_formula("[] (X == Error -> <> X == Normal)");
  ASSERT_TRUE(f);
  EXPECT_FALSE(f->is_state_invariant());
  EXPECT_FALSE(f->is_propositional());
  std::vector<const Formula*> atoms;
  f->atoms(atoms);
  ASSERT_EQ(atoms.size(), 2u);
  EXPECT_EQ(atoms[0]->address, "X");
  EXPECT_EQ(atoms[1]->level, State::Normal);
}

TEST(InvariantGrammar, EveryComparisonAndLevelParses) {
  for (const char* op : {"==", "!=", "<", "<=", ">", ">="}) {
    for (const char* level : {"Normal", "Warning", "Error"}) {
      const auto f = parse_formula(std::string("SYSTEM ") + op + " " + level);
      ASSERT_TRUE(f) << op << level;
      EXPECT_EQ(std::string(to_string(f->compare)), op);
    }
  }
  EXPECT_TRUE(holds(Formula::Compare::Ge, State::Error, State::Warning));
  EXPECT_FALSE(holds(Formula::Compare::Lt, State::Error, State::Warning));
}

TEST(InvariantGrammar, ErrorsSayWhatAndWhere) {
  struct Case {
    const char* text;
    const char* message;
    std::size_t offset;
  };
  for (const Case& c : {Case{"", "ends where", 0}, Case{"A == Error)", "after the end", 10},
                        Case{"A = Error", "comparison", 2}, Case{"(A == Error", "to close", 11},
                        Case{"A == Fine", "expected a level", 5}, Case{"[] && A == Error", "expected an address", 3}}) {
    const auto f = parse_formula(c.text);
    ASSERT_FALSE(f) << c.text;
    EXPECT_THAT(f.error().message, ::testing::HasSubstr(c.message)) << c.text;
    EXPECT_EQ(f.error().offset, c.offset) << c.text;
  }
}

TEST(InvariantGrammar, DeepNestingIsRefusedNotACrash) {
  const auto f = parse_formula(std::string(10000, '!') + "A == Error");
  ASSERT_FALSE(f);
  EXPECT_THAT(f.error().message, ::testing::HasSubstr("nested deeper"));
}

}  // namespace
}  // namespace safecass::spec
