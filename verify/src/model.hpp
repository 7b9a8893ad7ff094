#pragma once
// The abstract model of a system that the Promela translation writes out (docs/verify.md §1).
//
// The coordinator's state is a function of its set of active root conditions: a root is an onset
// active at one machine, with the level it took when it arrived; mirrors are exactly the roots'
// reachable machines (DESIGN §2.6), so they need no variables. The model therefore has one
// variable per possible root (or, merged, per class of interchangeable roots: a count per
// level), and every address's state is an expression over them:
//   state(A) = Error   iff some root in E(A) is active at Error,
//              Warning iff not Error and some root in W(A) is active at Warning,
// where E(A) (W(A)) are the roots whose Error (Warning) level reaches a machine of A: roots at
// that machine, and roots whose propagation at that level reaches it. Reachability is taken from
// the coordinator itself, built from the specification.

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/id_vector.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/spec/formula.hpp"
#include "safecass/spec/instance.hpp"
#include "safecass/verify/verify.hpp"

namespace safecass::verify {

/// An onset that can occur at one machine (a possible root condition).
struct Root {
  std::string event;
  std::string completion;  ///< the completion that clears it; empty when none is defined
  MachineId machine = kNoMachine;
  TransitionSet transitions;
  bool latched = false;
  std::string hazard;
  int broadcast = -1;    ///< index of the broadcast event it belongs to, or -1
  std::string source;    ///< who generates it, for people
  spec::Position where;  ///< the event's definition (empty for framework events)
  /// The level it takes when it arrives in a machine at Normal, Warning, Error (DESIGN §2.3).
  std::array<State, 3> level{};
  bool clearable() const { return !completion.empty() && !latched; }
  bool constant_level() const { return level[0] == level[1] && level[1] == level[2]; }
};

/// Interchangeable roots: same machine, transitions, latching, completion and hazard. Every
/// property treats them alike, so the model counts how many are active at each level.
struct RootClass {
  std::vector<std::size_t> members;  ///< indices into Model::roots
  std::size_t first() const { return members.front(); }
};

/// A broadcast event: one root on every component's s_A, raised (or completed) together.
struct Broadcast {
  std::string event;
  std::string completion;
  std::vector<std::size_t> roots;
};

/// An address and the roots that make it Error or Warning.
struct AddressInfo {
  std::string address;
  spec::Position where;
  std::vector<std::size_t> error_roots;    ///< E(A)
  std::vector<std::size_t> warning_roots;  ///< W(A)
  std::vector<MachineId> machines;         ///< the machines whose product it is
};

class Model {
public:
  /// Builds the system into a coordinator (one process: every component) and derives the model.
  [[nodiscard]] static Expected<std::unique_ptr<Model>> build(const spec::SystemSpec& system,
                                                              const FilterRegistry& registry);

  const spec::SystemSpec& system() const { return *system_; }
  Coordinator& coordinator() { return instance_->coordinator(); }
  const Coordinator& coordinator() const { return instance_->coordinator(); }
  const std::vector<Root>& roots() const { return roots_; }
  const std::vector<Broadcast>& broadcasts() const { return broadcasts_; }
  const std::vector<AddressInfo>& addresses() const { return addresses_; }
  /// Index of an address in addresses(), or -1.
  int address_index(std::string_view address) const;
  /// Roots at machine `m`.
  const std::vector<std::size_t>& roots_at(MachineId m) const { return at_machine_[m]; }
  /// Levels each root can take (over-approximated by a fixpoint on the structure).
  bool can_be(std::size_t root, State level) const { return can_[root][static_cast<std::size_t>(level)]; }
  /// Whether the state of `address` can leave Normal.
  bool can_leave_normal(std::size_t address) const;
  /// Roots of a hazard.
  std::vector<std::size_t> linked(std::string_view hazard) const;
  /// The machine index of an address that is a machine, for resets.
  const std::string& machine_address(MachineId m) const { return instance_->coordinator().structure().address_of(m); }

  /// The root classes among `roots` (sorted indices): each broadcast root alone; the others
  /// merged with their interchangeable peers when `merge`.
  std::vector<RootClass> classes(const std::vector<std::size_t>& roots, bool merge) const;

  /// The cone of influence: every root whose state can influence the given roots' and
  /// addresses' flags (`need_warning`: the Warning flag of the address matters too), closed
  /// under "the level of a relevant root depends on its machine's state".
  std::vector<std::size_t> cone(const std::vector<std::size_t>& seed_roots,
                                const std::vector<std::pair<std::size_t, bool>>& seed_addresses) const;

private:
  Model() = default;
  [[nodiscard]] Expected<void> derive(const FilterRegistry& registry);
  // derive()'s steps, in order.
  /// The roots: onsets filters generate on their targets, onsets components raise on their s_A,
  /// broadcasts on every s_A.
  void derive_roots(const FilterRegistry& registry);
  /// Where a root of each level at each machine that holds roots makes mirrors land.
  void derive_reach();
  /// The roots that can set each machine (its own and those that reach it), per level.
  struct RootsAt {
    IdVector<std::vector<std::size_t>, MachineId> error, warning;
  };
  RootsAt roots_at() const;
  /// SYSTEM, each component, its machines and services, with their root sets.
  void derive_addresses(const RootsAt& at);
  /// Which levels each root can take: a fixpoint over the machines' possible states.
  void derive_levels(const RootsAt& at);

  const spec::SystemSpec* system_ = nullptr;
  std::unique_ptr<spec::Instance> instance_;  ///< the system, built by the one factory
  std::vector<Root> roots_;
  std::vector<Broadcast> broadcasts_;
  std::vector<AddressInfo> addresses_;
  IdVector<std::vector<std::size_t>, MachineId> at_machine_;
  std::vector<std::array<bool, 3>> can_;
  IdVector<IdVector<bool, MachineId>, MachineId> reach_error_;    ///< [machine][machine]: an Error root reaches it
  IdVector<IdVector<bool, MachineId>, MachineId> reach_warning_;  ///< ... a Warning root
};

}  // namespace safecass::verify
