#pragma once
/// @file formula.hpp
/// Invariants of a system file (`"invariants"`): linear temporal logic over the states of
/// addresses (docs/verify.md). Grammar, lowest precedence first:
///
///     formula := equiv
///     equiv   := implies ( '<->' implies )*
///     implies := or ( '->' implies )?              (right-associative)
///     or      := and ( '||' and )*
///     and     := until ( '&&' until )*
///     until   := unary ( 'U' unary )?
///     unary   := '!' unary | '[]' unary | '<>' unary | '(' formula ')' | 'true' | 'false' | atom
///     atom    := ADDRESS ( '==' | '!=' | '<' | '<=' | '>' | '>=' ) LEVEL
///
/// ADDRESS is SYSTEM, C, C.s_F, C.s_A, C.s_P.p, C.s_R.r or C.s_S.p; LEVEL is Normal, Warning
/// or Error (ordered Normal < Warning < Error). The parser checks the syntax only; the loader
/// checks that the addresses exist.

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"

namespace safecass::spec {

struct Formula {
  enum class Kind { True, False, Atom, Not, And, Or, Implies, Equiv, Always, Eventually, Until };
  enum class Compare { Eq, Ne, Lt, Le, Gt, Ge };
  Kind kind = Kind::True;
  // Atom
  std::string address;
  Compare compare = Compare::Eq;
  State level = State::Normal;
  std::size_t offset = 0;  ///< byte offset of the atom (or operator) in the text
  std::vector<Formula> operands;

  /// True when the formula is `[] P` with P free of temporal operators (a safety invariant that
  /// is checked in every reachable state).
  bool is_state_invariant() const;
  /// True when no operand is temporal.
  bool is_propositional() const;
  /// Every atom, in text order.
  void atoms(std::vector<const Formula*>& out) const;
};

/// A syntax error: what, and the byte offset in the text where it was found.
struct FormulaError {
  std::string message;
  std::size_t offset = 0;
};

/// Parses `text`. Never throws.
[[nodiscard]] tl::expected<Formula, FormulaError> parse_formula(std::string_view text);

/// The formula written back in the grammar above, fully parenthesised.
std::string to_string(const Formula& f);

/// "==", "!=", ...
std::string_view to_string(Formula::Compare c) noexcept;

/// Whether `state` satisfies the atom's comparison.
bool holds(Formula::Compare c, State state, State level) noexcept;

}  // namespace safecass::spec
