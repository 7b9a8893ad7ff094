// DESIGN §2.1: the three states and the state product; §2.3: the six transitions.

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "core_test_support.hpp"
#include "safecass/core/observer.hpp"
#include "safecass/core/state.hpp"

namespace safecass {
namespace {

using test::E;
using test::N;
using test::W;

constexpr std::array<State, 3> kStates{State::Normal, State::Warning, State::Error};
constexpr std::array<Transition, 6> kTransitions{Transition::N2W, Transition::N2E, Transition::W2E,
                                                 Transition::W2N, Transition::E2N, Transition::E2W};

TEST(StateOrder, NormalIsLessSevereThanWarningWhichIsLessSevereThanError) {
  EXPECT_LT(State::Normal, State::Warning);
  EXPECT_LT(State::Warning, State::Error);
  EXPECT_LT(State::Normal, State::Error);
}

TEST(StateProduct, IsTheMoreSevereOfTheTwoForEveryPair) {
  // Written out by hand: row = a, column = b.
  const std::array<std::array<State, 3>, 3> expected{{{N, W, E}, {W, W, E}, {E, E, E}}};
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::size_t b = 0; b < 3; ++b) {
      EXPECT_EQ(product(kStates[a], kStates[b]), expected[a][b])
          << to_string(kStates[a]) << " x " << to_string(kStates[b]);
      EXPECT_EQ(kStates[a] * kStates[b], expected[a][b]) << "operator* must equal product()";
    }
  }
}

TEST(StateProduct, IsAssociativeOverAllTwentySevenTriples) {
  int triples = 0;
  for (State a : kStates) {
    for (State b : kStates) {
      for (State c : kStates) {
        EXPECT_EQ((a * b) * c, a * (b * c)) << to_string(a) << ", " << to_string(b) << ", " << to_string(c);
        // And the triple product is the maximum of the three, whatever the grouping.
        State max = a;
        if (b > max) max = b;
        if (c > max) max = c;
        EXPECT_EQ(a * b * c, max);
        ++triples;
      }
    }
  }
  EXPECT_EQ(triples, 27);
}

TEST(StateProduct, IsCommutativeOverAllTwentySevenTriplesInEveryOrder) {
  for (State a : kStates) {
    for (State b : kStates) {
      EXPECT_EQ(a * b, b * a);
      for (State c : kStates) {
        const State abc = a * b * c;
        EXPECT_EQ(abc, a * c * b);
        EXPECT_EQ(abc, b * a * c);
        EXPECT_EQ(abc, b * c * a);
        EXPECT_EQ(abc, c * a * b);
        EXPECT_EQ(abc, c * b * a);
      }
    }
  }
}

TEST(StateProduct, IsIdempotent) {
  for (State a : kStates) EXPECT_EQ(a * a, a) << to_string(a);
}

TEST(StateProduct, HasNormalAsIdentityOnBothSides) {
  for (State a : kStates) {
    EXPECT_EQ(State::Normal * a, a) << to_string(a);
    EXPECT_EQ(a * State::Normal, a) << to_string(a);
  }
}

TEST(StateProduct, HasErrorAsAbsorbingElement) {
  for (State a : kStates) EXPECT_EQ(a * State::Error, State::Error) << to_string(a);
}

TEST(StateProduct, IsUsableInConstantExpressions) {
  static_assert(product(State::Warning, State::Normal) == State::Warning);
  static_assert((State::Normal * State::Error) == State::Error);
  SUCCEED();
}

TEST(Transitions, TransitionBetweenNamesEveryOrderedPairOfDifferentStates) {
  EXPECT_EQ(transition_between(N, W), Transition::N2W);
  EXPECT_EQ(transition_between(N, E), Transition::N2E);
  EXPECT_EQ(transition_between(W, E), Transition::W2E);
  EXPECT_EQ(transition_between(W, N), Transition::W2N);
  EXPECT_EQ(transition_between(E, N), Transition::E2N);
  EXPECT_EQ(transition_between(E, W), Transition::E2W);
}

TEST(Transitions, SourceAndTargetAreTheStatesTheTransitionConnects) {
  struct Row {
    Transition t;
    State from;
    State to;
  };
  const Row rows[] = {{Transition::N2W, N, W}, {Transition::N2E, N, E}, {Transition::W2E, W, E},
                      {Transition::W2N, W, N}, {Transition::E2N, E, N}, {Transition::E2W, E, W}};
  for (const Row& r : rows) {
    EXPECT_EQ(source_of(r.t), r.from) << to_string(r.t);
    EXPECT_EQ(target_of(r.t), r.to) << to_string(r.t);
    EXPECT_EQ(transition_between(source_of(r.t), target_of(r.t)), r.t) << to_string(r.t);
  }
}

TEST(Transitions, WorseningTransitionsRaiseAndImprovingTransitionsLowerTheState) {
  for (Transition t : kTransitions) {
    const bool worsening = t == Transition::N2W || t == Transition::N2E || t == Transition::W2E;
    EXPECT_EQ(target_of(t) > source_of(t), worsening) << to_string(t);
    EXPECT_EQ(TransitionSet{t}.worsening_only(), worsening) << to_string(t);
    EXPECT_EQ(TransitionSet{t}.improving_only(), !worsening) << to_string(t);
  }
}

TEST(TransitionSet, HoldsExactlyTheTransitionsInserted) {
  for (unsigned mask = 0; mask < 64; ++mask) {
    TransitionSet s;
    for (unsigned i = 0; i < 6; ++i) {
      if ((mask & (1u << i)) != 0) s.insert(kTransitions[i]);
    }
    EXPECT_EQ(s.empty(), mask == 0);
    for (unsigned i = 0; i < 6; ++i) {
      EXPECT_EQ(s.contains(kTransitions[i]), (mask & (1u << i)) != 0) << "mask " << mask;
    }
    EXPECT_EQ(s.worsening_only(), mask != 0 && (mask & 0b111000u) == 0) << "mask " << mask;
    EXPECT_EQ(s.improving_only(), mask != 0 && (mask & 0b000111u) == 0) << "mask " << mask;
  }
}

TEST(TransitionSet, EmptySetIsNeitherOnsetNorCompletion) {
  const TransitionSet empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_FALSE(empty.worsening_only());
  EXPECT_FALSE(empty.improving_only());
}

TEST(TransitionSet, MixedSetIsNeitherOnsetNorCompletion) {
  const TransitionSet mixed{Transition::N2E, Transition::E2N};
  EXPECT_FALSE(mixed.worsening_only());
  EXPECT_FALSE(mixed.improving_only());
}

TEST(TransitionSet, EqualityComparesMembersNotInsertionOrder) {
  EXPECT_EQ((TransitionSet{Transition::N2E, Transition::W2E}), (TransitionSet{Transition::W2E, Transition::N2E}));
  EXPECT_NE((TransitionSet{Transition::N2E}), (TransitionSet{Transition::N2E, Transition::W2E}));
}

TEST(StateText, ToStringGivesTheModelNames) {
  EXPECT_EQ(to_string(State::Normal), "Normal");
  EXPECT_EQ(to_string(State::Warning), "Warning");
  EXPECT_EQ(to_string(State::Error), "Error");
}

TEST(StateText, ParseStateRoundTripsEveryState) {
  for (State s : kStates) {
    const auto parsed = parse_state(to_string(s));
    ASSERT_TRUE(parsed.has_value()) << to_string(s);
    EXPECT_EQ(*parsed, s);
  }
}

TEST(StateText, ParseStateAcceptsInitialsAndAnyCase) {
  EXPECT_EQ(parse_state("N"), State::Normal);
  EXPECT_EQ(parse_state("w"), State::Warning);
  EXPECT_EQ(parse_state("E"), State::Error);
  EXPECT_EQ(parse_state("error"), State::Error);
  EXPECT_EQ(parse_state("WARNING"), State::Warning);
  EXPECT_EQ(parse_state("nOrMaL"), State::Normal);
}

TEST(StateText, ParseStateRejectsAnythingElse) {
  for (const char* bad : {"", "X", "Norm", "Errors", "Normal ", " Error", "NW", "0", "Fault"}) {
    EXPECT_FALSE(parse_state(bad).has_value()) << "'" << bad << "'";
  }
}

TEST(TransitionText, ToStringAndParseRoundTripEveryTransition) {
  const char* names[] = {"N2W", "N2E", "W2E", "W2N", "E2N", "E2W"};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(to_string(kTransitions[i]), names[i]);
    const auto parsed = parse_transition(names[i]);
    ASSERT_TRUE(parsed.has_value()) << names[i];
    EXPECT_EQ(*parsed, kTransitions[i]);
  }
}

TEST(TransitionText, ParseTransitionRejectsUnknownText) {
  for (const char* bad : {"", "N2N", "E2E", "W2W", "N2", "N2WE", "normal", "2W"}) {
    EXPECT_FALSE(parse_transition(bad).has_value()) << "'" << bad << "'";
  }
}

TEST(RecordText, EveryRecordKindAndOutcomeHasADistinctName) {
  const RecordKind kinds[] = {RecordKind::Event, RecordKind::Transition, RecordKind::ComponentTransition,
                              RecordKind::Reset, RecordKind::Injection};
  const Outcome outcomes[] = {Outcome::None,   Outcome::Raised,  Outcome::Override, Outcome::Joined,
                              Outcome::Masked, Outcome::Cleared, Outcome::Ignored};
  std::vector<std::string> seen;
  for (RecordKind k : kinds) seen.emplace_back(to_string(k));
  for (Outcome o : outcomes) seen.emplace_back(to_string(o));
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_NE(seen[i], "?");
    EXPECT_FALSE(seen[i].empty());
  }
  EXPECT_EQ(to_string(Outcome::Masked), "masked");
  EXPECT_EQ(to_string(Outcome::Override), "override");
  EXPECT_EQ(to_string(Outcome::Ignored), "ignored");
  EXPECT_EQ(to_string(RecordKind::Reset), "reset");
  // Outcomes are distinct from one another.
  for (std::size_t i = std::size(kinds); i < seen.size(); ++i) {
    for (std::size_t j = i + 1; j < seen.size(); ++j) EXPECT_NE(seen[i], seen[j]);
  }
}

}  // namespace
}  // namespace safecass
