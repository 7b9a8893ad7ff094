// The coordinator's writes and explain by name (named.hpp).

#include "safecass/core/named.hpp"

#include <string>

namespace safecass {

[[nodiscard]] Expected<GenerateTarget> resolve_generate(const Structure& s, std::string_view event,
                                                        std::string_view target) {
  auto e = s.find_event(event);
  if (!e) return tl::unexpected(e.error());
  const Event& ev = s.event(*e);
  if (!ev.is_onset && ev.counterpart == kNoEvent) {
    return fail(ErrorCode::InvalidState,
                "event '" + ev.name + "' completes '" + ev.completes + "', which is not defined");
  }
  if (ev.is_broadcast()) return GenerateTarget{*e, kNoMachine};
  auto m = s.find_machine(target);
  if (!m) return tl::unexpected(m.error());
  return GenerateTarget{*e, *m};
}

[[nodiscard]] Expected<EventId> resolve_broadcast(const Structure& s, std::string_view event) {
  auto e = s.find_event(event);
  if (!e) return tl::unexpected(e.error());
  if (const Event& ev = s.event(*e); !ev.is_broadcast()) {
    return fail(ErrorCode::InvalidArgument, "event '" + std::string(event) + "' has severity " +
                                                std::to_string(ev.severity) + "; broadcasts need severity 251-255");
  }
  return *e;
}

[[nodiscard]] Expected<Address> resolve_reset(const Structure& s, std::string_view target) {
  auto a = s.resolve(target);
  if (!a) return tl::unexpected(a.error());
  if (a->kind == Address::Kind::Service) {
    return fail(ErrorCode::InvalidArgument, "cannot reset service state '" + std::string(target) +
                                                "': it is derived; reset its component or a machine");
  }
  return *a;
}

[[nodiscard]] Expected<void> generate(Coordinator& co, std::string_view event, std::string_view target) {
  auto t = resolve_generate(co.structure(), event, target);
  if (!t) return tl::unexpected(t.error());
  co.generate(t->event, t->machine);
  return {};
}

[[nodiscard]] Expected<void> broadcast(Coordinator& co, std::string_view event) {
  auto e = resolve_broadcast(co.structure(), event);
  if (!e) return tl::unexpected(e.error());
  co.generate(*e, kNoMachine);
  return {};
}

[[nodiscard]] Expected<void> reset(Coordinator& co, std::string_view target, std::string_view who,
                                   std::string_view why) {
  auto a = resolve_reset(co.structure(), target);
  if (!a) return tl::unexpected(a.error());
  co.reset(*a, who, why);
  return {};
}

[[nodiscard]] Expected<std::vector<Explanation>> explain(const Coordinator& co, std::string_view address) {
  auto a = co.structure().resolve(address);
  if (!a) return tl::unexpected(a.error());
  return co.explain(*a);
}

}  // namespace safecass
