#pragma once
// Writing a Model (or the part of it a property needs) as Promela (docs/verify.md §1).

#include <cstddef>
#include <string>
#include <vector>

#include "model.hpp"

namespace safecass::verify {

/// What the Promela text is for.
struct PromelaSpec {
  std::string title;                   ///< first comment line
  std::vector<RootClass> classes;      ///< the variables
  std::vector<std::size_t> addresses;  ///< addresses the property (or the printing) reads
  /// The properties, as named LTL claims (SPIN syntax) over the macros ST_<a> (a in
  /// `addresses`) and ACTIVE_<c> (classes); the verifier checks one at a time (pan -N name).
  std::vector<std::pair<std::string, std::string>> claims;
  /// Print every address's state after every step (random simulation).
  bool print_states = false;
};

/// The Promela text. Steps print "@ on C", "@ off C L", "@ reset M", "@ bon B", "@ boff B" (C a
/// class index, L 1 or 2, M a machine id, B a broadcast index) so that a trail replayed by
/// `spin -t` (or a random simulation) can be turned back into scenario steps; with
/// print_states, "@ st s0 s1 ..." follows each step.
std::string write_promela(const Model& model, const PromelaSpec& spec);

/// `state(a) op level` without conditional expressions (SPIN's LTL parser has none), over the
/// ERR_<a> and WARN_<a> macros.
std::string compare_text(std::size_t address, spec::Formula::Compare op, State level);

/// A formula (spec/formula.hpp) in terms of ST_<a> macros; `ltl`: SPIN's LTL syntax (else a C
/// expression, for propositional formulas). Addresses must be in the model.
std::string formula_text(const Model& model, const spec::Formula& f, bool ltl);

}  // namespace safecass::verify
