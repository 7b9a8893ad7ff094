#pragma once
/// @file model.hpp
/// The read model: one value type per fact about a running system, with every name already
/// resolved (no ids), produced in one place (a SystemQuery) and formatted by one formatter
/// (format.hpp). The console, the viewer, the timeline, the supervisor and the middleware's
/// Control servant all consume these types; none of them re-derives a fact from the coordinator.
///
/// A record of the observer stream has ONE shape here, HistoryEntry: the history file, the
/// console's history and watch lines, the wire (EventMessage / RecordEntry carry its fields), and
/// the viewer's and timeline's JSON are all made from it.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/params.hpp"

namespace safecass::introspect {

/// What the times of a system mean, so that they are shown right.
enum class TimeBase : std::uint8_t {
  Simulated,  ///< scenario seconds from t = 0 (in-process runs): shown as seconds
  Host,       ///< the host's monotonic clock (live processes): shown as wall-clock time
};

/// The clock of the system a query answers for.
struct ClockInfo {
  TimeBase base = TimeBase::Simulated;
  Time now{};
  /// Host: wall-clock time (ns since the Unix epoch) = a time of this clock + wall_offset.
  std::int64_t wall_offset_ns = 0;
  /// Simulated: the tick, the scenario file (empty: none) and its duration in seconds.
  double period = 0.0;
  std::string scenario;
  double duration = 0.0;
};

/// What a row of `state list` is.
enum class RowKind : std::uint8_t { System, Component, Framework, Application, Provided, Required, Service };
/// "system", "component", "framework", "application", "provided", "required", "service".
std::string_view to_string(RowKind kind) noexcept;
/// The inverse of to_string(RowKind); false for any other text.
bool parse_row_kind(std::string_view text, RowKind& out) noexcept;

/// One row of `state list`: SYSTEM, a component's extended state, one of its machines or its
/// service states.
struct StateRow {
  std::string address;  ///< "SYSTEM", "JR3", "JR3.s_A", "JR3.s_S.ForceData"
  RowKind kind = RowKind::Component;
  State state = State::Normal;
  std::string outstanding;  ///< the outstanding event; empty when Normal and for SYSTEM and services

  friend bool operator==(const StateRow&, const StateRow&) = default;
};

/// The system at a glance (`state summary`): its state, how many components are in each state,
/// and the components that are not Normal, in declaration order.
struct StateSummary {
  struct Component {
    std::string name;
    State state = State::Normal;
    std::string outstanding;  ///< the outstanding event

    friend bool operator==(const Component&, const Component&) = default;
  };
  State system = State::Normal;
  std::size_t normal = 0;
  std::size_t warning = 0;
  std::size_t error = 0;
  std::vector<Component> not_normal;

  friend bool operator==(const StateSummary&, const StateSummary&) = default;
};

/// One record of the observer stream: an event processed (or ignored, masked), a machine or
/// component transition, a reset, an injection.
struct HistoryEntry {
  std::uint64_t seq = 0;  ///< coordinator-wide order
  Time time{};
  RecordKind kind = RecordKind::Event;
  Outcome outcome = Outcome::None;
  std::string component;  ///< the component (empty when the record names none)
  std::string machine;    ///< the machine's address (empty for component records)
  std::string event;      ///< the event processed (empty for none)
  State from = State::Normal;
  State to = State::Normal;
  State level = State::Normal;
  int severity = 0;
  bool mirror = false;
  std::optional<ResolvedRoot> root;  ///< the root cause of the condition added or removed (DESIGN §2.6)
  std::string text;                  ///< reason of an ignored event, "who: why" of a reset

  /// The machine, else the component, else "-".
  std::string_view where() const noexcept;
  friend bool operator==(const HistoryEntry&, const HistoryEntry&) = default;
};

/// The entry of record `r` of `co`'s stream (names resolved; a remote root keeps its origin
/// address in its own process).
HistoryEntry history_entry(const Record& r, const Coordinator& co);

/// Which records a history query returns.
enum class HistoryFilter : std::uint8_t {
  All,     ///< events, transitions, component transitions, resets, injections
  Events,  ///< events only (`event history`)
};

/// The answer to `explain ADDRESS`: the state there and every active condition with its root
/// cause and hop path (safecass::Explanation has every field, names resolved).
struct ExplainAnswer {
  std::string address;
  State state = State::Normal;
  std::vector<Explanation> conditions;
};

/// A signal a filter reads or writes.
struct SignalRef {
  std::string name;
  std::size_t size = 1;
  friend bool operator==(const SignalRef&, const SignalRef&) = default;
};

/// One row of `filter list`.
struct FilterRow {
  std::string name;
  std::string type;
  std::string target;  ///< machine address, empty when none
  bool active = true;  ///< ACTIVE (false: PASSIVE)
  bool edge = true;    ///< EDGE (false: LEVEL)
  bool enabled = true;
  bool detected = false;
  std::vector<SignalRef> inputs;
  std::vector<SignalRef> outputs;
  std::string onset;  ///< the onset it raises, empty when none
  // Its run-time facts (safecass::FilterFacts): what `analyze now` judges coverage by.
  bool injected = false;            ///< a shallow injection queued, or the newest sample judged injected
  std::optional<Time> last_sample;  ///< the newest sample judged (system clock), none yet
  std::uint64_t evaluations = 0;    ///< runs that judged its inputs
};

/// A hazard-linked onset the system cannot raise now, and why (`analyze now`).
struct CoverageGap {
  std::string onset;
  std::string reason;  ///< "filter force_limit is disabled; ..." (every filter that raises it)
  friend bool operator==(const CoverageGap&, const CoverageGap&) = default;
};

/// A hazard of the running system (an id that events name in "hazard") and what leaves it
/// undetected now: covered when it has no gap.
struct HazardCoverage {
  std::string hazard;
  std::vector<std::string> onsets;  ///< the onsets linked to it, in event-list order
  std::vector<CoverageGap> gaps;
  bool covered() const noexcept { return gaps.empty(); }
  friend bool operator==(const HazardCoverage&, const HazardCoverage&) = default;
};

/// The answer to `analyze now` (docs/analyze.md, "At run time"): each hazard, in the order its
/// first onset is declared, at the system's time `now`.
struct CoverageNow {
  Time now{};
  std::vector<HazardCoverage> hazards;
  std::size_t uncovered() const noexcept;
  friend bool operator==(const CoverageNow&, const CoverageNow&) = default;
};

/// One parameter of a filter type's manifest, with this filter's value.
struct ParamRow {
  std::string name;
  ParamType type = ParamType::Number;
  std::string doc;
  std::optional<ParamValue> default_value;
  bool optional = false;
  double min = -1e300;
  double max = 1e300;
  std::vector<std::string> choices;
  std::optional<ParamValue> value;  ///< a filter's value (none for a type, or when not set)
};

/// The answer to `filter info NAME`: a filter instance (with its row) or a filter type.
struct FilterInfo {
  std::optional<FilterRow> filter;  ///< none when NAME is a filter type
  std::string type;
  std::string doc;
  std::vector<std::string> inputs;   ///< the manifest's input parameters
  std::vector<std::string> outputs;  ///< the manifest's output parameters
  bool generates_events = true;
  std::uint64_t missed_samples = 0;
  std::vector<ParamRow> params;
};

/// One row of `event list`.
struct EventRow {
  std::string name;
  int severity = 0;
  bool onset = true;
  bool broadcast = false;
  std::vector<Transition> transitions;
  std::string counterpart;  ///< an onset's completion, or the onset a completion clears
  bool latched = false;
  bool framework = false;
  std::string hazard;
  std::string description;
};

/// One row of `connection list`. The states are unknown (none) for an end in another process.
struct ConnectionRow {
  std::string required;  ///< "Client.r"
  std::string provided;  ///< "Provider.p"
  std::optional<State> required_state;
  std::optional<State> service_state;
  std::optional<State> propagate;
  bool remote = false;  ///< the provider runs in another process
};

/// One row of `service list`.
struct ServiceRow {
  std::string address;  ///< "C.s_S.p"
  State state = State::Normal;
  std::vector<std::string> depends_on;  ///< "s_P.p", "s_F", "s_A", "s_R.r" in that order
  State propagate = State::Error;
};

/// The names TAB completes.
struct Names {
  std::vector<std::string> components, machines, addresses, events, filters, filter_types, signals;
};

}  // namespace safecass::introspect
