#include "safecass/viewer/live_diff.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <utility>

#include "safecass/spec/json.hpp"

namespace safecass::viewer {

namespace {

std::string seconds(double t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6f", t);
  return buf;
}

std::string component_of(const std::string& address) { return address.substr(0, address.find('.')); }

/// The interface name of "C.s_P.I" / "C.s_R.I" / "C.s_S.I": what follows the second dot.
std::string interface_of(const std::string& address) {
  const auto first = address.find('.');
  const auto second = first == std::string::npos ? std::string::npos : address.find('.', first + 1);
  return second == std::string::npos ? address : address.substr(second + 1);
}

bool machine_kind(const std::string& kind, NodeKind& out) {
  if (kind == "s_F") out = NodeKind::Framework;
  else if (kind == "s_A") out = NodeKind::Application;
  else if (kind == "s_P") out = NodeKind::Provided;
  else if (kind == "s_R") out = NodeKind::Required;
  else if (kind == "s_S") out = NodeKind::Service;
  else return false;
  return true;
}

std::string transition_record(const LiveRow* before, const LiveRow& after, double t) {
  const State from = before == nullptr ? State::Normal : before->state;
  std::string event = after.outstanding;
  if (event.empty() && before != nullptr) event = before->outstanding;
  const bool component = after.kind == "component";
  std::string out = "{\"t\":" + seconds(t) + ",\"kind\":" + spec::json_quote(component ? "component-transition" : "transition");
  out += ",\"component\":" + spec::json_quote(component_of(after.address));
  if (!component) out += ",\"machine\":" + spec::json_quote(after.address);
  if (!event.empty()) out += ",\"event\":" + spec::json_quote(event);
  out += ",\"from\":" + spec::json_quote(to_string(from)) + ",\"to\":" + spec::json_quote(to_string(after.state)) + "}";
  return out;
}

}  // namespace

std::vector<LiveRow> skeleton_rows(const Coordinator& co) {
  std::vector<LiveRow> out;
  auto outstanding = [&](EventId e) { return e == kNoEvent ? std::string() : co.event(e).name; };
  for (ComponentId id = 0; id < co.component_count(); ++id) {
    if (co.is_remote(id)) continue;
    const std::string name(co.component_name(id));
    const StateSnapshot s = co.extended(id);
    out.push_back({name, "component", s.state, s.state == State::Normal ? std::string() : outstanding(s.outstanding)});
    auto machine = [&](MachineId m, const char* kind) {
      const StateSnapshot ms = co.snapshot(m);
      out.push_back({co.address_of(m), kind, ms.state, ms.state == State::Normal ? std::string() : outstanding(ms.outstanding)});
    };
    machine(co.framework_machine(id), "s_F");
    machine(co.application_machine(id), "s_A");
    for (const MachineId m : co.provided_machines(id)) machine(m, "s_P");
    for (const MachineId m : co.required_machines(id)) machine(m, "s_R");
    const auto& provided = co.provided_machines(id);
    for (std::uint32_t p = 0; p < provided.size(); ++p) {
      out.push_back({name + ".s_S." + std::string(co.interface_name(provided[p])), "s_S", co.service_state(id, p), {}});
    }
  }
  return out;
}

CoordinatorView coordinator_view(std::string name, const std::vector<LiveRow>& rows) {
  CoordinatorView cv;
  cv.name = std::move(name);
  for (const LiveRow& r : rows) {
    if (r.kind == "component") {
      ComponentView c;
      c.name = r.address;
      c.state = r.state;
      if (r.state != State::Normal) c.outstanding = r.outstanding;
      cv.state = std::max(cv.state, c.state);
      cv.components.push_back(std::move(c));
      continue;
    }
    NodeKind kind{};
    if (!machine_kind(r.kind, kind) || cv.components.empty() || component_of(r.address) != cv.components.back().name) continue;
    MachineView m;
    m.address = r.address;
    m.kind = kind;
    m.name = kind == NodeKind::Framework ? "s_F" : kind == NodeKind::Application ? "s_A" : interface_of(r.address);
    m.state = r.state;
    if (r.state != State::Normal && kind != NodeKind::Service) m.outstanding = r.outstanding;
    cv.components.back().machines.push_back(std::move(m));
  }
  return cv;
}

std::vector<std::string> diff_records(const std::vector<LiveRow>& before, const std::vector<LiveRow>& after, double t) {
  std::map<std::string_view, const LiveRow*> old;
  for (const LiveRow& r : before) old.emplace(r.address, &r);
  std::vector<std::string> out;
  for (const LiveRow& r : after) {
    NodeKind kind{};
    if (r.kind != "component" && !machine_kind(r.kind, kind)) continue;
    const auto it = old.find(r.address);
    const LiveRow* b = it == old.end() ? nullptr : it->second;
    const State from = b == nullptr ? State::Normal : b->state;
    const std::string& was = b == nullptr ? std::string() : b->outstanding;
    if (from == r.state && (r.state == State::Normal || was == r.outstanding)) continue;
    out.push_back(transition_record(b, r, t));
  }
  // Rows that disappeared (a coordinator that now lists fewer components) go back to Normal.
  std::map<std::string_view, bool> present;
  for (const LiveRow& r : after) present.emplace(r.address, true);
  for (const LiveRow& r : before) {
    NodeKind kind{};
    if (present.count(r.address) != 0 || r.state == State::Normal || (r.kind != "component" && !machine_kind(r.kind, kind))) continue;
    LiveRow normal{r.address, r.kind, State::Normal, {}};
    out.push_back(transition_record(&r, normal, t));
  }
  return out;
}

std::string coordinator_record(std::string_view coordinator, std::string_view text, double t) {
  return "{\"t\":" + seconds(t) + ",\"kind\":\"coordinator\",\"coordinator\":" + spec::json_quote(coordinator) +
         ",\"text\":" + spec::json_quote(text) + "}";
}

}  // namespace safecass::viewer
