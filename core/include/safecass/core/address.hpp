#pragma once
/// @file address.hpp
/// The text of an address of the Generic Component Model (DESIGN §2): the one place that spells
/// `C.s_F`, `C.s_A`, `C.s_P.p`, `C.s_R.r` and `C.s_S.p`. Structure::resolve (structure.hpp) reads them.

#include <cstdint>
#include <string>
#include <string_view>

namespace safecass {

/// The four kinds of state machine a component owns (DESIGN §2.2).
enum class MachineKind : std::uint8_t { Framework, Application, Provided, Required };

namespace address {

/// "C.s_F": the framework state machine of component C.
inline std::string framework(std::string_view component) { return std::string(component) + ".s_F"; }
/// "C.s_A": the application state machine of component C.
inline std::string application(std::string_view component) { return std::string(component) + ".s_A"; }
/// "C.s_P.p": the state machine of provided interface p of component C.
inline std::string provided(std::string_view component, std::string_view iface) {
  return std::string(component) + ".s_P." + std::string(iface);
}
/// "C.s_R.r": the state machine of required interface r of component C.
inline std::string required(std::string_view component, std::string_view iface) {
  return std::string(component) + ".s_R." + std::string(iface);
}
/// Writes "C.s_S.p" into `out`, reusing its storage (for hot paths).
inline void assign_service(std::string& out, std::string_view component, std::string_view iface) {
  out.assign(component).append(".s_S.").append(iface);
}
/// "C.s_S.p": the service state of provided interface p of component C (a derived state).
inline std::string service(std::string_view component, std::string_view iface) {
  std::string out;
  assign_service(out, component, iface);
  return out;
}

/// The address of the machine of `kind` of `component` (`iface`: the interface's name, for a
/// provided or required interface).
inline std::string machine(MachineKind kind, std::string_view component, std::string_view iface) {
  switch (kind) {
    case MachineKind::Framework: return framework(component);
    case MachineKind::Application: return application(component);
    case MachineKind::Provided: return provided(component, iface);
    case MachineKind::Required: return required(component, iface);
  }
  return application(component);
}

}  // namespace address
}  // namespace safecass
