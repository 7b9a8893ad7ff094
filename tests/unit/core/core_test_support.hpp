#pragma once
// Small helpers shared by the core specification tests: a coordinator running in simulated time
// and terse ways to declare events and read states by address.

#include <gtest/gtest.h>

#include <initializer_list>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
// Readable values in test failure messages (found by GoogleTest through argument-dependent lookup).
inline void PrintTo(State s, std::ostream* os) { *os << to_string(s); }
inline void PrintTo(Transition t, std::ostream* os) { *os << to_string(t); }
inline void PrintTo(Outcome o, std::ostream* os) { *os << to_string(o); }
inline void PrintTo(RecordKind k, std::ostream* os) { *os << to_string(k); }
}  // namespace safecass

namespace safecass::test {

// Terse states for the tables of expected levels.
inline constexpr State N = State::Normal;
inline constexpr State W = State::Warning;
inline constexpr State E = State::Error;
// Terse onset transitions for the same tables.
inline constexpr Transition N2W = Transition::N2W;
inline constexpr Transition N2E = Transition::N2E;
inline constexpr Transition W2E = Transition::W2E;

inline constexpr TransitionSet kToWarning{Transition::N2W};
inline constexpr TransitionSet kToError{Transition::N2E, Transition::W2E};
inline constexpr TransitionSet kFromWarning{Transition::W2N};
inline constexpr TransitionSet kFromError{Transition::E2N, Transition::E2W};

inline EventDef onset(std::string name, int severity, TransitionSet transitions, bool latched = false,
                      std::string hazard = {}) {
  EventDef d;
  d.name = std::move(name);
  d.severity = severity;
  d.transitions = transitions;
  d.latched = latched;
  d.hazard = std::move(hazard);
  return d;
}

inline EventDef completion(std::string name, int severity, TransitionSet transitions, std::string completes = {}) {
  EventDef d;
  d.name = std::move(name);
  d.severity = severity;
  d.transitions = transitions;
  d.completes = std::move(completes);
  return d;
}

/// Unwraps an Expected, failing the test with the error's message when it holds an error.
template <class T>
T must(Expected<T> result, std::string_view what) {
  if (!result) {
    ADD_FAILURE() << what << ": " << result.error().message;
    throw std::runtime_error(std::string(what));
  }
  if constexpr (!std::is_void_v<T>) return std::move(*result);
}

/// A coordinator named "robot" that reads time from a SimulatedClock.
struct Gcm {
  SimulatedClock clock;
  Coordinator co;

  explicit Gcm(CoordinatorOptions options = {}) : co("robot", &clock, options) {}

  ComponentId component(std::string_view name, std::initializer_list<std::string_view> provided = {},
                        std::initializer_list<std::string_view> required = {}) {
    const ComponentId id = must(co.add_component(name), "add_component");
    for (std::string_view p : provided) must(co.add_provided(id, p), "add_provided");
    for (std::string_view r : required) must(co.add_required(id, r), "add_required");
    return id;
  }
  EventId event(const EventDef& def) { return must(co.add_event(def), "add_event " + def.name); }
  /// Defines onset `name` and its completion "/name" with the usual transitions for `level`.
  EventId pair(const std::string& name, int severity, State level, bool latched = false) {
    const EventId id = event(onset(name, severity, level == State::Error ? kToError : kToWarning, latched));
    event(completion("/" + name, severity, level == State::Error ? kFromError : kFromWarning));
    return id;
  }
  void connect(std::string_view client_required, std::string_view provider_provided) {
    must(co.connect(client_required, provider_provided), "connect");
  }
  MachineId machine(std::string_view address) const {
    return must(co.structure().find_machine(address), "find_machine");
  }
  ComponentId comp(std::string_view name) const { return must(co.structure().find_component(name), "find_component"); }
  EventId id(std::string_view event) const { return must(co.structure().find_event(event), "find_event"); }
  void gen(std::string_view event, std::string_view target) {
    must(generate(co, event, target), "generate " + std::string(event) + " on " + std::string(target));
  }
  void reset(std::string_view target, std::string_view who = "operator", std::string_view why = "test") {
    must(safecass::reset(co, target, who, why), "reset " + std::string(target));
  }
  State at(std::string_view address) const { return co.state_of(must(co.structure().resolve(address), "resolve")); }
  /// Name of the outstanding event of a machine, or "" when it has none.
  std::string outstanding(std::string_view address) const {
    const auto c = co.outstanding(machine(address));
    return c ? co.structure().event(c->event).name : std::string{};
  }
  /// Name of the outstanding event of a component's extended state, or "".
  std::string component_outstanding(std::string_view name) const {
    const StateSnapshot s = co.extended(comp(name));
    return s.outstanding == kNoEvent ? std::string{} : co.structure().event(s.outstanding).name;
  }
  std::vector<Record> history(std::string_view address) const { return co.history(machine(address)); }
  /// The Event records of a machine's history, oldest first.
  std::vector<Record> event_records(std::string_view address) const {
    std::vector<Record> out;
    for (const Record& r : history(address)) {
      if (r.kind == RecordKind::Event) out.push_back(r);
    }
    return out;
  }
  std::vector<Record> records_of_kind(std::string_view address, RecordKind kind) const {
    std::vector<Record> out;
    for (const Record& r : history(address)) {
      if (r.kind == kind) out.push_back(r);
    }
    return out;
  }
  std::size_t mirrors(std::string_view address) const {
    std::size_t n = 0;
    for (const Condition& c : co.conditions(machine(address))) n += c.mirror ? 1 : 0;
    return n;
  }
};

}  // namespace safecass::test
