#include "safecass/spec/load.hpp"

#include <algorithm>
#include <exception>
#include <map>

#include "model.hpp"
#include "text.hpp"

namespace safecass::spec {

Position Sink::position(const Site& site) const {
  Position p;
  if (site.file >= 0 && static_cast<std::size_t>(site.file) < documents.size()) {
    p.file = documents[static_cast<std::size_t>(site.file)].path;
  }
  p.line = site.position.line;
  p.column = site.position.column;
  return p;
}

std::string Sink::at(const Site& site) const {
  const Position p = position(site);
  return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

void Sink::add(Diagnostic::Severity severity, const Site& site, std::string message) {
  Diagnostic d;
  d.severity = severity;
  d.where = position(site);
  d.message = std::move(message);
  d.pointer = site.pointer;
  if (severity == Diagnostic::Severity::Note) {
    notes.push_back(std::move(d));
    note_files.push_back(site.file);
    return;
  }
  diagnostics.push_back(std::move(d));
  files.push_back(site.file);
}

std::size_t Sink::error_count() const {
  return static_cast<std::size_t>(std::count_if(diagnostics.begin(), diagnostics.end(), [](const Diagnostic& d) {
    return d.severity == Diagnostic::Severity::Error;
  }));
}

const std::vector<FrameworkEvent>& framework_events() {
  static const std::vector<FrameworkEvent> events = [] {
    std::vector<FrameworkEvent> out;
    const Coordinator probe("framework-events");
    for (EventId id : id_range<EventId>(framework_event::kCount)) {
      const Event& e = probe.structure().event(id);
      FrameworkEvent f;
      f.name = e.name;
      f.onset = e.is_onset;
      f.severity = e.severity;
      f.transitions = e.transitions;
      if (e.counterpart != kNoEvent) f.counterpart = probe.structure().event(e.counterpart).name;
      out.push_back(std::move(f));
    }
    return out;
  }();
  return events;
}

SystemSpec to_system(const Model& model, const Sink& sink) {
  SystemSpec system;
  system.name = model.name;
  system.path = model.path;
  // A framework filter template is not a component: its filters were instantiated for every
  // component, and its own events (other than repeated framework events) are system events,
  // given to the first component (event names are system-wide).
  std::vector<EventDef> template_events;
  std::vector<Position> template_where;  // parallel to template_events
  for (const ComponentItem& c : model.components) {
    if (!c.is_template()) continue;
    for (const EventItem& e : c.events) {
      if (e.framework_redefinition) continue;
      template_events.push_back(e.def);
      template_where.push_back(sink.position(e.name_site));
    }
  }
  for (const ComponentItem& c : model.components) {
    if (c.is_template() || c.stand_in) continue;
    ComponentSpec out;
    out.name = c.name;
    for (const Name& n : c.provided) out.provided.push_back(n.text);
    for (const Name& n : c.required) out.required.push_back(n.text);
    for (const SignalItem& s : c.signals) out.signals.push_back(SignalSpec{s.name, s.size});
    for (const EventItem& e : c.events) {
      if (e.framework_redefinition) continue;
      out.events.push_back(e.def);
      out.event_where.push_back(sink.position(e.name_site));
    }
    if (system.components.empty()) {
      out.events.insert(out.events.end(), template_events.begin(), template_events.end());
      out.event_where.insert(out.event_where.end(), template_where.begin(), template_where.end());
    }
    for (const FilterEntryItem& entry : c.filters) {
      FilterSpec f;
      f.pipeline = entry.pipeline;
      f.where = sink.position(entry.site);
      for (const FilterItem& stage : entry.stages) f.stages.push_back(stage.config);
      out.filters.push_back(std::move(f));
    }
    for (const ServiceItem& s : c.services) out.services.push_back(ServiceSpec{s.provided, s.dependency});
    for (const Name& p : c.provided) {
      const bool written =
          std::any_of(c.services.begin(), c.services.end(), [&](const ServiceItem& s) { return s.provided == p.text; });
      if (!written) out.services.push_back(ServiceSpec{p.text, ServiceDependency{}});
    }
    out.period = c.period;
    out.file = sink.position(c.site).file;
    out.where = sink.position(c.name_site);
    system.components.push_back(std::move(out));
  }
  for (const ConnectionItem& k : model.connections) {
    system.connections.push_back(ConnectionSpec{k.required, k.provided, sink.position(k.site)});
  }
  for (const CoordinatorItem& co : model.coordinators) {
    std::vector<std::string> components;
    for (const Name& n : co.components) components.push_back(n.text);
    system.coordinators.emplace_back(co.name.text, std::move(components));
  }
  for (const HazardItem& h : model.hazards) {
    HazardSpec out;
    out.id = h.id;
    out.description = h.description;
    out.where = sink.position(h.id_site);
    for (const HazardItem::Reaction& r : h.reaction) {
      out.reaction.emplace_back(r.address, parse_state(r.level).value_or(State::Error));
      out.reaction_where.push_back(sink.position(r.key_site));
    }
    system.hazards.push_back(std::move(out));
  }
  for (const InvariantItem& i : model.invariants) {
    system.invariants.push_back(InvariantSpec{i.name, i.formula, i.description, sink.position(i.name_site)});
  }
  if (model.reliability) {
    ReliabilitySpec r;
    r.mission_time = model.reliability->mission_time.value_or(ReliabilitySpec::kDefaultMissionTime);
    r.where = sink.position(model.reliability->site);
    for (const ReliabilityItem::Mode& m : model.reliability->modes)
      r.modes.push_back(ReliabilitySpec::Mode{m.name, m.rate, m.probability, sink.position(m.key_site)});
    system.reliability = std::move(r);
  }
  return system;
}

namespace {

LoadResult load(const std::string& path, const std::string* text, const FilterRegistry& registry) {
  Sink sink;
  Model model;
  LoadResult result;
  try {
    read_files(path, text, sink, model);
    validate(model, registry, sink);
    if (sink.error_count() == 0) result.system = to_system(model, sink);
  } catch (const std::exception& e) {
    // Not expected: every input is checked before use. Reported, never propagated.
    result.system.reset();
    sink.error(Site{sink.documents.empty() ? -1 : 0, {}, ""}, std::string("internal error while loading: ") + e.what());
  }
  // Files in load order, then positions; problems at one position keep the order they were found in.
  std::vector<std::size_t> order(sink.diagnostics.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Diagnostic& x = sink.diagnostics[a];
    const Diagnostic& y = sink.diagnostics[b];
    const int fx = sink.files[a];
    const int fy = sink.files[b];
    if (fx != fy) return fx < fy;
    if (x.where.line != y.where.line) return x.where.line < y.where.line;
    return x.where.column < y.where.column;
  });
  for (const std::size_t i : order) result.diagnostics.push_back(std::move(sink.diagnostics[i]));
  std::vector<std::size_t> note_order(sink.notes.size());
  for (std::size_t i = 0; i < note_order.size(); ++i) note_order[i] = i;
  std::stable_sort(note_order.begin(), note_order.end(), [&](std::size_t a, std::size_t b) {
    const Diagnostic& x = sink.notes[a];
    const Diagnostic& y = sink.notes[b];
    if (sink.note_files[a] != sink.note_files[b]) return sink.note_files[a] < sink.note_files[b];
    if (x.where.line != y.where.line) return x.where.line < y.where.line;
    return x.where.column < y.where.column;
  });
  for (const std::size_t i : note_order) result.notes.push_back(std::move(sink.notes[i]));
  return result;
}

}  // namespace

bool LoadResult::ok() const { return errors() == 0; }

std::size_t LoadResult::errors() const {
  return static_cast<std::size_t>(std::count_if(diagnostics.begin(), diagnostics.end(), [](const Diagnostic& d) {
    return d.severity == Diagnostic::Severity::Error;
  }));
}

std::size_t LoadResult::warnings() const { return diagnostics.size() - errors(); }

LoadResult load_system(const std::string& path, const FilterRegistry& registry) {
  return load(path, nullptr, registry);
}

LoadResult load_system_from_text(std::string_view text, const std::string& name, const FilterRegistry& registry) {
  const std::string copy(text);
  return load(name, &copy, registry);
}

}  // namespace safecass::spec
