#pragma once
/// @file state.hpp
/// The three GCM states, the state product and the six transitions (DESIGN §2.1, §2.3).

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string_view>

namespace safecass {

/// Operational status of a state machine, ordered by severity: Normal < Warning < Error.
enum class State : std::uint8_t { Normal = 0, Warning = 1, Error = 2 };

/// The state product a ⊗ b: the more severe of the two. Associative, commutative, idempotent,
/// with Normal as identity, so any summary is independent of the order it is computed in.
constexpr State product(State a, State b) noexcept { return a < b ? b : a; }
constexpr State operator*(State a, State b) noexcept { return product(a, b); }

/// A transition between two different states.
enum class Transition : std::uint8_t { N2W, N2E, W2E, W2N, E2N, E2W };

/// A set of transitions, as listed by an event's `state_transition`.
class TransitionSet {
public:
  constexpr TransitionSet() noexcept = default;
  constexpr TransitionSet(std::initializer_list<Transition> ts) noexcept {
    for (Transition t : ts) insert(t);
  }
  constexpr void insert(Transition t) noexcept { bits_ |= bit(t); }
  constexpr bool contains(Transition t) const noexcept { return (bits_ & bit(t)) != 0; }
  constexpr bool empty() const noexcept { return bits_ == 0; }
  /// True when the set holds only N2W, N2E, W2E (and is not empty).
  constexpr bool worsening_only() const noexcept { return !empty() && (bits_ & kImproving) == 0; }
  /// True when the set holds only W2N, E2N, E2W (and is not empty).
  constexpr bool improving_only() const noexcept { return !empty() && (bits_ & kWorsening) == 0; }
  constexpr std::uint8_t bits() const noexcept { return bits_; }
  friend constexpr bool operator==(TransitionSet a, TransitionSet b) noexcept { return a.bits_ == b.bits_; }
  friend constexpr bool operator!=(TransitionSet a, TransitionSet b) noexcept { return a.bits_ != b.bits_; }

private:
  static constexpr std::uint8_t bit(Transition t) noexcept {
    return static_cast<std::uint8_t>(1u << static_cast<unsigned>(t));
  }
  static constexpr std::uint8_t kWorsening = 0b000111;
  static constexpr std::uint8_t kImproving = 0b111000;
  std::uint8_t bits_ = 0;
};

/// The transition from `from` to `to`; `from` and `to` must differ.
constexpr Transition transition_between(State from, State to) noexcept {
  switch (from) {
    case State::Normal: return to == State::Warning ? Transition::N2W : Transition::N2E;
    case State::Warning: return to == State::Error ? Transition::W2E : Transition::W2N;
    case State::Error: break;
  }
  return to == State::Normal ? Transition::E2N : Transition::E2W;
}

constexpr State source_of(Transition t) noexcept {
  switch (t) {
    case Transition::N2W:
    case Transition::N2E: return State::Normal;
    case Transition::W2E:
    case Transition::W2N: return State::Warning;
    case Transition::E2N:
    case Transition::E2W: break;
  }
  return State::Error;
}

constexpr State target_of(Transition t) noexcept {
  switch (t) {
    case Transition::W2N:
    case Transition::E2N: return State::Normal;
    case Transition::N2W:
    case Transition::E2W: return State::Warning;
    case Transition::N2E:
    case Transition::W2E: break;
  }
  return State::Error;
}

/// "Normal", "Warning", "Error".
std::string_view to_string(State s) noexcept;
/// "N2W", "N2E", ...
std::string_view to_string(Transition t) noexcept;
/// Parses "Normal"/"Warning"/"Error" (also "N"/"W"/"E", any case).
std::optional<State> parse_state(std::string_view text) noexcept;
/// Parses "N2W", "N2E", "W2E", "W2N", "E2N", "E2W".
std::optional<Transition> parse_transition(std::string_view text) noexcept;

}  // namespace safecass
