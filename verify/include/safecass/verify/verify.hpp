#pragma once
/// @file verify.hpp
/// `safecass verify` (docs/verify.md): a system is translated into Promela and model-checked
/// with SPIN. The model has every onset that can occur (filter events on their filters'
/// targets, events a component declares but no filter generates on its s_A, broadcasts on every
/// s_A), their completions and resets in any order, and the coordinator's rules (DESIGN §2.3,
/// §2.4, §2.6): the onset level depends on the state when the onset arrives, latched conditions
/// clear only by reset, propagation follows services and connections (cycles included) with
/// their propagation levels. It checks every hazard reaction and every invariant, and reports
/// three properties of the specification itself. A violated property's shortest counterexample
/// is written as a scenario that `safecass run` replays and fails at its last step.
///
/// Multi-process systems are modelled as one process with synchronous propagation; asynchrony
/// across processes is a documented limit.
///
/// Not thread-safe; runs `spin` and the system's C compiler as child processes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::verify {

struct Options {
  std::string property;          ///< only this property (a hazard id or an invariant name); empty: all
  std::string out_dir;           ///< write counterexample scenarios (and the Promela of violated properties) here
  std::size_t memory_mb = 4096;  ///< SPIN's memory bound per property (pan -DMEMLIM)
  bool slice = true;             ///< keep only the onsets that can influence a property (cone of influence)
  bool merge = true;             ///< count interchangeable onsets instead of tracking each one
  std::string spin = "spin";     ///< the SPIN executable
  std::string cc = "cc";         ///< the C compiler for SPIN's verifier
  std::string work_dir;          ///< where SPIN's files go (default: a fresh temporary directory, removed)
};

/// One property and its verdict.
struct PropertyResult {
  enum class Kind { Reaction, Invariant, NeedsReset, Undetectable, NeverLeavesNormal };
  enum class Verdict { Holds, Violated, Undecided };
  Kind kind = Kind::Reaction;
  Verdict verdict = Verdict::Holds;
  std::string name;              ///< hazard id, invariant name, or the finding's subject
  std::string text;              ///< what is checked, for people
  std::string message;           ///< for a violation or a finding: what and why
  spec::Position where;          ///< what it concerns, in the specification
  bool structural = false;       ///< decided on the model's structure (no state search)
  std::uint64_t states = 0;      ///< states SPIN stored
  double memory_mb = 0.0;        ///< SPIN's total memory
  double seconds = 0.0;          ///< translation, compilation and search
  std::size_t onsets = 0;        ///< onset classes in this property's model (after slicing and merging)
  std::size_t onsets_total = 0;  ///< onsets the system has
  std::string scenario;          ///< the counterexample scenario written (violations with out_dir)
  std::string advice;            ///< Undecided: which abstraction would help
};

struct Report {
  std::string system;
  std::vector<PropertyResult> properties;
  double seconds = 0.0;
  /// 0 every reaction and invariant holds; 1 one is violated; 3 one could not be decided within
  /// the limits (nothing violated). Findings about the specification itself are warnings.
  int exit_code() const;
};

/// Verifies `system` (loaded without errors). Errors: NotFound (an unknown `property`), Io (SPIN or
/// the compiler cannot be run, a file cannot be written), InvalidArgument (the system cannot be
/// built into a coordinator).
[[nodiscard]] Expected<Report> verify(const spec::SystemSpec& system, const FilterRegistry& registry,
                                      const Options& options);

/// A step of the model, as applied to a coordinator: an onset or a completion (`event` on
/// `target`; a broadcast has an empty target), or a reset of machine `target`.
struct Step {
  enum class Kind { Generate, Reset };
  Kind kind = Kind::Generate;
  std::string event;
  std::string target;
};

/// A random run of the Promela model (SPIN's random simulation, seeded): the steps it took and,
/// after each one, the state of every address in `addresses`, as the model computed them.
struct Simulation {
  std::vector<std::string> addresses;  ///< SYSTEM, components, machines, services
  std::vector<Step> steps;
  std::vector<std::vector<State>> states;  ///< states[k][a]: after step k, address a
};

/// Runs the whole model (no slicing, no merging) for `steps` steps with SPIN's random simulation
/// seeded with `seed`. Errors as verify().
[[nodiscard]] Expected<Simulation> simulate(const spec::SystemSpec& system, const FilterRegistry& registry,
                                            unsigned seed, std::size_t steps, const Options& options = {});

/// The text of the model of the whole system (for people and tests), one property per check.
[[nodiscard]] Expected<std::string> promela(const spec::SystemSpec& system, const FilterRegistry& registry);

std::string_view to_string(PropertyResult::Kind kind) noexcept;
std::string_view to_string(PropertyResult::Verdict verdict) noexcept;

}  // namespace safecass::verify
