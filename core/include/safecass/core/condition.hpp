#pragma once
/// @file condition.hpp
/// Active conditions and their root causes (DESIGN §2.4, §2.6).

#include <cstdint>
#include <string>

#include "safecass/core/clock.hpp"
#include "safecass/core/ids.hpp"
#include "safecass/core/state.hpp"

namespace safecass {

/// What a filter saw when it fired; all fields are optional (kNoName when absent).
struct SampleCause {
  NameId filter = kNoName;  ///< interned filter name
  NameId signal = kNoName;  ///< interned signal name ("Component.signal")
  double value = 0.0;       ///< the sample value the filter judged
  Time sample_time{};       ///< when the sample was taken
  bool injected = false;    ///< the sample came from fault injection

  bool present() const noexcept { return filter != kNoName || signal != kNoName; }
};

/// The original onset a condition traces back to.
struct RootCause {
  EventId event = kNoEvent;       ///< the onset that started it all
  MachineId origin = kNoMachine;  ///< the machine it was generated on
  Time time{};                    ///< when it was processed at the origin
  SampleCause sample;             ///< filter data, for filter events
  /// kNone for a root that originated in this process. Otherwise the root originated in another
  /// process and arrived through the remote provided interface `origin`
  /// (Coordinator::add_remote_provided); this is the index of its remote data (origin address,
  /// hop path), read with Coordinator::resolve_root() and explain().
  std::uint32_t remote = kNone;
  /// For a remote root: its origin address in its own process, interned when it arrived. A record
  /// keeps it by value, so the record names its true root cause for ever, even after `remote`'s
  /// slot has been freed and reused by another root (the audit trail resolves causes when a
  /// record is made, never later).
  NameId remote_origin = kNoName;
};

/// A root cause with its names resolved (Coordinator::resolve_root): the one shape in which every
/// module and tool keeps, shows and sends one — explain(), the read model's records, the full state
/// a process sends its remote requirers, the timeline, trace and replay. The origin is the origin
/// machine's address in its own process (a root from another process names its machine there).
struct ResolvedRoot {
  std::string event;   ///< the onset that started it all
  std::string origin;  ///< "JR3.s_A"
  Time time{};         ///< when it was processed at the origin (the origin process's clock)
  std::string filter;  ///< empty unless a filter fired the root
  std::string signal;  ///< empty unless the root has a sample; then value and sample_time are its
  double value = 0.0;
  Time sample_time{};
  bool injected = false;  ///< the sample came from fault injection

  /// "JR3.s_A:EVT_FORCE_ERROR", how scenarios (expect_cause) and explanations name a root.
  std::string name() const { return origin + ":" + event; }
  // Written out: core's headers are also read as C++17 (the ROS 1 extension).
  friend bool operator==(const ResolvedRoot& a, const ResolvedRoot& b) {
    return a.event == b.event && a.origin == b.origin && a.time == b.time && a.filter == b.filter &&
           a.signal == b.signal && a.value == b.value && a.sample_time == b.sample_time && a.injected == b.injected;
  }
  friend bool operator!=(const ResolvedRoot& a, const ResolvedRoot& b) { return !(a == b); }
};

/// An active condition of a state machine.
struct Condition {
  EventId event = kNoEvent;  ///< the event; for mirrors EVT_SERVICE_FAILURE/DEGRADED
  State level = State::Normal;
  std::uint8_t severity = 0;
  bool mirror = false;               ///< propagated from a provider (DESIGN §2.6)
  ConnectionId via = kNoConnection;  ///< mirrors: the connection it arrived through
  Time first{};                      ///< activation time
  Time last{};                       ///< last onset (refresh) time
  std::uint32_t count = 1;           ///< onsets seen while active (1 + refreshes)
  std::uint64_t seq = 0;             ///< activation order, for "most recent" ties
  RootCause root;                    ///< for a root condition, root.event == event
};

}  // namespace safecass
