#pragma once
/// @file action.hpp
/// Action: one thing an operator, a scenario or a replayed recording does to a running system
/// (push a sample, generate or broadcast an event, reset, inject shallow or deep), as one value;
/// check() and apply() are the one path every tool takes to do it: the scenario runner, a live
/// coordinator running a scenario, replay, the console and the viewer (through
/// SystemQuery::apply(), in-process and over the bus).
///
/// apply() checks the action against the system first (the rules of the name-based writes of
/// core/named.hpp and of the Monitor), so a refused action changes nothing, then applies it and tells
/// the ActionObserver: recording is an observer of applied actions (record's InputRecorder), and
/// each applied action is told once.
///
/// C++17, so that framework extensions built as C++17 can read and implement it.

#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/filters/monitor.hpp"

namespace safecass::introspect {

/// One sample of one signal, written at the time of apply() (a scenario's `sample` step).
struct PushSample {
  std::string signal;  ///< "Component.signal"
  std::vector<double> values;
};
/// An event processed on one machine (a broadcast event: on s_A of every component).
struct GenerateEvent {
  std::string event;
  std::string target;  ///< a machine address, "C.s_A"
};
/// A broadcast event (severity 251-255) processed on s_A of every component.
struct BroadcastEvent {
  std::string event;
};
/// Clears the conditions originating in `target`, recording who asked and why.
struct ResetState {
  std::string target;  ///< a machine, a component, SYSTEM or the coordinator's name
  std::string who;     ///< "console", "scenario", "viewer", ...
  std::string why;
};
/// Samples queued into one filter's private input (Monitor::inject_shallow).
struct InjectShallow {
  std::string filter;
  std::vector<std::vector<double>> samples;
};
/// Samples written into a signal's history at the time of apply(), seen by every consumer
/// (Monitor::inject_deep; the console's `filter dinject` and `filter dinload`).
struct InjectDeep {
  std::string signal;
  std::vector<std::vector<double>> samples;
};

using Action = std::variant<PushSample, GenerateEvent, BroadcastEvent, ResetState, InjectShallow, InjectDeep>;

/// The action's name as the console and the documents say it: "sample", "generate", "broadcast",
/// "reset", "inject", "dinject".
std::string_view action_name(const Action& action) noexcept;

/// Told of every action after apply() applied it (a refused action is not told). Called on the
/// applying thread, after the action; must not apply actions itself.
class ActionObserver {
public:
  virtual ~ActionObserver() = default;
  /// `action` was applied at `at` (the time apply() was given).
  virtual void applied(const Action& action, Time at) = 0;
};

/// Why `action` cannot be applied to the system of `co` and `monitor`, changing nothing: the
/// errors of resolve_generate/resolve_broadcast/resolve_reset (core/named.hpp) and of the
/// Monitor's check_inject_shallow/check_inject_deep; for a sample, NotFound (no such signal) or
/// InvalidArgument (a wrong number of values).
[[nodiscard]] Expected<void> check(const Action& action, const Coordinator& co, const Monitor& monitor);

/// Checks `action` (as check()) and applies it at `now`; then tells `observer`, when given. An
/// error changes nothing and tells no one.
[[nodiscard]] Expected<void> apply(const Action& action, Coordinator& co, Monitor& monitor, Time now,
                                   ActionObserver* observer = nullptr);

}  // namespace safecass::introspect
