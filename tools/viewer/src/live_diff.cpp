#include "safecass/viewer/live_diff.hpp"

#include <algorithm>
#include <utility>

#include "safecass/json/write.hpp"

namespace safecass::viewer {

namespace {

std::string component_of(const std::string& address) { return address.substr(0, address.find('.')); }

/// The interface name of "C.s_P.I" / "C.s_R.I" / "C.s_S.I": what follows the second dot.
std::string interface_of(const std::string& address) {
  const auto first = address.find('.');
  const auto second = first == std::string::npos ? std::string::npos : address.find('.', first + 1);
  return second == std::string::npos ? address : address.substr(second + 1);
}

bool node_kind(introspect::RowKind kind, NodeKind& out) {
  switch (kind) {
    case introspect::RowKind::Framework: out = NodeKind::Framework; return true;
    case introspect::RowKind::Application: out = NodeKind::Application; return true;
    case introspect::RowKind::Provided: out = NodeKind::Provided; return true;
    case introspect::RowKind::Required: out = NodeKind::Required; return true;
    case introspect::RowKind::Service: out = NodeKind::Service; return true;
    case introspect::RowKind::System:
    case introspect::RowKind::Component: break;
  }
  return false;
}

}  // namespace

CoordinatorView coordinator_view(std::string name, const std::vector<introspect::StateRow>& rows) {
  CoordinatorView cv;
  cv.name = std::move(name);
  for (const introspect::StateRow& r : rows) {
    if (r.kind == introspect::RowKind::Component) {
      ComponentView c;
      c.name = r.address;
      c.state = r.state;
      if (r.state != State::Normal) c.outstanding = r.outstanding;
      cv.state = std::max(cv.state, c.state);
      cv.components.push_back(std::move(c));
      continue;
    }
    NodeKind kind{};
    if (!node_kind(r.kind, kind) || cv.components.empty() || component_of(r.address) != cv.components.back().name)
      continue;
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

std::string coordinator_record(std::string_view coordinator, std::string_view text, double t) {
  return json::JsonObject()
      .raw("t", json::json_seconds(seconds_to_time(t)))
      .str("kind", "coordinator")
      .str("coordinator", coordinator)
      .str("text", text)
      .text();
}

}  // namespace safecass::viewer
