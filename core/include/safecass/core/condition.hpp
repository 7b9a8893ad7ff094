#pragma once
/// @file condition.hpp
/// Active conditions and their root causes (DESIGN §2.4, §2.6).

#include <cstdint>

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
  /// hop path), read with Coordinator::root_origin() and explain().
  std::uint32_t remote = kNone;
  /// For a remote root: its origin address in its own process, interned when it arrived. A record
  /// keeps it by value, so the record names its true root cause for ever, even after `remote`'s
  /// slot has been freed and reused by another root (the audit trail resolves causes when a
  /// record is made, never later).
  NameId remote_origin = kNoName;
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
