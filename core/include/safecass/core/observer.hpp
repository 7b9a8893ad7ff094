#pragma once
/// @file observer.hpp
/// The observer stream: one record for everything that happens in a coordinator (every processed,
/// ignored, masked and override event, every transition, reset and injection). The recorder, the
/// middleware publisher and the tools all consume it. Refreshes of an already active condition are
/// not in the stream: they only update the condition's count and last time (DESIGN §2.4).

#include <cstdint>
#include <optional>
#include <string_view>

#include "safecass/core/condition.hpp"

namespace safecass {

enum class RecordKind : std::uint8_t {
  Event,                ///< an onset or completion processed (or ignored) by a machine
  Transition,           ///< a machine changed state
  ComponentTransition,  ///< a component's extended state changed
  Reset,                ///< a machine was reset (text: "who: why")
  Injection,            ///< a fault was injected (published by the filters module)
};

enum class Outcome : std::uint8_t {
  None,
  Raised,    ///< onset added with a level above the state: caused a transition
  Override,  ///< onset added at the current level and became outstanding
  Joined,    ///< onset added at the current level, outstanding unchanged
  Masked,    ///< onset added below the current level
  Cleared,   ///< completion removed its onset's condition
  Ignored,   ///< completion ignored; text says why
};

/// One entry of the observer stream and of a machine's history. Plain data, copied by value.
struct Record {
  RecordKind kind = RecordKind::Event;
  Outcome outcome = Outcome::None;
  Time time{};
  std::uint64_t seq = 0;  ///< coordinator-wide order of records
  ComponentId component = kNoComponent;
  MachineId machine = kNoMachine;  ///< kNoMachine for component records
  EventId event = kNoEvent;        ///< the event processed
  State from = State::Normal;      ///< state before
  State to = State::Normal;        ///< state after
  State level = State::Normal;     ///< level of the condition added/removed
  std::uint8_t severity = 0;
  bool mirror = false;
  ConnectionId via = kNoConnection;
  RootCause root;
  /// Reason for ignored events and resets; points at storage that lives as long as the coordinator.
  std::string_view text;
};

std::string_view to_string(RecordKind k) noexcept;
std::string_view to_string(Outcome o) noexcept;
/// The kind or outcome named exactly as to_string() names it (a history file's text).
std::optional<RecordKind> parse_record_kind(std::string_view text) noexcept;
std::optional<Outcome> parse_outcome(std::string_view text) noexcept;

}  // namespace safecass
