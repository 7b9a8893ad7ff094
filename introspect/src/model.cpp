#include "safecass/introspect/model.hpp"

namespace safecass::introspect {

std::string_view to_string(RowKind kind) noexcept {
  switch (kind) {
    case RowKind::System: return "system";
    case RowKind::Component: return "component";
    case RowKind::Framework: return "framework";
    case RowKind::Application: return "application";
    case RowKind::Provided: return "provided";
    case RowKind::Required: return "required";
    case RowKind::Service: return "service";
  }
  return "?";
}

bool parse_row_kind(std::string_view text, RowKind& out) noexcept {
  for (const RowKind k : {RowKind::System, RowKind::Component, RowKind::Framework, RowKind::Application,
                          RowKind::Provided, RowKind::Required, RowKind::Service}) {
    if (to_string(k) == text) {
      out = k;
      return true;
    }
  }
  return false;
}

std::string_view HistoryEntry::where() const noexcept {
  if (!machine.empty()) return machine;
  if (!component.empty()) return component;
  return "-";
}

HistoryEntry history_entry(const Record& r, const Coordinator& co) {
  const Structure& shape = co.structure();
  HistoryEntry e;
  e.seq = r.seq;
  e.time = r.time;
  e.kind = r.kind;
  e.outcome = r.outcome;
  if (r.component != kNoComponent && to_index(r.component) < shape.component_count())
    e.component = std::string(shape.component_name(r.component));
  if (r.machine != kNoMachine && to_index(r.machine) < shape.machine_count()) e.machine = shape.address_of(r.machine);
  if (r.event != kNoEvent && to_index(r.event) < shape.event_count()) e.event = shape.event(r.event).name;
  e.from = r.from;
  e.to = r.to;
  e.level = r.level;
  e.severity = r.severity;
  e.mirror = r.mirror;
  if (r.root.event != kNoEvent && to_index(r.root.event) < shape.event_count() && r.root.origin != kNoMachine &&
      to_index(r.root.origin) < shape.machine_count()) {
    e.root = co.resolve_root(r.root);
  }
  e.text = std::string(r.text);
  return e;
}

}  // namespace safecass::introspect
