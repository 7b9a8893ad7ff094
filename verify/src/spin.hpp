#pragma once
// Running SPIN: the Promela text → pan.c → the verifier (compiled with the system's C compiler)
// → its verdict, statistics and trail; random simulation; trail replay.

#include <cstdint>
#include <string>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/verify/command.hpp"

namespace safecass::verify {

struct PanOptions {
  bool ltl = false;  ///< search for acceptance cycles (-a), depth-first; else safety, breadth-first
  std::size_t memory_mb = 4096;
  int hash_bits = 20;     ///< -w
  bool optimise = false;  ///< compile the verifier with -O1: for searches long enough to repay it (-O1
                          ///< runs within 5 % of -O2 and compiles in half the time)
  bool shortest = true;   ///< safety: breadth-first, so that a trail is a shortest one (else depth-first:
                          ///< faster, half the memory, any trail)
  std::string spin = "spin";
  std::string cc = "cc";
};

struct PanResult {
  enum class Outcome { Holds, Violated, MemoryLimit, Failed } outcome = Outcome::Failed;
  std::uint64_t states = 0;
  double memory_mb = 0.0;
  std::string output;              ///< pan's report, for diagnosis
  std::vector<std::string> trail;  ///< the "@ ..." lines of the counterexample, in order
  bool cycle = false;              ///< LTL: the trail ends in a cycle (starting at `cycle_start`)
  std::size_t cycle_start = 0;
};

/// Writes `model` as `name`.pml in `dir`, generates SPIN's verifier and compiles it (once for
/// all the model's claims). Safety verifiers search breadth-first, so a trail is a shortest one.
/// Returns the verifier's file name in `dir`. Errors: Io (SPIN or the compiler failed).
[[nodiscard]] Expected<std::string> compile(const std::string& dir, const std::string& name, const std::string& model,
                                            const PanOptions& options);

/// Checks claim `claim` (empty: the model's assertions only) with the verifier `binary` of model
/// `name`; on a violation, replays the trail (pan -r). Errors: Io.
[[nodiscard]] Expected<PanResult> check_claim(const std::string& dir, const std::string& name,
                                              const std::string& binary, const std::string& claim,
                                              const PanOptions& options);

/// SPIN's random simulations of `model`, one per seed in [first_seed, first_seed + runs), each for
/// at most `steps` steps, given to `each`. The model is preprocessed once, by `cc` as SPIN does it
/// (`-std=gnu99 -E -x c`), and every run reads that text (`spin -Pcat`): a run costs SPIN's parse
/// and simulation, not the preprocessor's too (on robodoc's bus model 37 ms a run, against 71 ms
/// preprocessing each time).
/// Errors: Io.
[[nodiscard]] Expected<void> simulate_model(const std::string& dir, const std::string& model, unsigned first_seed,
                                            unsigned runs, std::size_t steps, const std::string& spin,
                                            const std::string& cc, const SimulationRun& each);

/// An Io error unless the C compiler `cc` runs.
[[nodiscard]] Expected<void> compiler_check(const std::string& cc);

/// "Spin Version 6.5.2 -- ..." or an Io error saying SPIN is not installed.
[[nodiscard]] Expected<std::string> spin_version(const std::string& spin);

}  // namespace safecass::verify
