#pragma once
/// @file system.hpp
/// A loaded and validated specification (DESIGN §5): the system, its components with their
/// interfaces, signals, events, filters and services, the connections, and which coordinator
/// (process) runs which components. Produced by load_system(); consumed by instantiate().

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/event.hpp"
#include "safecass/filters/filter.hpp"
#include "safecass/spec/diagnostics.hpp"

namespace safecass::spec {

/// One `filter` entry: a single filter (`pipeline` empty, one stage) or a pipeline (sugar for a
/// chain: a stage without an input reads the previous stage's output).
struct FilterSpec {
  std::string pipeline;              ///< empty for a single filter
  std::vector<FilterConfig> stages;  ///< type is the registry's canonical name; unnamed filters get a name
  Position where;
};

struct SignalSpec {
  std::string name;      ///< "Component.signal"
  std::size_t size = 1;  ///< doubles per sample
};

/// A `service` entry: what the service state of a provided interface depends on.
struct ServiceSpec {
  std::string provided;
  ServiceDependency dependency;
};

/// A hazard of the system file's `"hazards"` section: its id (what events name in their
/// `"hazard"` field), a description, and its required reaction: whenever an onset linked to the
/// hazard is active, each listed address is at least at the listed level.
struct HazardSpec {
  std::string id;
  std::string description;
  std::vector<std::pair<std::string, State>> reaction;  ///< address -> minimum level, in file order
  Position where;                                       ///< its id
  std::vector<Position> reaction_where;                 ///< each reaction entry's address
};

/// A named invariant of the system file's `"invariants"` section: an LTL formula over the states
/// of addresses (formula.hpp, docs/verify.md), checked by `safecass verify`.
struct InvariantSpec {
  std::string name;
  std::string formula;
  std::string description;
  Position where;  ///< its name
};

/// The system file's `"reliability"` section (docs/analyze.md): a rate or a probability per
/// failure mode, named as `safecass analyze` names them; at most one of the two is set.
struct ReliabilitySpec {
  static constexpr double kDefaultMissionTime = 8760.0;  ///< hours: a year
  struct Mode {
    std::string name;                   ///< "EVT_X@C.s_A", "EVT_X", "C.s_F", "stale:C.sig", "fault:f", "lost:c", …
    std::optional<double> rate;         ///< failures per hour
    std::optional<double> probability;  ///< within the mission
    Position where;                     ///< its name
  };
  double mission_time = kDefaultMissionTime;  ///< hours
  std::vector<Mode> modes;
  Position where;
};

struct ComponentSpec {
  std::string name;
  std::vector<std::string> provided, required;
  std::vector<SignalSpec> signals;  ///< declared signals (and, for 2016 files, the implied ones)
  std::vector<EventDef> events;
  std::vector<Position> event_where;  ///< the name of each event, parallel to `events`
  std::vector<FilterSpec> filters;
  /// One entry per provided interface: the written ones in file order, then the conservative
  /// default (ServiceDependency{}) for every provided interface without an entry.
  std::vector<ServiceSpec> services;
  std::optional<double> period;  ///< seconds
  std::string file;              ///< the file that defines the component
  Position where;                ///< its name
};

struct ConnectionSpec {
  std::string required;  ///< "C.r"
  std::string provided;  ///< "P.p"
  Position where;
};

struct SystemSpec {
  std::string name;
  std::string path;  ///< the file it was loaded from
  std::vector<ComponentSpec> components;
  std::vector<ConnectionSpec> connections;
  /// Coordinator name -> its components, in file order. Empty: one coordinator runs everything.
  std::vector<std::pair<std::string, std::vector<std::string>>> coordinators;
  std::vector<HazardSpec> hazards;  ///< empty when the system declares none
  std::vector<InvariantSpec> invariants;
  std::optional<ReliabilitySpec> reliability;  ///< absent when the system file has no such section

  /// The hazard of that id, or null.
  const HazardSpec* hazard(std::string_view id) const noexcept {
    for (const HazardSpec& h : hazards) {
      if (h.id == id) return &h;
    }
    return nullptr;
  }
};

}  // namespace safecass::spec
