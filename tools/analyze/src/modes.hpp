#pragma once
// The failure modes and the engine that gives their effects (modes.cpp), shared by the fault
// trees (fault_tree.cpp) and the tests that check SCRAM's cut sets against the engine.

#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "safecass/analyze/analyze.hpp"
#include "safecass/core/address.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::analyze {

/// One onset a failure mode raises, and where.
struct Raise {
  std::string event;
  std::string machine;
};

/// A system built as `run` builds it (one coordinator for every component), into which failure
/// modes are raised one set at a time: the effects are the engine's own propagation.
class Engine {
public:
  explicit Engine(std::unique_ptr<spec::Instance> instance);

  /// Raises `raises` in order (with `escalated`, each on a machine put at Warning first, so that an
  /// escalating onset takes Error), reads every address that left Normal, and resets the system.
  /// Errors: NotFound (an event or machine the system lacks).
  [[nodiscard]] Expected<std::vector<Reached>> raise(const std::vector<Raise>& raises, bool escalated);
  /// Raises `raises` in order without resetting; state() reads the result; reset() ends it.
  [[nodiscard]] Expected<void> raise_and_hold(const std::vector<Raise>& raises);
  State state(const Address& address) const noexcept { return co().state_of(address); }
  void reset();

  const spec::SystemSpec& spec() const noexcept { return instance_->spec(); }
  [[nodiscard]] Expected<Address> resolve(std::string_view address) const;
  /// The event of that name, or null.
  const Event* event(std::string_view name) const;

private:
  Coordinator& co() noexcept { return instance_->coordinator(); }
  const Coordinator& co() const noexcept { return instance_->coordinator(); }

  std::unique_ptr<spec::Instance> instance_;
  std::vector<std::pair<std::string, Address>> addresses_;  ///< every address, in the system's order
  Address system_;
};

/// The level `address` is at in `effects` (Normal when absent).
State level_at(const std::vector<Reached>& effects, std::string_view address) noexcept;

/// The failure modes, and what each raises (parallel vectors).
struct ModeSet {
  std::vector<FailureMode> modes;
  std::vector<std::vector<Raise>> raises;
};

/// Every failure mode of `sys`, with its effects from `engine` and its evidence from `trace`.
[[nodiscard]] Expected<ModeSet> failure_modes(const spec::SystemSpec& sys, const trace::Trace& trace, Engine& engine);

}  // namespace safecass::analyze
