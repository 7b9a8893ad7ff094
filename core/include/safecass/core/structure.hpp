#pragma once
/// @file structure.hpp
/// The shape of one coordinator's model: its components and their state machines, the events,
/// the connections, the service dependencies, and the names interned for causes. Configuration
/// (Coordinator's add_* calls) builds it; nothing changes it afterwards, so every read here is
/// lock-free and safe from any thread once configuration is over, callbacks and observers
/// included (the interned names take a small lock of their own). Reached through
/// Coordinator::structure(); the state of the model is the coordinator's.

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "safecass/core/address.hpp"
#include "safecass/core/event.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/ids.hpp"
#include "safecass/core/stable_vector.hpp"
#include "safecass/core/state.hpp"
#include "safecass/core/text_map.hpp"

namespace safecass {

/// What the service state of a provided interface depends on (DESIGN §2.2):
/// s_S.p = s_P.p ⊗ [s_F] ⊗ [s_A] ⊗ (⊗ over the listed required interfaces).
/// The default-constructed value is the conservative default used when a provided interface has
/// no `service` entry: s_F, s_A and every required interface.
struct ServiceDependency {
  bool framework = true;              ///< include s_F
  bool application = true;            ///< include s_A
  bool all_required = true;           ///< include every required interface (ignores `required`)
  std::vector<std::string> required;  ///< used when all_required is false
  State propagate = State::Error;     ///< lowest level that crosses connections (Error or Warning)

  /// `"dependency": {}`: the service state is s_P alone.
  static ServiceDependency provided_only() {
    ServiceDependency d;
    d.framework = d.application = d.all_required = false;
    return d;
  }
};

/// A connection from a client's required interface to a provider's provided interface.
struct Connection {
  ComponentId client = kNoComponent;
  std::uint32_t required = kNone;  ///< index into the client's required interfaces
  ComponentId provider = kNoComponent;
  std::uint32_t provided = kNone;  ///< index into the provider's provided interfaces
};

/// A parsed address: `SYSTEM`, `C`, `C.s_F`, `C.s_A`, `C.s_P.p`, `C.s_R.r`, `C.s_S.p`.
struct Address {
  enum class Kind : std::uint8_t { System, Component, Machine, Service };
  Kind kind = Kind::System;
  ComponentId component = kNoComponent;
  MachineId machine = kNoMachine;
  std::uint32_t service = kNone;  ///< Service: index of the provided interface
};

class Coordinator;

class Structure {
public:
  /// The coordinator's name: another address of SYSTEM (resolve()).
  std::string_view name() const noexcept { return name_; }

  // ---- lookup by name ------------------------------------------------------------------------
  [[nodiscard]] Expected<ComponentId> find_component(std::string_view name) const;
  [[nodiscard]] Expected<EventId> find_event(std::string_view name) const;
  /// Parses an address (see Address); the coordinator's own name stands for SYSTEM when no
  /// component has that name. Errors: Parse, NotFound.
  [[nodiscard]] Expected<Address> resolve(std::string_view address) const;
  /// Resolves an address that must name one state machine. Errors: as resolve(), InvalidArgument.
  [[nodiscard]] Expected<MachineId> find_machine(std::string_view address) const;

  // ---- what the model holds (ids are valid ones) ----------------------------------------------
  std::size_t component_count() const noexcept { return components_.size(); }
  std::size_t machine_count() const noexcept { return machines_.size(); }
  std::size_t event_count() const noexcept { return events_.size(); }
  const Event& event(EventId id) const noexcept { return *event_table_[to_index(id)]; }
  const std::vector<Connection>& connections() const noexcept { return connections_; }
  std::string_view component_name(ComponentId id) const noexcept { return components_[id].name; }
  /// True when `id` stands for a component of another process (Coordinator::add_remote_provided).
  bool is_remote(ComponentId id) const noexcept { return components_.contains(id) && components_[id].remote; }
  MachineId framework_machine(ComponentId id) const noexcept { return components_[id].framework; }
  MachineId application_machine(ComponentId id) const noexcept { return components_[id].application; }
  const std::vector<MachineId>& provided_machines(ComponentId id) const noexcept { return components_[id].provided; }
  const std::vector<MachineId>& required_machines(ComponentId id) const noexcept { return components_[id].required; }
  /// The dependency entry of provided interface `provided` (index) of `component`.
  const ServiceDependency& service(ComponentId component, std::uint32_t provided) const noexcept {
    return components_[component].services[provided].dependency;
  }
  MachineKind machine_kind(MachineId id) const noexcept { return machines_[id].kind; }
  ComponentId machine_component(MachineId id) const noexcept { return machines_[id].component; }
  /// "C.s_F", "C.s_A", "C.s_P.p", "C.s_R.r".
  const std::string& address_of(MachineId id) const noexcept { return machines_[id].address; }
  /// Interface name of a provided/required machine; "s_F"/"s_A" otherwise.
  std::string_view interface_name(MachineId id) const noexcept;
  /// A name interned by Coordinator::intern(); empty for an unknown id.
  std::string_view name_of(NameId id) const;

private:
  friend class Coordinator;

  struct Service {
    ServiceDependency dependency;
    std::vector<std::uint32_t> required;  ///< resolved indices of the required interfaces
  };
  struct Machine {
    ComponentId component = kNoComponent;
    MachineKind kind = MachineKind::Framework;
    std::uint32_t iface = kNone;  ///< index of the interface for Provided/Required
    std::string address;
  };
  struct Component {
    std::string name;
    bool remote = false;  ///< a stand-in for a component of another process
    MachineId framework = kNoMachine;
    MachineId application = kNoMachine;
    std::vector<MachineId> provided;
    std::vector<MachineId> required;
    std::vector<Service> services;                   ///< one per provided interface
    std::vector<ConnectionId> required_connection;   ///< one per required interface
    std::vector<ConnectionId> provider_connections;  ///< connections to its provided interfaces
  };

  explicit Structure(std::string name) : name_(std::move(name)) {}
  /// s_F, s_A, then every s_P and s_R of `c`.
  std::vector<MachineId> machines_of(ComponentId c) const;
  /// Interns a text for SampleCause and reasons. Thread-safe.
  NameId intern(std::string_view text);

  std::string name_;  ///< the coordinator's name (an address of SYSTEM)
  // Elements never move once added: references handed out stay valid while the model grows.
  detail::StableVector<Machine, MachineId> machines_;
  detail::StableVector<Component, ComponentId> components_;
  TextMap<ComponentId> component_index_;  ///< by name
  std::deque<Event> events_;
  TextMap<EventId> event_index_;           ///< by name
  std::vector<const Event*> event_table_;  ///< events_ by id; indexing a deque is slow on the hot path
  std::vector<Connection> connections_;

  mutable std::mutex names_mutex_;
  std::deque<std::string> names_;  ///< by NameId; elements never move
  /// names_ by text (views of its elements): intern() finds a known text without allocating.
  std::unordered_map<std::string_view, NameId, TextHash, std::equal_to<>> name_index_;
};

}  // namespace safecass
