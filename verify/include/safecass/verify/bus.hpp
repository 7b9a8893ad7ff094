#pragma once
/// @file bus.hpp
/// `safecass verify --bus` (docs/verify.md "The bus"): the bus protocol between the processes of a
/// deployment, model-checked with SPIN. From the system file come the pairs of a provider and a
/// receiver (a coordinator feeding another, every coordinator feeding the supervisor, the
/// supervisor's heartbeats feeding every coordinator) with their streams and loss bounds; pairs
/// that differ in nothing the protocol reads form one pattern, checked once. Each pattern's model
/// (verify/bus/bus.pml with its constants) is searched exhaustively once per fault class: a set of
/// faults and attacks that may happen at any time, in any order, in runs of any length. Five
/// properties are checked in every search (P1–P5 below); a violation comes with its trace as bus
/// messages, faults and decisions.
///
/// Not thread-safe; runs `spin` and the system's C compiler as child processes.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"
#include "safecass/spec/system.hpp"
#include "safecass/verify/command.hpp"

namespace safecass::verify {

struct BusOptions {
  std::chrono::milliseconds period{100};                 ///< heartbeat period (NodeOptions::heartbeat)
  std::chrono::milliseconds lost_after{0};               ///< a coordinator's loss bound (0: 3 periods)
  std::chrono::milliseconds supervisor_lost_after{600};  ///< the supervisor's (SupervisorOptions)
  bool supervisor = true;                                ///< the deployment runs a supervisor
  std::string mutant;                                    ///< a rule removed (bus_mutants()); empty: none
  std::string fault_class;                               ///< only this class (bus_fault_classes()); empty: all
  bool first_violation = false;                          ///< stop at the first search that finds one (mutants)
  std::size_t memory_mb = 2048;                          ///< SPIN's memory bound per search
  std::string spin = "spin";
  std::string cc = "cc";
  std::string work_dir;  ///< where SPIN's files go (default: a fresh temporary directory, removed)
  /// A violation is searched again breadth-first, for a shortest trail and the property it breaks
  /// first; false keeps the depth-first search's trail, found in a fraction of the time.
  bool shortest_trail = true;
};

/// The model's scale for a provider settling its own losses (docs/verify.md "The bus"), in ticks of
/// half a period: the provider hears its own peers again within kBusSettleTicks of the heal, and
/// the receiver keeps a loss for it at most kBusSettleLimitTicks (Liveness::kSettleLimit, scaled
/// down: longer than any wait of a provider that settles in time, which is what is checked).
inline constexpr int kBusSettleTicks = 4;
inline constexpr int kBusSettleLimitTicks = kBusSettleTicks + 6;
/// The subscription round in ticks (middleware/src/ice_util.hpp: kResubscribeCheckEvery periods):
/// what IceStorm no longer holds is made again, and a provider still held lost a round after its
/// loss began, or after the last renewal, is subscribed to again under new identities
/// (Liveness::renew_due).
inline constexpr int kBusResubscribeTicks = 20;

/// One kind of pair: everything the protocol reads of a provider and its receiver.
struct BusPattern {
  std::size_t streams = 0;  ///< state streams the receiver holds of the provider (at most 2 modelled)
  std::size_t streams_total = 0;
  int bound_ticks = 6;              ///< the receiver's loss bound, in ticks of half a period
  bool watch_start = true;          ///< watched from the receiver's start (a provider); else once heard
  bool forget = false;              ///< the receiver forgets the provider's process on a loss (the supervisor's)
  State loss_level = State::Error;  ///< what the receiver shows while the provider is lost
  std::vector<std::string> pairs;   ///< "robot -> ui", in the system file's order
  std::string name() const;         ///< e.g. "coordinator -> coordinator, 1 stream, bound 300 ms"
};

/// A set of faults and attacks a search lets happen, each at most as often as its count.
struct BusFaultClass {
  std::string name;
  std::string text;  ///< for people
  int crash = 0, cut = 0, unsubscribe = 0, broker = 0, flip = 0, replay = 0, forge = 0, wild = 0, receiver_restart = 0,
      drop = 0;
  int settle = 0;            ///< the provider, cut off, loses its own peers and settles after the heal
  bool two_streams = false;  ///< only for patterns of two or more streams, and checked with two
};

/// A rule of the protocol that a mutant removes or weakens (the mutation check).
struct BusMutant {
  std::string name;   ///< e.g. "unproven-heartbeat"
  std::string text;   ///< what the mutant does
  std::string macro;  ///< the model's switch
};

enum class BusVerdict { Holds, Violated, Undecided };

/// One search: a pattern under a fault class.
struct BusSearch {
  std::size_t pattern = 0;
  std::string fault_class;
  BusVerdict verdict = BusVerdict::Holds;
  std::string property;  ///< the violated property ("P3"), if any
  std::uint64_t states = 0;
  double memory_mb = 0.0;
  double seconds = 0.0;
  std::vector<std::string> trace;  ///< a violation's trace, one line per step, for people
  std::string detail;              ///< Undecided: why (memory bound, SPIN failed)
};

struct BusProperty {
  std::string name;  ///< "P1"
  std::string text;
  BusVerdict verdict = BusVerdict::Holds;
  std::uint64_t states = 0;  ///< over every search (each search checks every property)
  double memory_mb = 0.0;    ///< the largest search's
  double seconds = 0.0;
};

struct BusReport {
  std::string system;
  std::vector<BusPattern> patterns;
  std::vector<BusSearch> searches;
  std::vector<BusProperty> properties;  ///< P1..P5
  std::string bounds;                   ///< the constants of the model, for people
  double seconds = 0.0;
  /// 0 every property holds; 1 one is violated; 3 a search could not be completed.
  int exit_code() const;
};

/// The pairs of `system` as the bus carries them, grouped into patterns. Errors: InvalidArgument
/// (a bound that is not a whole number of half periods, or too large for the model).
[[nodiscard]] Expected<std::vector<BusPattern>> bus_patterns(const spec::SystemSpec& system, const BusOptions& options);
const std::vector<BusFaultClass>& bus_fault_classes();
const std::vector<BusMutant>& bus_mutants();

/// The Promela text of `pattern` under `faults` (with `mutant`'s switch when not empty).
std::string bus_promela(const BusPattern& pattern, const BusFaultClass& faults, const BusOptions& options,
                        const std::string& mutant = {});

/// Checks every pattern of `system` under every fault class. Errors: Io (SPIN or the compiler
/// cannot be run), NotFound (an unknown mutant or fault class), InvalidArgument (bus_patterns).
[[nodiscard]] Expected<BusReport> verify_bus(const spec::SystemSpec& system, const BusOptions& options);

/// SPIN's random simulations of `pattern` under `faults`, with seeds 1 to `runs`, each for
/// `steps` steps: each run's "@ ..." lines (inputs, decisions, ticks) with the absolute numbers of
/// the messages (SIM), given to `each` with its seed; `each` returns false to stop. The model is
/// made and preprocessed once for all the runs. Errors: Io.
[[nodiscard]] Expected<void> simulate_bus(const BusPattern& pattern, const BusFaultClass& faults, unsigned runs,
                                          std::size_t steps, const BusOptions& options, const SimulationRun& each);

std::string_view to_string(BusVerdict verdict) noexcept;

}  // namespace safecass::verify
