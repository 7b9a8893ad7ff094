#include "safecass/introspect/action.hpp"
#include "safecass/core/named.hpp"

#include <string>
#include <type_traits>

namespace safecass::introspect {

namespace {

template <class T>
inline constexpr bool kIs = false;

[[nodiscard]] Expected<Signal*> sample_signal(const Monitor& monitor, const PushSample& s) {
  Signal* signal = monitor.signals().find(s.signal);
  if (signal == nullptr) {
    return fail(ErrorCode::NotFound, "no signal '" + s.signal + "' (signals are written Component.signal)");
  }
  if (s.values.size() != signal->size()) {
    return fail(ErrorCode::InvalidArgument, "sample of " + s.signal + ": " + std::to_string(s.values.size()) +
                                                " values; the signal has size " + std::to_string(signal->size()));
  }
  return signal;
}

}  // namespace

std::string_view action_name(const Action& action) noexcept {
  static constexpr std::string_view kNames[] = {"sample", "generate", "broadcast", "reset", "inject", "dinject"};
  static_assert(std::size(kNames) == std::variant_size_v<Action>);
  return kNames[action.index()];
}

[[nodiscard]] Expected<void> check(const Action& action, const Coordinator& co, const Monitor& monitor) {
  return std::visit(
      [&](const auto& a) -> Expected<void> {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, PushSample>) {
          if (auto s = sample_signal(monitor, a); !s) return tl::unexpected(s.error());
          return {};
        } else if constexpr (std::is_same_v<A, GenerateEvent>) {
          if (auto t = resolve_generate(co.structure(), a.event, a.target); !t) return tl::unexpected(t.error());
          return {};
        } else if constexpr (std::is_same_v<A, BroadcastEvent>) {
          if (auto e = resolve_broadcast(co.structure(), a.event); !e) return tl::unexpected(e.error());
          return {};
        } else if constexpr (std::is_same_v<A, ResetState>) {
          if (auto t = resolve_reset(co.structure(), a.target); !t) return tl::unexpected(t.error());
          return {};
        } else if constexpr (std::is_same_v<A, InjectShallow>) {
          return monitor.check_inject_shallow(a.filter, a.samples);
        } else if constexpr (std::is_same_v<A, InjectDeep>) {
          return monitor.check_inject_deep(a.signal, a.samples);
        } else {
          static_assert(kIs<A>, "an Action alternative without its check");
        }
      },
      action);
}

[[nodiscard]] Expected<void> apply(const Action& action, Coordinator& co, Monitor& monitor, Time now,
                                   ActionObserver* observer) {
  auto done = std::visit(
      [&](const auto& a) -> Expected<void> {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, PushSample>) {
          auto s = sample_signal(monitor, a);
          if (!s) return tl::unexpected(s.error());
          (*s)->push(now, a.values.data());
          return {};
        } else if constexpr (std::is_same_v<A, GenerateEvent>) {
          return generate(co, a.event, a.target);
        } else if constexpr (std::is_same_v<A, BroadcastEvent>) {
          return broadcast(co, a.event);
        } else if constexpr (std::is_same_v<A, ResetState>) {
          return reset(co, a.target, a.who, a.why);
        } else if constexpr (std::is_same_v<A, InjectShallow>) {
          return monitor.inject_shallow(a.filter, a.samples);
        } else if constexpr (std::is_same_v<A, InjectDeep>) {
          return monitor.inject_deep(a.signal, a.samples, now);
        } else {
          static_assert(kIs<A>, "an Action alternative without its application");
        }
      },
      action);
  if (done && observer != nullptr) observer->applied(action, now);
  return done;
}

}  // namespace safecass::introspect
