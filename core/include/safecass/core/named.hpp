#pragma once
/// @file named.hpp
/// The coordinator's writes and `explain` by name, for tools and people: each resolves its names
/// against the structure first and changes nothing when one is wrong. The resolve_* checks say
/// what a write would act on, or why it would refuse: a caller that must check a whole batch
/// before applying any of it (a replay, introspect's Action) checks with these, and the writes
/// below use them.

#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/ids.hpp"
#include "safecass/core/structure.hpp"

namespace safecass {

/// The event and machine that generate(event, target) processes. A broadcast event ignores
/// `target` (machine kNoMachine).
struct GenerateTarget {
  EventId event = kNoEvent;
  MachineId machine = kNoMachine;
};
/// Errors: NotFound (event or address), InvalidArgument (address is not a machine), InvalidState
/// (completion of an onset that was never defined).
[[nodiscard]] Expected<GenerateTarget> resolve_generate(const Structure& s, std::string_view event,
                                                        std::string_view target);
/// The broadcast event broadcast(event) processes. Errors: NotFound, InvalidArgument (not a broadcast).
[[nodiscard]] Expected<EventId> resolve_broadcast(const Structure& s, std::string_view event);
/// The address reset(target, ...) clears. Errors: as Structure::resolve(), InvalidArgument (a
/// service state: it is derived).
[[nodiscard]] Expected<Address> resolve_reset(const Structure& s, std::string_view target);

/// Processes `event` on machine `target` (Coordinator::generate). Errors: as resolve_generate.
[[nodiscard]] Expected<void> generate(Coordinator& co, std::string_view event, std::string_view target);
/// Processes a broadcast event (severity 251–255) on s_A of every component. Errors: as resolve_broadcast.
[[nodiscard]] Expected<void> broadcast(Coordinator& co, std::string_view event);
/// Clears every condition originating in `target` (machine, component, SYSTEM or the
/// coordinator's name) and records who and why (Coordinator::reset). Errors: as resolve_reset.
[[nodiscard]] Expected<void> reset(Coordinator& co, std::string_view target, std::string_view who,
                                   std::string_view why);
/// Every active condition at `address` with its root cause and hop path (Coordinator::explain).
/// Errors: as Structure::resolve().
[[nodiscard]] Expected<std::vector<Explanation>> explain(const Coordinator& co, std::string_view address);

}  // namespace safecass
