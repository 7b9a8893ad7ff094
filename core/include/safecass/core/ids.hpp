#pragma once
/// @file ids.hpp
/// Dense indices that name the parts of a coordinator's model. They are stable for the lifetime
/// of the coordinator and index its tables directly, so the hot path never looks up a string.

#include <cstdint>
#include <limits>

namespace safecass {

using ComponentId = std::uint32_t;
using MachineId = std::uint32_t;
using EventId = std::uint32_t;
using ConnectionId = std::uint32_t;
using NameId = std::uint32_t;  ///< an interned string (filter, signal, reason, ...)

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
inline constexpr EventId kNoEvent = kNone;
inline constexpr MachineId kNoMachine = kNone;
inline constexpr ComponentId kNoComponent = kNone;
inline constexpr ConnectionId kNoConnection = kNone;
inline constexpr NameId kNoName = kNone;

}  // namespace safecass
