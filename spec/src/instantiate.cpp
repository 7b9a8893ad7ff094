#include <algorithm>
#include <set>

#include "safecass/spec/load.hpp"

namespace safecass::spec {

namespace {

std::string component_of(std::string_view address) { return std::string(address.substr(0, address.find('.'))); }

tl::unexpected<Error> in(std::string_view what, const Error& e) {
  return tl::unexpected<Error>(Error{e.code, std::string(what) + ": " + e.message});
}

}  // namespace

[[nodiscard]] Expected<void> instantiate(const SystemSpec& system, Coordinator& coordinator, Monitor& monitor,
                                         std::string_view only_coordinator) {
  std::set<std::string, std::less<>> local;
  if (!only_coordinator.empty()) {
    const auto it = std::find_if(system.coordinators.begin(), system.coordinators.end(),
                                 [&](const auto& c) { return c.first == only_coordinator; });
    if (it == system.coordinators.end()) {
      std::string known;
      for (const auto& c : system.coordinators) known += (known.empty() ? "" : ", ") + c.first;
      return fail(ErrorCode::NotFound, "system '" + system.name + "' has no coordinator '" +
                                           std::string(only_coordinator) + "'" +
                                           (known.empty() ? " (it declares none)" : " (known: " + known + ")"));
    }
    local.insert(it->second.begin(), it->second.end());
  }
  const auto is_local = [&](std::string_view component) {
    return only_coordinator.empty() || local.count(component) > 0;
  };

  for (const ComponentSpec& c : system.components) {
    if (!is_local(c.name)) continue;
    auto id = coordinator.add_component(c.name);
    if (!id) return tl::unexpected(id.error());
    for (const std::string& p : c.provided) {
      if (auto r = coordinator.add_provided(*id, p); !r) return tl::unexpected(r.error());
    }
    for (const std::string& r : c.required) {
      if (auto e = coordinator.add_required(*id, r); !e) return tl::unexpected(e.error());
    }
  }
  // Every event of the system: events are system-wide names.
  for (const ComponentSpec& c : system.components) {
    for (const EventDef& e : c.events) {
      if (auto r = coordinator.add_event(e); !r) return in("component '" + c.name + "'", r.error());
    }
  }
  for (const ComponentSpec& c : system.components) {
    if (!is_local(c.name)) continue;
    const ComponentId id = *coordinator.structure().find_component(c.name);
    for (const ServiceSpec& s : c.services) {
      if (auto r = coordinator.set_service(id, s.provided, s.dependency); !r) return tl::unexpected(r.error());
    }
  }
  for (const ConnectionSpec& k : system.connections) {
    if (!is_local(component_of(k.required)) || !is_local(component_of(k.provided))) continue;
    if (auto r = coordinator.connect(k.required, k.provided); !r) return tl::unexpected(r.error());
  }
  for (const ComponentSpec& c : system.components) {
    if (!is_local(c.name)) continue;
    for (const SignalSpec& s : c.signals) {
      if (auto r = monitor.add_signal(s.name, s.size); !r) return in("component '" + c.name + "'", r.error());
    }
  }
  // Filters run where their target component runs, in system order (a filter may read what an
  // earlier one writes).
  for (const ComponentSpec& c : system.components) {
    for (const FilterSpec& f : c.filters) {
      if (f.stages.empty() || !is_local(f.stages.front().target.component)) continue;
      if (f.pipeline.empty()) {
        if (auto r = monitor.add_filter(f.stages.front()); !r) return in("component '" + c.name + "'", r.error());
      } else {
        if (auto r = monitor.add_pipeline(f.pipeline, f.stages); !r) return in("component '" + c.name + "'", r.error());
      }
    }
  }
  return {};
}

}  // namespace safecass::spec
