// The shape of a coordinator's model: lookups by name and the names interned for causes.

#include "safecass/core/structure.hpp"

#include <string>

namespace safecass {

Expected<ComponentId> Structure::find_component(std::string_view name) const {
  if (const auto it = component_index_.find(name); it != component_index_.end()) return it->second;
  return fail(ErrorCode::NotFound, "no component '" + std::string(name) + "'");
}

Expected<EventId> Structure::find_event(std::string_view name) const {
  if (const auto it = event_index_.find(name); it != event_index_.end()) return it->second;
  return fail(ErrorCode::NotFound, "no event '" + std::string(name) + "'");
}

Expected<Address> Structure::resolve(std::string_view text) const {
  Address a;
  // SYSTEM, or the coordinator's own name when no component has that name.
  if (text == "SYSTEM" || (text == name_ && !find_component(text))) return a;
  const auto dot = text.find('.');
  auto comp = find_component(text.substr(0, dot));
  if (!comp)
    return fail(ErrorCode::NotFound,
                "address '" + std::string(text) + "': no component '" + std::string(text.substr(0, dot)) + "'");
  a.component = *comp;
  const Component& c = components_[*comp];
  if (dot == std::string_view::npos) {
    a.kind = Address::Kind::Component;
    return a;
  }
  const std::string_view rest = text.substr(dot + 1);
  a.kind = Address::Kind::Machine;
  if (rest == "s_F") {
    a.machine = c.framework;
    return a;
  }
  if (rest == "s_A") {
    a.machine = c.application;
    return a;
  }
  const auto dot2 = rest.find('.');
  const std::string_view kind = rest.substr(0, dot2);
  if (dot2 == std::string_view::npos || (kind != "s_P" && kind != "s_R" && kind != "s_S")) {
    return fail(ErrorCode::Parse,
                "address '" + std::string(text) + "': expected C, C.s_F, C.s_A, C.s_P.p, C.s_R.r, C.s_S.p or SYSTEM");
  }
  const std::string_view iface = rest.substr(dot2 + 1);
  const auto& list = kind == "s_R" ? c.required : c.provided;
  for (std::uint32_t i = 0; i < list.size(); ++i) {
    if (interface_name(list[i]) == iface) {
      if (kind == "s_S") {
        a.kind = Address::Kind::Service;
        a.service = i;
      } else {
        a.machine = list[i];
      }
      return a;
    }
  }
  return fail(ErrorCode::NotFound, "address '" + std::string(text) + "': component '" + c.name + "' has no " +
                                       (kind == "s_R" ? "required" : "provided") + " interface '" + std::string(iface) +
                                       "'");
}

Expected<MachineId> Structure::find_machine(std::string_view address) const {
  auto a = resolve(address);
  if (!a) return tl::unexpected(a.error());
  if (a->kind != Address::Kind::Machine) {
    return fail(ErrorCode::InvalidArgument,
                "address '" + std::string(address) + "' is not a state machine (use C.s_F, C.s_A, C.s_P.p or C.s_R.r)");
  }
  return a->machine;
}

std::string_view Structure::interface_name(MachineId id) const noexcept {
  const Machine& m = machines_[id];
  switch (m.kind) {
    case MachineKind::Framework: return "s_F";
    case MachineKind::Application: return "s_A";
    case MachineKind::Provided:
    case MachineKind::Required: break;
  }
  const std::string_view a = m.address;
  return a.substr(a.rfind('.') + 1);
}

NameId Structure::intern(std::string_view text) {
  std::lock_guard lock(names_mutex_);
  if (const auto it = name_index_.find(text); it != name_index_.end()) return it->second;
  const auto id = id_at<NameId>(names_.size());
  name_index_.emplace(std::string_view(names_.emplace_back(text)), id);
  return id;
}

std::string_view Structure::name_of(NameId id) const {
  std::lock_guard lock(names_mutex_);
  if (to_index(id) >= names_.size()) return {};
  return names_[to_index(id)];
}

std::vector<MachineId> Structure::machines_of(ComponentId id) const {
  const Component& c = components_[id];
  std::vector<MachineId> out{c.framework, c.application};
  out.insert(out.end(), c.provided.begin(), c.provided.end());
  out.insert(out.end(), c.required.begin(), c.required.end());
  return out;
}

}  // namespace safecass
