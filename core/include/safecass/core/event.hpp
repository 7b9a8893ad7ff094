#pragma once
/// @file event.hpp
/// Event definitions (DESIGN §2.3) and the onset-level rule.

#include <cstdint>
#include <string>

#include "safecass/core/ids.hpp"
#include "safecass/core/state.hpp"

namespace safecass {

/// Severity bands: 1–200 application, 201–250 framework, 251–255 broadcast.
inline constexpr int kMinSeverity = 1;
inline constexpr int kMaxApplicationSeverity = 200;
inline constexpr int kMinBroadcastSeverity = 251;
inline constexpr int kMaxSeverity = 255;

/// An event as written in a specification, before the coordinator checks it.
struct EventDef {
  std::string name;
  int severity = 0;           ///< 1–255; int so that out-of-range values can be reported
  TransitionSet transitions;  ///< onset: worsening only; completion: improving only
  std::string completes;      ///< completion only: the onset it clears (default "/X" → "X")
  bool latched = false;       ///< onset only: a completion is ignored, only reset clears it
  std::string hazard;         ///< an id from the user's hazard analysis
  std::string description;
};

/// A checked event definition, owned by a coordinator.
struct Event {
  EventId id = kNoEvent;
  std::string name;
  std::uint8_t severity = 0;
  TransitionSet transitions;
  bool is_onset = true;
  /// Onset: its completion, if one is defined. Completion: the onset it clears.
  EventId counterpart = kNoEvent;
  std::string completes;  ///< completion: the onset's name
  bool latched = false;
  std::string hazard;
  std::string description;

  bool is_broadcast() const noexcept { return severity >= kMinBroadcastSeverity; }
};

/// The level an onset with `transitions` takes when processed in state `current` (DESIGN §2.3):
/// from Normal, Error if N2E is listed else Warning; from Warning, Error if W2E is listed;
/// otherwise the highest level its transitions reach.
constexpr State onset_level(TransitionSet transitions, State current) noexcept {
  if (current == State::Normal) return transitions.contains(Transition::N2E) ? State::Error : State::Warning;
  if (current == State::Warning && transitions.contains(Transition::W2E)) return State::Error;
  return (transitions.contains(Transition::N2E) || transitions.contains(Transition::W2E)) ? State::Error
                                                                                          : State::Warning;
}

/// The framework events every coordinator defines (DESIGN §2.7), with fixed ids.
/// Each onset's completion has the next id.
namespace framework_event {
inline constexpr EventId kServiceFailure{0};      ///< EVT_SERVICE_FAILURE (220)
inline constexpr EventId kServiceDegraded{2};     ///< EVT_SERVICE_DEGRADED (215)
inline constexpr EventId kThreadException{4};     ///< EVT_THREAD_EXCEPTION (210)
inline constexpr EventId kPeriodOverrun{6};       ///< EVT_PERIOD_OVERRUN (205)
inline constexpr EventId kStale{8};               ///< EVT_STALE (230)
inline constexpr EventId kCallbackException{10};  ///< EVT_CALLBACK_EXCEPTION (210)
inline constexpr EventId kCoordinatorLost{12};    ///< EVT_COORDINATOR_LOST (240)
inline constexpr EventId kInvalidSample{14};      ///< EVT_INVALID_SAMPLE (225): NaN or infinite input
/// EVT_SUPERVISOR_LOST (235, a warning): the supervisor that watches the whole system stopped
/// sending heartbeats, so nothing system-wide watches this process (DESIGN §4).
inline constexpr EventId kSupervisorLost{16};
inline constexpr std::uint32_t kCount = 18;  ///< how many framework events (ids 0 to kCount - 1)
constexpr EventId completion_of(EventId onset) noexcept { return EventId{to_index(onset) + 1}; }
}  // namespace framework_event

}  // namespace safecass
