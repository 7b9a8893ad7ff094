// Cross-reference checks of a specification (DESIGN §5): names, events, interfaces, connections,
// coordinators, filters (parameters, signals, sizes, events), and which events can happen at all.

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>

#include "safecass/spec/formula.hpp"

#include "model.hpp"
#include "text.hpp"

namespace safecass::spec {

namespace {

std::vector<std::string> names_of(const std::vector<Name>& names) {
  std::vector<std::string> out;
  for (const Name& n : names) out.push_back(n.text);
  return out;
}

bool contains(const std::vector<Name>& names, std::string_view text) {
  return std::any_of(names.begin(), names.end(), [&](const Name& n) { return n.text == text; });
}

std::string qualify(std::string_view signal, std::string_view component) {
  if (signal.find('.') != std::string_view::npos) return std::string(signal);
  return std::string(component) + "." + std::string(signal);
}

/// A parameter as written, converted to the type its manifest expects.
std::optional<ParamValue> convert(const json::JsonValue& v, ParamType type) {
  switch (v.type) {
    case json::JsonValue::Type::Number: return ParamValue(v.number);
    case json::JsonValue::Type::Bool: return ParamValue(v.boolean);
    case json::JsonValue::Type::String: return ParamValue(v.string);
    case json::JsonValue::Type::Array: {
      const bool strings =
          std::all_of(v.array.begin(), v.array.end(), [](const json::JsonValue& x) { return x.is_string(); });
      const bool numbers =
          std::all_of(v.array.begin(), v.array.end(), [](const json::JsonValue& x) { return x.is_number(); });
      if (v.array.empty()) {
        return type == ParamType::NumberList ? ParamValue(std::vector<double>{})
                                             : ParamValue(std::vector<std::string>{});
      }
      if (strings) {
        std::vector<std::string> out;
        for (const json::JsonValue& x : v.array) out.push_back(x.string);
        return ParamValue(std::move(out));
      }
      if (numbers) {
        std::vector<double> out;
        for (const json::JsonValue& x : v.array) out.push_back(x.number);
        return ParamValue(std::move(out));
      }
      return std::nullopt;
    }
    case json::JsonValue::Type::Null:
    case json::JsonValue::Type::Object: break;
  }
  return std::nullopt;
}

std::string param_type_text(const ParamSpec& p) {
  switch (p.type) {
    case ParamType::Number: return "a number";
    case ParamType::Integer: return "an integer";
    case ParamType::Bool: return "true or false";
    case ParamType::String: return "a string";
    case ParamType::Choice: return "one of " + join_or(p.choices);
    case ParamType::Signal: return "a signal name";
    case ParamType::SignalList: return "a list of signal names";
    case ParamType::Event: return "an event name";
    case ParamType::NumberList: return "a list of numbers";
  }
  return "a value";
}

struct EventInfo {
  bool framework = false;
  bool kind_known = false;
  bool onset = true;
  bool latched = false;
  int severity = 0;
  std::string completes;                 ///< completion: its onset
  std::vector<std::string> completions;  ///< onset: the completions that clear it
  const EventItem* item = nullptr;
  bool generated = false;
};

struct SignalInfo {
  std::size_t size = 0;  ///< 0: unknown (the writer's sizes could not be checked)
  std::string writer;    ///< the filter that writes it, if any
  Site site;
};

class Validator {
public:
  Validator(Model& model, const FilterRegistry& registry, Sink& sink) : m_(model), registry_(registry), sink_(sink) {}

  void run() {
    expand_templates();
    check_components();
    for (ComponentItem& c : m_.components) check_interfaces(c);
    for (ComponentItem& c : m_.components) check_signals(c);
    check_events();
    check_connections();
    check_coordinators();
    for (ComponentItem& c : m_.components) check_filters(c);
    check_event_use();
    check_unconnected();
    check_hazards();
    check_invariants();
    check_reliability();
  }

private:
  // ---- framework filter templates ---------------------------------------------------------------
  /// A component file with `"component": ""` is a framework filter template (the 2016 framework
  /// filter file): its filters are instantiated for every component of the system, their target
  /// component ("" or absent) being that component; its events are system events. Loaded alone,
  /// it is checked against a stand-in component that is not part of the system.
  void expand_templates() {
    std::vector<std::size_t> templates;
    std::vector<std::size_t> real;
    for (std::size_t i = 0; i < m_.components.size(); ++i) {
      (m_.components[i].is_template() ? templates : real).push_back(i);
    }
    if (templates.empty()) return;
    for (const std::size_t t : templates) {
      const ComponentItem& c = m_.components[t];
      const auto refuse = [&](const Site& site, const char* what) {
        sink_.error(site, std::string("framework filter template (\"component\": \"\"): ") + what +
                              " cannot be applied to every component; a template holds events and filters");
      };
      if (c.has_interfaces || !c.provided.empty() || !c.required.empty()) refuse(c.site, "interfaces");
      if (!c.signals.empty()) refuse(c.signals.front().site, "signals");
      if (!c.services.empty()) refuse(c.services.front().site, "services");
    }
    if (real.empty()) {
      ComponentItem stand_in;
      stand_in.name = "COMPONENT";
      stand_in.has_name = true;
      stand_in.stand_in = true;
      stand_in.site = stand_in.name_site = m_.components[templates.front()].site;
      m_.components.push_back(std::move(stand_in));
      real.push_back(m_.components.size() - 1);
    }
    for (const std::size_t t : templates) {
      std::vector<FilterEntryItem> entries = std::move(m_.components[t].filters);
      m_.components[t].filters.clear();
      for (const std::size_t r : real) {
        ComponentItem& c = m_.components[r];
        for (std::size_t k = 0; k < entries.size(); ++k) {
          FilterEntryItem copy = entries[k];
          for (FilterItem& stage : copy.stages) {
            stage.owner = c.name;
            stage.from_template = true;
            if (!stage.target_component_given || stage.config.target.component.empty())
              stage.config.target.component = c.name;
            if (stage.named) {
              stage.config.name = c.name + "." + stage.config.name;
            } else if (copy.pipeline.empty()) {
              const FilterRegistry::Entry* e = registry_.find(stage.config.type);
              stage.config.name = c.name + ".framework." + (e != nullptr ? e->manifest.type : stage.config.type) + "_" +
                                  std::to_string(k + 1);
              stage.named = true;  // named here, not by its position in c's list
            }
          }
          if (!copy.pipeline.empty() && copy.pipeline != "?") copy.pipeline = c.name + "_" + copy.pipeline;
          c.filters.push_back(std::move(copy));
        }
      }
    }
  }

  // ---- components ------------------------------------------------------------------------------
  void check_components() {
    for (std::size_t i = 0; i < m_.components.size(); ++i) {
      ComponentItem& c = m_.components[i];
      if (c.is_template()) continue;  // its filters were given to every component
      if (!c.has_name) {
        invalid_components_.insert(c.name);  // reported as a missing key
        continue;
      }
      if (!simple_name(c.name)) {
        sink_.error(c.name_site, "component name " + quote_name(c.name) + " must be non-empty, without dots or spaces");
        invalid_components_.insert(c.name);
        continue;
      }
      if (c.name == "SYSTEM") {
        sink_.error(c.name_site, "component name 'SYSTEM' is reserved: it is the address of the whole system");
        invalid_components_.insert(c.name);
        continue;
      }
      const auto [it, fresh] = components_.emplace(c.name, i);
      if (!fresh) {
        sink_.error(c.name_site, "duplicate component " + quote_name(c.name) + " (first defined at " +
                                     sink_.at(m_.components[it->second].name_site) + ")");
      }
    }
    if (m_.system_file && m_.has_components_key && m_.component_entries == 0) {
      sink_.warning(Site{0,
                         sink_.documents.empty() || !sink_.documents[0].root ? json::TextPosition{}
                                                                             : sink_.documents[0].root->position,
                         ""},
                    "system " + quote_name(m_.name) + " has no components");
    }
  }

  const ComponentItem* component(std::string_view name) const {
    const auto it = components_.find(name);
    return it == components_.end() ? nullptr : &m_.components[it->second];
  }

  std::vector<std::string> component_names() const {
    std::vector<std::string> out;
    for (const auto& [name, index] : components_) out.push_back(name);
    return out;
  }

  // ---- interfaces and services -----------------------------------------------------------------
  void check_interfaces(ComponentItem& c) {
    if (c.is_template()) return;  // reported by expand_templates()
    const std::string who = "component " + quote_name(c.name);
    if (!c.has_interfaces) {
      // 2016 files declare no interfaces: the services name the provided ones, their s_R lists
      // the required ones.
      for (const ServiceItem& s : c.services) {
        if (s.has_name && !contains(c.provided, s.provided)) c.provided.push_back(Name{s.provided, s.name_site});
        for (const Name& r : s.required) {
          if (!contains(c.required, r.text)) c.required.push_back(r);
        }
      }
    }
    for (const auto* list : {&c.provided, &c.required}) {
      const bool provided = list == &c.provided;
      std::map<std::string, Site, std::less<>> seen;
      for (const Name& n : *list) {
        if (!simple_name(n.text)) {
          sink_.error(n.site,
                      who + ": interface name " + quote_name(n.text) + " must be non-empty, without dots or spaces");
          continue;
        }
        const auto [it, fresh] = seen.emplace(n.text, n.site);
        if (!fresh) {
          sink_.error(n.site, who + ": duplicate " + (provided ? "provided" : "required") + " interface " +
                                  quote_name(n.text) + " (first at " + sink_.at(it->second) + ")");
        }
      }
    }
    std::map<std::string, Site, std::less<>> services;
    for (const ServiceItem& s : c.services) {
      if (!s.has_name) continue;
      if (!contains(c.provided, s.provided)) {
        sink_.error(s.name_site, who + ": service " + quote_name(s.provided) + " names no provided interface" +
                                     did_you_mean(s.provided, names_of(c.provided)));
      } else {
        const auto [it, fresh] = services.emplace(s.provided, s.name_site);
        if (!fresh) {
          sink_.error(s.name_site, who + ": duplicate service entry for " + quote_name(s.provided) + " (first at " +
                                       sink_.at(it->second) + ")");
        }
      }
      for (const Name& r : s.required) {
        if (!contains(c.required, r.text)) {
          sink_.error(r.site, who + ": service " + quote_name(s.provided) + " depends on unknown required interface " +
                                  quote_name(r.text) + did_you_mean(r.text, names_of(c.required)));
        }
      }
    }
  }

  // ---- signals ---------------------------------------------------------------------------------
  void check_signals(ComponentItem& c) {
    if (c.is_template()) return;                        // reported by expand_templates()
    if (invalid_components_.count(c.name) > 0) return;  // reported with the name
    for (const SignalItem& s : c.signals) {
      const auto dot = s.name.find('.');
      const std::string owner = s.name.substr(0, dot);
      const std::string bare = s.name.substr(dot + 1);
      if (c.has_name && owner != c.name) {
        sink_.error(s.site, "component " + quote_name(c.name) + ": signal " + quote_name(s.name) +
                                " belongs to another component; declare it as " + quote_name(bare) + " or " +
                                quote_name(c.name + "." + bare));
        continue;
      }
      if (!simple_name(bare)) {
        sink_.error(s.site, "component " + quote_name(c.name) + ": signal name " + quote_name(bare) +
                                " must be non-empty, without dots or spaces");
        continue;
      }
      const auto [it, fresh] = signals_.emplace(s.name, SignalInfo{s.size, {}, s.site});
      if (!fresh) {
        sink_.error(s.site, "duplicate signal " + quote_name(s.name) + " (first at " + sink_.at(it->second.site) + ")");
      }
    }
  }

  // ---- events ----------------------------------------------------------------------------------
  void check_events() {
    for (const FrameworkEvent& f : framework_events()) {
      EventInfo info;
      info.framework = true;
      info.kind_known = true;
      info.onset = f.onset;
      info.severity = f.severity;
      if (f.onset)
        info.completions.push_back(f.counterpart);
      else
        info.completes = f.counterpart;
      events_.emplace(f.name, std::move(info));
    }
    std::vector<EventItem*> completions;
    for (ComponentItem& c : m_.components) {
      for (EventItem& e : c.events) {
        if (!e.has_name) continue;
        const std::string& name = e.def.name;
        if (!token_name(name)) {
          sink_.error(e.name_site, "event name " + quote_name(name) + " must be non-empty, without spaces");
          continue;
        }
        const auto existing = events_.find(name);
        if (existing != events_.end()) {
          if (existing->second.framework) {
            check_framework_redefinition(e);
          } else {
            sink_.error(e.name_site, "duplicate event " + quote_name(name) + " (first defined at " +
                                         sink_.at(existing->second.item->name_site) + ")");
          }
          continue;
        }
        EventInfo info;
        info.item = &e;
        info.severity = e.def.severity;
        info.latched = e.def.latched;
        if (e.has_transitions && e.transitions_valid) {
          const TransitionSet t = e.def.transitions;
          if (t.empty()) {
            sink_.error(e.transitions_site,
                        "event " + quote_name(name) +
                            ": 'state_transition' is empty: list worsening transitions (an onset) or "
                            "improving ones (a completion)");
          } else if (t.worsening_only() || t.improving_only()) {
            info.kind_known = true;
            info.onset = t.worsening_only();
          } else {
            sink_.error(e.transitions_site, "event " + quote_name(name) +
                                                " mixes worsening (N2W, N2E, W2E) and improving (W2N, E2N, E2W) "
                                                "transitions: an event is either an onset or a completion");
          }
        }
        if (info.kind_known && info.onset && !e.def.completes.empty()) {
          sink_.error(e.completes_site, "event " + quote_name(name) +
                                            " is an onset: only a completion may say which onset it 'completes'");
        }
        if (info.kind_known && !info.onset) {
          if (e.def.latched) {
            sink_.error(e.latched_site, "event " + quote_name(name) + " is a completion: only an onset can be latched");
          }
          info.completes = e.def.completes;
          if (info.completes.empty()) {
            if (name.size() > 1 && name[0] == '/') {
              info.completes = name.substr(1);
            } else {
              sink_.error(e.name_site, "completion " + quote_name(name) +
                                           " must be named '/ONSET' or say which onset it 'completes'");
            }
          }
          if (!info.completes.empty()) completions.push_back(&e);
        }
        events_.emplace(name, std::move(info));
      }
    }
    for (EventItem* e : completions) {
      const std::string& completes = events_.at(e->def.name).completes;
      const auto it = events_.find(completes);
      const Site& site = e->def.completes.empty() ? e->name_site : e->completes_site;
      if (it == events_.end()) {
        std::vector<std::string> onsets;
        for (const auto& [n, info] : events_) {
          if (info.kind_known && info.onset) onsets.push_back(n);
        }
        sink_.error(site, "completion " + quote_name(e->def.name) + " completes " + quote_name(completes) +
                              ", which is not defined" + did_you_mean(completes, onsets));
      } else if (it->second.kind_known && !it->second.onset) {
        sink_.error(site, "completion " + quote_name(e->def.name) + " completes " + quote_name(completes) +
                              ", which is not an onset");
      } else if (it->second.kind_known) {
        it->second.completions.push_back(e->def.name);
      }
    }
    for (const ComponentItem& c : m_.components) {
      for (const EventItem& e : c.events) {
        const auto it = events_.find(e.def.name);
        if (!e.has_name || it == events_.end() || it->second.item != &e) continue;
        const EventInfo& info = it->second;
        if (!info.kind_known || !info.onset) continue;
        if (info.completions.empty() && !info.latched) {
          sink_.warning(e.name_site, "onset " + quote_name(e.def.name) +
                                         " has no completion: nothing can clear it but a reset (needs reset); define " +
                                         quote_name("/" + e.def.name) +
                                         ", or mark it \"latched\": true if that is intended");
        } else if (info.completions.size() > 1) {
          std::vector<std::string> q;
          for (const std::string& n : info.completions) q.push_back(quote_name(n));
          std::string list;
          for (std::size_t i = 0; i < q.size(); ++i) list += (i == 0 ? "" : i + 1 == q.size() ? " and " : ", ") + q[i];
          sink_.warning(e.name_site, "onset " + quote_name(e.def.name) + " has " + std::to_string(q.size()) +
                                         " completions (" + list +
                                         "): name the one each filter sends with its completion parameter");
        }
      }
    }
  }

  /// A definition of a framework event, as the 2016 framework filter file carries: accepted when
  /// it means what the built-in means (same kind, severity and level from every state), and then
  /// the built-in is used (a note says so); refused otherwise, saying what differs. The built-in
  /// definitions are fixed because extensions, supervision and propagation raise them everywhere.
  void check_framework_redefinition(EventItem& e) {
    const std::string& name = e.def.name;
    const FrameworkEvent* builtin = nullptr;
    for (const FrameworkEvent& f : framework_events()) {
      if (f.name == name) builtin = &f;
    }
    if (builtin == nullptr) return;
    const std::string head = "event " + quote_name(name) + " redefines the framework event";
    if (!e.has_severity || !e.has_transitions || !e.transitions_valid) return;  // reported as such
    const TransitionSet t = e.def.transitions;
    const bool onset = t.worsening_only() && !t.empty();
    const bool completion = t.improving_only() && !t.empty();
    std::string differs;
    if (onset != builtin->onset || (!onset && !completion)) {
      differs = std::string("it is ") + (builtin->onset ? "an onset" : "a completion");
    } else if (e.def.severity != builtin->severity) {
      differs = "its severity is " + std::to_string(builtin->severity) + ", not " + std::to_string(e.def.severity);
    } else if (onset) {
      for (const State from : {State::Normal, State::Warning}) {
        if (onset_level(t, from) != onset_level(builtin->transitions, from)) {
          differs = std::string("from ") + std::string(to_string(from)) + " it leads to " +
                    std::string(to_string(onset_level(builtin->transitions, from))) + ", not " +
                    std::string(to_string(onset_level(t, from)));
          break;
        }
      }
    }
    if (!differs.empty()) {
      sink_.error(e.name_site,
                  head + " differently: " + differs +
                      "; a framework event cannot be changed: remove this definition, or give your event another name");
      return;
    }
    if (!e.def.completes.empty() || e.def.latched) {
      sink_.error(e.name_site, head + " with 'completes' or 'latched': a framework event cannot be changed");
      return;
    }
    e.framework_redefinition = true;
    sink_.note(e.name_site, head + " as it is (severity " + std::to_string(builtin->severity) +
                                "): the built-in definition is used");
  }

  std::vector<std::string> event_names() const {
    std::vector<std::string> out;
    for (const auto& [n, info] : events_) out.push_back(n);
    return out;
  }

  // ---- connections -----------------------------------------------------------------------------
  struct End {
    const ComponentItem* component = nullptr;
    std::string interface;
  };

  std::optional<End> connection_end(const std::string& text, bool required, const Site& site) {
    const char* role = required ? "required" : "provided";
    const auto dot = text.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() ||
        text.find('.', dot + 1) != std::string::npos) {
      sink_.error(
          site, std::string("connection: '") + role + "' must be written Component.interface, not " + quote_name(text));
      return std::nullopt;
    }
    const std::string comp = text.substr(0, dot);
    End end;
    end.component = component(comp);
    end.interface = text.substr(dot + 1);
    if (end.component == nullptr) {
      sink_.error(site, "connection: no component " + quote_name(comp) + did_you_mean(comp, component_names()));
      return std::nullopt;
    }
    const std::vector<Name>& same = required ? end.component->required : end.component->provided;
    const std::vector<Name>& other = required ? end.component->provided : end.component->required;
    if (contains(same, end.interface)) return end;
    if (contains(other, end.interface)) {
      sink_.error(
          site, "connection: " + quote_name(text) + " is a " + (required ? "provided" : "required") + " interface; '" +
                    role + "' must name a " + role + " interface" +
                    (same.empty() ? std::string(" (component ") + quote_name(comp) + " has none)"
                                  : std::string(" of ") + quote_name(comp) + " (" + join_or(names_of(same)) + ")"));
      return std::nullopt;
    }
    sink_.error(site, "connection: component " + quote_name(comp) + " has no " + role + " interface " +
                          quote_name(end.interface) + did_you_mean(end.interface, names_of(same)));
    return std::nullopt;
  }

  void check_connections() {
    const std::size_t before = sink_.error_count();
    check_each_connection();
    connection_errors_ = sink_.error_count() > before;
  }

  void check_each_connection() {
    for (const ConnectionItem& k : m_.connections) {
      if (!k.complete) continue;
      const auto client = connection_end(k.required, true, k.required_site);
      const auto provider = connection_end(k.provided, false, k.provided_site);
      if (!client || !provider) continue;
      if (client->component == provider->component) {
        sink_.error(k.site,
                    "connection " + k.required + " -> " + k.provided + ": a component cannot require its own service");
        continue;
      }
      const auto [it, fresh] = connected_.emplace(k.required, &k);
      if (!fresh) {
        sink_.error(k.required_site, "required interface " + k.required + " is already connected (to " +
                                         it->second->provided + " at " + sink_.at(it->second->site) +
                                         "); a required interface takes one connection");
      }
    }
  }

  // ---- coordinators ----------------------------------------------------------------------------
  void check_coordinators() {
    if (!m_.has_coordinators) return;
    std::map<std::string, Site, std::less<>> assigned;
    std::map<std::string, Site, std::less<>> names;
    for (const CoordinatorItem& co : m_.coordinators) {
      if (const auto [it, fresh] = names.emplace(co.name.text, co.name.site); !fresh) {
        sink_.error(co.name.site,
                    "duplicate coordinator " + quote_name(co.name.text) + " (first at " + sink_.at(it->second) + ")");
      }
      if (!simple_name(co.name.text)) {
        sink_.error(co.name.site,
                    "coordinator name " + quote_name(co.name.text) + " must be non-empty, without dots or spaces");
      } else if (co.name.text == "SYSTEM") {
        sink_.error(co.name.site, "coordinator name 'SYSTEM' is reserved: it is the address of the whole system");
      } else if (component(co.name.text) != nullptr) {
        sink_.error(co.name.site,
                    "coordinator " + quote_name(co.name.text) +
                        " has the name of a component: a coordinator's name addresses all its components");
      }
      for (const Name& n : co.components) {
        if (component(n.text) == nullptr) {
          sink_.error(n.site, "coordinator " + quote_name(co.name.text) + ": no component " + quote_name(n.text) +
                                  did_you_mean(n.text, component_names()));
          continue;
        }
        const auto [it, fresh] = assigned.emplace(n.text, n.site);
        if (!fresh) {
          sink_.error(n.site, "component " + quote_name(n.text) + " is already in coordinator " +
                                  quote_name(coordinator_of_[n.text]) + " (at " + sink_.at(it->second) +
                                  "); a component runs in one coordinator");
          continue;
        }
        coordinator_of_[n.text] = co.name.text;
      }
    }
    for (const auto& [name, index] : components_) {
      if (assigned.count(name) == 0) {
        sink_.warning(m_.components[index].name_site,
                      "component " + quote_name(name) + " is in no coordinator: no process will monitor it");
      }
    }
  }

  /// The coordinator that runs `component`, or "" (one coordinator, or not assigned).
  std::string coordinator_of(std::string_view component) const {
    const auto it = coordinator_of_.find(std::string(component));
    return it == coordinator_of_.end() ? std::string() : it->second;
  }

  // ---- filters ---------------------------------------------------------------------------------
  void check_filters(ComponentItem& c) {
    for (std::size_t index = 0; index < c.filters.size(); ++index) {
      FilterEntryItem& entry = c.filters[index];
      const bool is_pipeline_entry = !entry.pipeline.empty();
      bool duplicate_pipeline = false;
      if (is_pipeline_entry) {
        if (entry.pipeline != "?" && !simple_name(entry.pipeline)) {
          sink_.error(entry.name_site,
                      "pipeline name " + quote_name(entry.pipeline) + " must be non-empty, without dots or spaces");
        } else if (entry.pipeline != "?") {
          const auto [it, fresh] = pipelines_.emplace(entry.pipeline, entry.name_site);
          if (!fresh) {
            duplicate_pipeline = true;
            sink_.error(entry.name_site, "duplicate pipeline " + quote_name(entry.pipeline) + " (first at " +
                                             sink_.at(it->second) + ")");
          }
        }
        if (entry.stages.empty()) {
          sink_.error(entry.site, "pipeline " + quote_name(entry.pipeline) + " has no stages");
          continue;
        }
        wire_pipeline(entry);
      } else if (!entry.stages.empty() && !entry.stages.front().named) {
        FilterItem& f = entry.stages.front();
        const FilterRegistry::Entry* e = registry_.find(f.config.type);
        f.config.name =
            c.name + "." + (e != nullptr ? e->manifest.type : f.config.type) + "_" + std::to_string(index + 1);
      }
      std::string coordinator;
      for (std::size_t k = 0; k < entry.stages.size(); ++k) {
        FilterItem& f = entry.stages[k];
        check_filter(f, duplicate_pipeline && !f.named);
        if (is_pipeline_entry && m_.has_coordinators) {
          const std::string here = coordinator_of(f.config.target.component);
          if (k == 0)
            coordinator = here;
          else if (here != coordinator && !here.empty() && !coordinator.empty()) {
            sink_.error(f.target_component_site, "pipeline " + quote_name(entry.pipeline) + ": stage " +
                                                     std::to_string(k + 1) + " targets a component of coordinator " +
                                                     quote_name(here) + " but the pipeline runs in " +
                                                     quote_name(coordinator));
          }
        }
      }
    }
  }

  /// What the monitor does to a pipeline: unnamed stages are called "<pipeline>.<k>", a stage
  /// without an input reads the previous stage's output, intermediate outputs without a name
  /// are called "<pipeline>_<k>".
  void wire_pipeline(FilterEntryItem& entry) {
    std::string previous_output;
    for (std::size_t i = 0; i < entry.stages.size(); ++i) {
      FilterItem& stage = entry.stages[i];
      if (!stage.named) stage.config.name = entry.pipeline + "." + std::to_string(i + 1);
      const FilterRegistry::Entry* e = stage.has_class ? registry_.find(stage.config.type) : nullptr;
      const auto has_param = [&](const std::string& name) {
        return std::any_of(stage.params.begin(), stage.params.end(),
                           [&](const ParamItem& p) { return p.name == name; });
      };
      if (e != nullptr && i > 0 && !e->manifest.inputs.empty()) {
        const bool has_input = std::any_of(e->manifest.inputs.begin(), e->manifest.inputs.end(), has_param);
        if (!has_input && !previous_output.empty()) {
          stage.params.push_back(
              ParamItem{e->manifest.inputs.front(), stage.site, stage.site, nullptr, previous_output});
        }
      }
      if (e != nullptr && !e->manifest.outputs.empty() && i + 1 < entry.stages.size() &&
          !has_param(e->manifest.outputs.front())) {
        stage.params.push_back(ParamItem{e->manifest.outputs.front(), stage.site, stage.site, nullptr,
                                         entry.pipeline + "_" + std::to_string(i + 1)});
      }
      previous_output.clear();
      if (e != nullptr && !e->manifest.outputs.empty()) {
        for (const ParamItem& p : stage.params) {
          if (p.name != e->manifest.outputs.front()) continue;
          if (p.value == nullptr)
            previous_output = qualify(p.synthetic, stage.config.target.component);
          else if (p.value->is_string())
            previous_output = qualify(p.value->string, stage.config.target.component);
        }
      }
    }
  }

  /// What check_filter's steps share about one filter.
  struct FilterCheck {
    std::string ctx;  ///< "filter 'NAME' (Type)", the prefix of every message
    const FilterRegistry::Entry* entry = nullptr;
    const ComponentItem* target = nullptr;                       ///< null when the target component does not exist
    std::string coordinator;                                     ///< of the target component
    Params given;                                                ///< the parameters that convert and check one by one
    std::map<std::string, const ParamItem*, std::less<>> items;  ///< where each given one is written
    bool params_ok = true;
    Params checked;  ///< all parameters checked together (with defaults), when params_ok
  };

  void check_filter(FilterItem& f, bool skip_duplicate_name) {
    FilterCheck c;
    c.ctx = "filter " + quote_name(f.config.name);
    check_filter_name(f, skip_duplicate_name);
    if (!f.has_class) return;  // reported as a missing key
    c.entry = filter_class(f, c.ctx);
    if (c.entry == nullptr) return;
    const FilterManifest& manifest = c.entry->manifest;
    f.config.type = manifest.type;
    c.ctx += " (" + manifest.type + ")";
    normalize_filter_params(f, c.ctx, manifest);
    c.target = check_filter_target(f, c.ctx);
    c.coordinator = coordinator_of(f.config.target.component);
    check_filter_params(f, manifest, c);
    f.config.params = c.given;

    // Events first: whatever else is wrong, the events a filter names count as generated, so
    // that one mistake is not reported twice.
    check_filter_events(f, c.ctx, manifest, c.given, c.items);
    if (c.target == nullptr) return;  // signals are resolved against the target component
    const std::optional<std::vector<std::size_t>> sizes = check_filter_inputs(f, c);
    check_filter_outputs(f, c, sizes);
  }

  /// A filter's name: a token, and unique (unless its pipeline's name was reported duplicate).
  void check_filter_name(const FilterItem& f, bool skip_duplicate_name) {
    if (f.named && !token_name(f.config.name)) {
      sink_.error(f.name_site, "filter name " + quote_name(f.config.name) + " must be non-empty, without spaces");
    } else if (!skip_duplicate_name) {
      const auto [it, fresh] = filters_.emplace(f.config.name, f.named ? f.name_site : f.site);
      if (!fresh) {
        sink_.error(f.named ? f.name_site : f.site,
                    "duplicate filter " + quote_name(f.config.name) + " (first at " + sink_.at(it->second) + ")");
      }
    }
  }

  /// The registry's entry of the filter's class, or null (reported, with the nearest known name;
  /// the events the filter names still count as generated).
  const FilterRegistry::Entry* filter_class(const FilterItem& f, const std::string& ctx) {
    const FilterRegistry::Entry* entry = registry_.find(f.config.type);
    if (entry != nullptr) return entry;
    std::vector<std::string> known;
    for (const FilterManifest* m : registry_.manifests()) known.push_back(m->type);
    std::string suggestion = did_you_mean(f.config.type, known);
    if (suggestion.empty() && f.config.type.rfind("Filter", 0) == 0) {
      suggestion = did_you_mean(f.config.type.substr(6), known);
    }
    if (suggestion.empty()) suggestion = " (known: " + join_list(known) + ")";
    sink_.error(f.class_site, ctx + ": unknown filter class " + quote_name(f.config.type) + suggestion);
    mark_named_events(f);
    return nullptr;
  }

  /// Events named under a misspelled parameters key count as generated; aliases become their
  /// parameter; a type that names its own output gets the default output parameter.
  void normalize_filter_params(FilterItem& f, const std::string& ctx, const FilterManifest& manifest) {
    if (f.misspelled_argument != nullptr && f.misspelled_argument->is_object()) {
      // The parameters are under a misspelled key (reported): the events they name still count
      // as generated, so that the one mistake is not reported again as "not generated".
      for (const json::JsonMember& m : f.misspelled_argument->object) {
        const auto mark = [&](const json::JsonValue& v) {
          if (!v.is_string()) return;
          if (const auto e = events_.find(v.string); e != events_.end()) e->second.generated = true;
        };
        mark(m.value);
        for (const json::JsonValue& item : m.value.array) mark(item);
      }
    }
    // Aliases of parameters (ChangeDetection's 2016 `event`) are checked as the parameter.
    for (ParamItem& p : f.params) {
      const std::string_view canonical = manifest.canonical(p.name);
      if (canonical == p.name) continue;
      const bool both =
          std::any_of(f.params.begin(), f.params.end(), [&](const ParamItem& q) { return q.name == canonical; });
      if (both) {
        sink_.error(p.key_site, ctx + ": parameters " + quote_name(p.name) + " and " + quote_name(canonical) +
                                    " are the same parameter; give one");
        p.name = "\x01duplicate";  // reported: not checked again
        continue;
      }
      p.name = std::string(canonical);
    }
    // A type that names its own output (the 2016 transforms) writes the signal named after the filter.
    if (manifest.default_output && !manifest.outputs.empty() && !f.argument_misspelled &&
        std::none_of(f.params.begin(), f.params.end(),
                     [&](const ParamItem& p) { return p.name == manifest.outputs.front(); })) {
      f.params.push_back(ParamItem{manifest.outputs.front(), f.argument_site, f.argument_site, nullptr,
                                   default_output_name(f.config.name, f.config.target.component)});
    }
  }

  /// The target: its component exists, and so does the interface it names. Returns the target
  /// component, or null.
  const ComponentItem* check_filter_target(const FilterItem& f, const std::string& ctx) {
    const std::string& tc = f.config.target.component;
    const ComponentItem* target = component(tc);
    if (target == nullptr && invalid_components_.count(tc) > 0) {
      // The component's name has been reported.
    } else if (target == nullptr) {
      sink_.error(f.target_component_site, ctx + ": target component " + quote_name(tc) + " does not exist" +
                                               did_you_mean(tc, component_names()));
    } else if (f.config.target.kind == MachineKind::Provided || f.config.target.kind == MachineKind::Required) {
      const bool provided = f.config.target.kind == MachineKind::Provided;
      const std::vector<Name>& list = provided ? target->provided : target->required;
      if (!f.has_target_interface) {
        sink_.error(f.target_site, ctx + ": target type " + (provided ? "s_P" : "s_R") + " needs an 'interface'");
      } else if (!contains(list, f.config.target.interface)) {
        sink_.error(f.target_interface_site, ctx + ": component " + quote_name(tc) + " has no " +
                                                 (provided ? "provided" : "required") + " interface " +
                                                 quote_name(f.config.target.interface) +
                                                 did_you_mean(f.config.target.interface, names_of(list)));
      }
    } else if (f.has_target_interface) {
      sink_.warning(f.target_interface_site, ctx + ": 'interface' is ignored for target type " +
                                                 (f.config.target.kind == MachineKind::Framework ? "s_F" : "s_A"));
    }
    return target;
  }

  /// The parameters, one by one so that every problem is reported, then all together.
  void check_filter_params(const FilterItem& f, const FilterManifest& manifest, FilterCheck& c) {
    const std::string& ctx = c.ctx;
    Params& given = c.given;
    std::map<std::string, const ParamItem*, std::less<>>& items = c.items;
    bool& params_ok = c.params_ok;
    std::vector<std::string> param_names;
    for (const ParamSpec& p : manifest.params) param_names.push_back(p.name);
    std::set<std::string, std::less<>> misspelled;  // known names that an unknown parameter is a typo of
    for (const ParamItem& p : f.params) {
      if (p.name == "\x01duplicate") {
        params_ok = false;
        continue;
      }
      const ParamSpec* spec = manifest.find(p.name);
      if (spec == nullptr) {
        if (const std::string_view now = renamed_parameter(p.name); !now.empty() && manifest.find(now) != nullptr) {
          // A parameter of the original format with a new name: say which.
          misspelled.insert(std::string(now));
          sink_.error(p.key_site, ctx + ": unknown parameter " + quote_name(p.name) + " (the original's name): write " +
                                      quote_name(now));
          params_ok = false;
          continue;
        }
        if (const auto near = nearest(p.name, param_names)) misspelled.insert(*near);
        std::string suggestion = did_you_mean(p.name, param_names);
        if (suggestion.empty()) suggestion = " (known: " + join_list(param_names) + ")";
        sink_.error(p.key_site, ctx + ": unknown parameter " + quote_name(p.name) + suggestion);
        params_ok = false;
        continue;
      }
      std::optional<ParamValue> value =
          p.value == nullptr ? std::optional<ParamValue>(ParamValue(p.synthetic)) : convert(*p.value, spec->type);
      if (!value) {
        sink_.error(p.value_site, ctx + ": parameter " + quote_name(p.name) + " must be " + param_type_text(*spec) +
                                      ", not " + a_type(p.value->type));
        params_ok = false;
        continue;
      }
      if (const std::string problem = number_problem(*spec, *value); !problem.empty()) {
        sink_.error(p.value_site, ctx + ": parameter " + quote_name(p.name) + " must be " + problem);
        params_ok = false;
        continue;
      }
      FilterManifest one;
      one.type = manifest.type;
      one.params = {*spec};
      auto checked = check_params(one, Params{{p.name, *value}}, f.config.name);
      if (!checked) {
        sink_.error(p.value_site, checked.error().message);
        params_ok = false;
        continue;
      }
      given[p.name] = std::move(*value);
      items[p.name] = &p;
    }
    if (!has_input_given(f, manifest) && f.argument_misspelled) params_ok = false;
    const std::string pipeline_note =
        f.stage > 0 ? "; the previous stage of pipeline " + quote_name(f.pipeline) + " writes no output it could read"
                    : "";
    bool missing_input = false;
    for (const ParamSpec& spec : manifest.params) {
      if (spec.default_value || spec.optional || given.count(spec.name) > 0) continue;
      if (std::any_of(f.params.begin(), f.params.end(), [&](const ParamItem& p) { return p.name == spec.name; }))
        continue;
      const bool input = std::find(manifest.inputs.begin(), manifest.inputs.end(), spec.name) != manifest.inputs.end();
      missing_input = missing_input || input;
      params_ok = false;
      if (misspelled.count(spec.name) > 0) continue;  // reported as the unknown parameter
      if (f.argument_misspelled) continue;            // reported as the misspelled 'argument' key
      sink_.error(f.argument_site, ctx + ": missing parameter " + quote_name(spec.name) + " (" + spec.doc + ")" +
                                       (input ? pipeline_note : ""));
    }
    const bool has_input = std::any_of(manifest.inputs.begin(), manifest.inputs.end(), [&](const std::string& n) {
      return std::any_of(f.params.begin(), f.params.end(), [&](const ParamItem& p) { return p.name == n; });
    });
    if (!manifest.inputs.empty() && !has_input && !missing_input && !f.argument_misspelled) {
      sink_.error(f.argument_site, ctx + ": needs an input (" + join_or(manifest.inputs) + ")" + pipeline_note);
      params_ok = false;
    }
    Params checked;
    if (params_ok) {
      auto all = check_params(manifest, given, f.config.name);
      if (all) {
        checked = std::move(*all);
      } else {
        sink_.error(f.argument_site, all.error().message);
        params_ok = false;
      }
    }
    c.checked = std::move(checked);
  }

  /// Input signals, in manifest order (lists expanded), as the monitor resolves them; then the
  /// filter type's own size check on stand-in signals of the declared sizes. Returns the sizes
  /// of its outputs, when known.
  std::optional<std::vector<std::size_t>> check_filter_inputs(const FilterItem& f, const FilterCheck& c) {
    const std::string& ctx = c.ctx;
    const std::string& tc = f.config.target.component;
    const FilterManifest& manifest = c.entry->manifest;
    std::vector<std::unique_ptr<Signal>> scratch;
    std::vector<std::pair<std::string, Site>> input_sites;
    bool sizes_known = c.params_ok;
    for (const std::string& input : manifest.inputs) {
      const auto it = c.given.find(input);
      if (it == c.given.end()) continue;
      const ParamItem* item = c.items.at(input);
      std::vector<std::pair<std::string, Site>> names;
      if (const auto* one = std::get_if<std::string>(&it->second)) names.emplace_back(*one, item->value_site);
      if (const auto* many = std::get_if<std::vector<std::string>>(&it->second)) {
        for (std::size_t k = 0; k < many->size(); ++k) {
          Site s = item->value_site;
          if (item->value != nullptr && k < item->value->array.size()) {
            s.position = item->value->array[k].position;
            s.pointer = pointer_join(s.pointer, k);
          }
          names.emplace_back((*many)[k], s);
        }
      }
      for (const auto& [name, site] : names) {
        const std::size_t size = resolve_input(ctx, input, name, site, tc, c.coordinator, f.from_template);
        if (size == 0) {
          sizes_known = false;
          continue;
        }
        scratch.push_back(std::make_unique<Signal>(qualify(name, tc), ComponentId{0}, size, 1));
        input_sites.emplace_back(scratch.back()->name(), site);
      }
    }

    std::optional<std::vector<std::size_t>> sizes;
    if (!sizes_known) return sizes;
    std::vector<Signal*> inputs;
    for (const auto& sig : scratch) inputs.push_back(sig.get());
    try {
      auto r = c.entry->shape(FilterShape{f.config.name, c.checked, inputs});
      if (r) {
        sizes = std::move(*r);
      } else {
        // Point at the input the message names, if it names one.
        Site site = f.argument_site;
        for (const auto& [name, input_site] : input_sites) {
          if (r.error().message.find("'" + name + "'") != std::string::npos) {
            site = input_site;
            break;
          }
        }
        sink_.error(site, r.error().message);
      }
    } catch (const std::exception& e) {
      sink_.error(f.argument_site, ctx + ": the size check failed: " + e.what());
    }
    return sizes;
  }

  /// Output signals: created by the filter unless they exist; an existing one must have the size
  /// written, and a second writer is warned of.
  void check_filter_outputs(const FilterItem& f, const FilterCheck& c,
                            const std::optional<std::vector<std::size_t>>& sizes) {
    const std::string& ctx = c.ctx;
    const std::string& tc = f.config.target.component;
    const FilterManifest& manifest = c.entry->manifest;
    for (std::size_t k = 0; k < manifest.outputs.size(); ++k) {
      const std::string& output = manifest.outputs[k];
      const auto it = c.given.find(output);
      if (it == c.given.end() || !std::holds_alternative<std::string>(it->second)) continue;
      const Site& site = c.items.at(output)->value_site;
      const std::string full = qualify(std::get<std::string>(it->second), tc);
      const auto dot = full.find('.');
      if (dot == 0 || dot + 1 == full.size()) {
        sink_.error(site, ctx + ": parameter " + quote_name(output) + ": " + quote_name(full) +
                              " is not a signal name (Component.signal, or a bare name for the target component)");
        continue;
      }
      const std::string comp = full.substr(0, dot);
      if (component(comp) == nullptr) {
        sink_.error(site, ctx + ": parameter " + quote_name(output) + ": no component " + quote_name(comp) +
                              " for signal " + quote_name(full) + did_you_mean(comp, component_names()));
        continue;
      }
      check_same_coordinator(ctx, output, full, comp, c.coordinator, site);
      const std::size_t size = sizes && k < sizes->size() ? (*sizes)[k] : 0;
      const auto existing = signals_.find(full);
      if (existing == signals_.end()) {
        signals_.emplace(full, SignalInfo{size, f.config.name, site});
        continue;
      }
      if (size != 0 && existing->second.size != 0 && existing->second.size != size) {
        sink_.error(site, ctx + ": parameter " + quote_name(output) + ": signal " + quote_name(full) + " has size " +
                              std::to_string(existing->second.size) + " but this filter writes " +
                              std::to_string(size));
      }
      if (!existing->second.writer.empty()) {
        sink_.warning(site, ctx + " writes signal " + quote_name(full) + ", which filter " +
                                quote_name(existing->second.writer) + " also writes (at " +
                                sink_.at(existing->second.site) + ")");
      } else {
        existing->second.writer = f.config.name;
      }
    }
  }

  /// The first event parameter is the onset, the second the completion (as the monitor reads
  /// them); absent ones take their defaults.
  void check_filter_events(const FilterItem& f, const std::string& ctx, const FilterManifest& manifest,
                           const Params& given, const std::map<std::string, const ParamItem*, std::less<>>& items) {
    std::vector<const ParamSpec*> event_params;
    for (const ParamSpec& p : manifest.params) {
      if (p.type == ParamType::Event) event_params.push_back(&p);
    }
    std::string onset, completion;
    Site onset_site, completion_site;
    bool onset_named = false;
    for (std::size_t k = 0; k < event_params.size() && k < 2; ++k) {
      const ParamSpec& spec = *event_params[k];
      const std::string* name = nullptr;
      Site site = f.argument_site;
      if (const auto it = given.find(spec.name); it != given.end()) {
        name = std::get_if<std::string>(&it->second);
        site = items.at(spec.name)->value_site;
      } else if (std::any_of(f.params.begin(), f.params.end(),
                             [&](const ParamItem& p) { return p.name == spec.name; })) {
        continue;  // given but wrong: reported
      } else if (spec.default_value) {
        name = std::get_if<std::string>(&*spec.default_value);
      }
      if (name == nullptr) continue;
      if (k == 0) onset_named = true;
      const bool want_onset = k == 0;
      const std::string what = ctx + ": parameter " + quote_name(spec.name);
      const auto e = events_.find(*name);
      if (e == events_.end()) {
        sink_.error(site, what + ": no event " + quote_name(*name) + did_you_mean(*name, event_names()));
        continue;
      }
      e->second.generated = true;
      if (e->second.kind_known && e->second.onset != want_onset) {
        sink_.error(site, what + ": event " + quote_name(*name) + " is " +
                              (want_onset ? "a completion; an onset is needed" : "an onset; a completion is needed"));
        continue;
      }
      (want_onset ? onset : completion) = *name;
      (want_onset ? onset_site : completion_site) = site;
    }
    if (!completion.empty() && !onset_named) {
      sink_.error(completion_site, ctx + ": parameter " + quote_name(event_params[1]->name) +
                                       " gives a completion but no onset (" + quote_name(event_params[0]->name) + ")");
    }
    if (!onset.empty() && !completion.empty()) {
      const EventInfo& c = events_.at(completion);
      if (c.kind_known && c.completes != onset) {
        sink_.error(completion_site,
                    ctx + ": completion " + quote_name(completion) + " does not complete onset " + quote_name(onset) +
                        (c.completes.empty() ? "" : " (it completes " + quote_name(c.completes) + ")"));
      }
    }
  }

  static bool has_input_given(const FilterItem& f, const FilterManifest& manifest) {
    return std::any_of(manifest.inputs.begin(), manifest.inputs.end(), [&](const std::string& n) {
      return std::any_of(f.params.begin(), f.params.end(), [&](const ParamItem& p) { return p.name == n; });
    });
  }

  /// Parameters of the original format that have another name now.
  static std::string_view renamed_parameter(std::string_view name) {
    static const std::pair<std::string_view, std::string_view> kRenamed[] = {
        {"margin", "tolerance"},     {"InputSignalName", "input_signal"}, {"output0", "output_below"},
        {"output1", "output_above"}, {"input", "input_signal"},           {"output", "output_signal"}};
    for (const auto& [old_name, now] : kRenamed) {
      if (old_name == name) return now;
    }
    return {};
  }

  /// Events named by any parameter of a filter whose type is unknown count as generated.
  void mark_named_events(const FilterItem& f) {
    for (const ParamItem& p : f.params) {
      if (p.value == nullptr) continue;
      const auto mark = [&](const json::JsonValue& v) {
        if (!v.is_string()) return;
        if (const auto e = events_.find(v.string); e != events_.end()) e->second.generated = true;
      };
      mark(*p.value);
      for (const json::JsonValue& item : p.value->array) mark(item);
    }
  }

  /// Numeric parameters: "finite", "a whole number", "at least 0"... or "" when fine.
  static std::string number_problem(const ParamSpec& spec, const ParamValue& value) {
    if (spec.type != ParamType::Number && spec.type != ParamType::Integer) return {};
    const double* d = std::get_if<double>(&value);
    if (d == nullptr) return {};
    if (spec.type == ParamType::Integer && std::floor(*d) != *d) return "a whole number, not " + number_text(*d);
    const bool low = spec.min > -1e300;
    const bool high = spec.max < 1e300;
    if ((low && *d < spec.min) || (high && *d > spec.max)) {
      if (low && high)
        return "within " + number_text(spec.min) + "-" + number_text(spec.max) + ", not " + number_text(*d);
      if (low) return "at least " + number_text(spec.min) + ", not " + number_text(*d);
      return "at most " + number_text(spec.max) + ", not " + number_text(*d);
    }
    return {};
  }

  /// Resolves an input signal; returns its size, or 0 when it cannot be used.
  std::size_t resolve_input(const std::string& ctx, const std::string& param, const std::string& name, const Site& site,
                            const std::string& tc, const std::string& coordinator, bool from_template) {
    const std::string full = qualify(name, tc);
    const auto dot = full.find('.');
    const std::string what = ctx + ": parameter " + quote_name(param);
    if (dot == 0 || dot + 1 == full.size()) {
      sink_.error(site, what + ": " + quote_name(name) +
                            " is not a signal name (Component.signal, or a bare name for the target component)");
      return 0;
    }
    const std::string comp = full.substr(0, dot);
    ComponentItem* owner = nullptr;
    if (const auto it = components_.find(comp); it != components_.end()) owner = &m_.components[it->second];
    if (owner == nullptr) {
      sink_.error(site, what + ": no component " + quote_name(comp) + " for signal " + quote_name(full) +
                            did_you_mean(comp, component_names()));
      return 0;
    }
    check_same_coordinator(ctx, param, full, comp, coordinator, site);
    const auto it = signals_.find(full);
    if (it != signals_.end()) return it->second.size;
    if (from_template && comp == tc) {
      // A framework filter template reads signals the framework gives every component (the 2016
      // ExceptionCount): the component has it, a scalar, whether or not it declares signals.
      owner->signals.push_back(SignalItem{full, 1, site, true});
      signals_.emplace(full, SignalInfo{1, {}, site});
      return 1;
    }
    if (!owner->has_signals) {
      // 2016 files declare no signals: an input names one of the component's signals.
      sink_.warning(site, "signal " + quote_name(full) + " is not declared; assumed to be a scalar (component " +
                              quote_name(comp) + " has no \"signals\" list, as in 2016 files)");
      owner->signals.push_back(SignalItem{full, 1, site, true});
      signals_.emplace(full, SignalInfo{1, {}, site});
      return 1;
    }
    std::vector<std::string> known;
    for (const auto& [n, info] : signals_) known.push_back(n);
    sink_.error(site, what + ": signal " + quote_name(full) + " is not declared and no earlier filter writes it" +
                          did_you_mean(full, known));
    return 0;
  }

  void check_same_coordinator(const std::string& ctx, const std::string& param, const std::string& signal,
                              const std::string& comp, const std::string& coordinator, const Site& site) {
    if (!m_.has_coordinators) return;
    const std::string other = coordinator_of(comp);
    if (!coordinator.empty() && !other.empty() && other != coordinator) {
      sink_.error(site, ctx + ": parameter " + quote_name(param) + ": signal " + quote_name(signal) +
                            " belongs to coordinator " + quote_name(other) + ", but the filter runs in " +
                            quote_name(coordinator) + " (with its target): signals do not cross coordinators");
    }
  }

  // ---- what can happen -------------------------------------------------------------------------
  void check_event_use() {
    // An onset is generated when a filter generates it or its completion, and the other way round.
    for (bool changed = true; changed;) {
      changed = false;
      for (auto& [name, info] : events_) {
        if (!info.generated || !info.kind_known) continue;
        const std::vector<std::string> related =
            info.onset ? info.completions : std::vector<std::string>{info.completes};
        for (const std::string& r : related) {
          const auto it = events_.find(r);
          if (it != events_.end() && !it->second.generated) {
            it->second.generated = true;
            changed = true;
          }
        }
      }
    }
    for (const ComponentItem& c : m_.components) {
      for (const EventItem& e : c.events) {
        const auto it = events_.find(e.def.name);
        if (!e.has_name || it == events_.end() || it->second.item != &e) continue;
        const EventInfo& info = it->second;
        if (!info.kind_known || !info.onset || info.generated) continue;
        if (info.severity >= kMinBroadcastSeverity) continue;  // broadcasts come from tools
        sink_.warning(e.name_site,
                      "event " + quote_name(e.def.name) +
                          " is not generated by any filter (only the application or a tool can generate it)");
      }
    }
  }

  void check_unconnected() {
    // A wrong connection usually meant to connect one of them: fix the connections first.
    if (!m_.system_file || connection_errors_) return;
    for (const auto& [name, index] : components_) {
      const ComponentItem& c = m_.components[index];
      for (const Name& r : c.required) {
        if (!simple_name(r.text) || connected_.count(c.name + "." + r.text) > 0) continue;
        sink_.warning(r.site, "required interface " + c.name + "." + r.text +
                                  " is not connected: errors of the service it uses cannot reach it");
      }
    }
  }

  // ---- hazards and invariants ------------------------------------------------------------------
  /// Why `address` names nothing ("" when it names a state): SYSTEM, C, C.s_F, C.s_A, C.s_P.p,
  /// C.s_R.r, C.s_S.p.
  std::string address_problem(const std::string& address) const {
    if (address == "SYSTEM") return {};
    const auto dot = address.find('.');
    const std::string comp = address.substr(0, dot);
    const ComponentItem* c = component(comp);
    if (c == nullptr) return "no component " + quote_name(comp) + did_you_mean(comp, component_names());
    if (dot == std::string::npos) return {};
    const std::string rest = address.substr(dot + 1);
    if (rest == "s_F" || rest == "s_A") return {};
    const auto dot2 = rest.find('.');
    const std::string kind = rest.substr(0, dot2);
    if (dot2 == std::string::npos || (kind != "s_P" && kind != "s_R" && kind != "s_S")) {
      return "expected C, C.s_F, C.s_A, C.s_P.p, C.s_R.r, C.s_S.p or SYSTEM";
    }
    const std::string iface = rest.substr(dot2 + 1);
    const std::vector<Name>& list = kind == "s_R" ? c->required : c->provided;
    if (contains(list, iface)) return {};
    return "component " + quote_name(comp) + " has no " + (kind == "s_R" ? "required" : "provided") + " interface " +
           quote_name(iface) + did_you_mean(iface, names_of(list));
  }

  void check_hazards() {
    std::map<std::string, Site, std::less<>> ids;
    std::vector<std::string> id_list;
    for (const HazardItem& h : m_.hazards) {
      if (!h.has_id) continue;  // reported as a missing key
      if (!token_name(h.id)) {
        sink_.error(h.id_site, "hazard id " + quote_name(h.id) + " must be non-empty, without spaces");
        continue;
      }
      const auto [it, fresh] = ids.emplace(h.id, h.id_site);
      if (!fresh) {
        sink_.error(h.id_site, "duplicate hazard " + quote_name(h.id) + " (first at " + sink_.at(it->second) + ")");
        continue;
      }
      id_list.push_back(h.id);
      const std::string ctx = "hazard " + quote_name(h.id);
      for (const HazardItem::Reaction& r : h.reaction) {
        if (const std::string problem = address_problem(r.address); !problem.empty()) {
          sink_.error(r.key_site,
                      ctx + ": reaction names address " + quote_name(r.address) + ", which does not exist: " + problem);
        }
        const auto level = parse_state(r.level);
        if (!level) {
          sink_.error(r.value_site, ctx + ": reaction of " + quote_name(r.address) +
                                        " must be \"Warning\" or \"Error\", not " + quote_name(r.level) +
                                        did_you_mean(r.level, {"Warning", "Error"}));
        } else if (*level == State::Normal) {
          sink_.error(r.value_site, ctx + ": reaction of " + quote_name(r.address) +
                                        " is Normal, which every state satisfies: say \"Warning\" or \"Error\"");
        }
      }
    }
    // Events name hazards. Without a "hazards" section the ids are free text (as in 2016 files).
    std::set<std::string, std::less<>> linked;
    for (const ComponentItem& c : m_.components) {
      for (const EventItem& e : c.events) {
        if (e.def.hazard.empty()) continue;
        const auto info = events_.find(e.def.name);
        const bool onset = info == events_.end() || !info->second.kind_known || info->second.onset;
        if (onset) linked.insert(e.def.hazard);
        if (m_.has_hazards && ids.count(e.def.hazard) == 0) {
          sink_.error(e.hazard_site, "event " + quote_name(e.def.name) + " names hazard " + quote_name(e.def.hazard) +
                                         ", which the system's \"hazards\" does not declare" +
                                         did_you_mean(e.def.hazard, id_list));
        }
      }
    }
    for (const HazardItem& h : m_.hazards) {
      if (!h.has_id || linked.count(h.id) > 0) continue;
      if (const auto it = ids.find(h.id);
          it == ids.end() || it->second.position.line != h.id_site.position.line || it->second.file != h.id_site.file) {
        continue;  // an invalid or duplicate id: reported
      }
      sink_.warning(h.id_site,
                    "hazard " + quote_name(h.id) +
                        " has no linked event: no onset names it in its \"hazard\" field, so nothing detects it");
    }
  }

  /// Each rate or probability names a failure mode of the system (docs/analyze.md), and gives
  /// exactly one of the two.
  void check_reliability() {
    if (!m_.reliability) return;
    for (const ReliabilityItem::Mode& mode : m_.reliability->modes) {
      if (mode.given != 1) {
        sink_.error(mode.value_site, "reliability of " + quote_name(mode.name) +
                                         ": give exactly one of \"rate\" (per hour) and \"probability\"");
      }
      if (const std::string problem = mode_problem(mode.name); !problem.empty())
        sink_.error(mode.key_site, "reliability: " + quote_name(mode.name) + " is not a failure mode: " + problem);
    }
  }

  /// Why `name` names no failure mode ("" when it does).
  std::string mode_problem(const std::string& name) const {
    const auto colon = name.find(':');
    if (colon != std::string::npos) {
      const std::string kind = name.substr(0, colon), what = name.substr(colon + 1);
      if (kind == "lost") {
        if (!m_.has_coordinators) return "the system declares no \"coordinators\": no process to lose";
        if (what == "supervisor") return {};
        std::vector<std::string> names{"supervisor"};
        for (const CoordinatorItem& c : m_.coordinators) names.push_back(c.name.text);
        return contains_text(names, what) ? "" : "no coordinator " + quote_name(what) + did_you_mean(what, names);
      }
      if (kind == "stale") {
        std::vector<std::string> signals;
        for (const ComponentItem& c : m_.components) {
          for (const SignalItem& sig : c.signals) signals.push_back(sig.name);
        }
        return contains_text(signals, what) ? "" : "no signal " + quote_name(what) + did_you_mean(what, signals);
      }
      if (kind == "fault") {
        std::vector<std::string> filters;
        for (const ComponentItem& c : m_.components) {
          for (const FilterEntryItem& f : c.filters) {
            for (const FilterItem& stage : f.stages) filters.push_back(stage.config.name);
          }
        }
        return contains_text(filters, what) ? "" : "no filter " + quote_name(what) + did_you_mean(what, filters);
      }
      return "expected EVT, EVT@C.s_A, C.s_F, C.s_A, stale:C.signal, fault:filter, lost:coordinator or lost:supervisor";
    }
    const auto at = name.find('@');
    const std::string event = name.substr(0, at);
    const auto info = events_.find(event);
    if (info == events_.end()) {
      if (at != std::string::npos || name.find('.') == std::string::npos) return "no event " + quote_name(event);
      if (!name.ends_with(".s_F") && !name.ends_with(".s_A"))
        return "a machine failure is C.s_F or C.s_A, not " + quote_name(name);
      return address_problem(name);
    }
    if (info->second.kind_known && !info->second.onset) return quote_name(event) + " is a completion, not an onset";
    if (at == std::string::npos) return {};
    const std::string machine = name.substr(at + 1);
    if (machine == "every s_A") return {};
    if (const std::string problem = address_problem(machine); !problem.empty()) return problem;
    const auto dots = std::count(machine.begin(), machine.end(), '.');
    if (dots == 0 || machine.find(".s_S.") != std::string::npos) return quote_name(machine) + " is not a state machine";
    return {};
  }

  static bool contains_text(const std::vector<std::string>& list, const std::string& s) {
    return std::find(list.begin(), list.end(), s) != list.end();
  }

  void check_invariants() {
    std::map<std::string, Site, std::less<>> names;
    for (const InvariantItem& inv : m_.invariants) {
      if (inv.has_name) {
        if (!token_name(inv.name)) {
          sink_.error(inv.name_site, "invariant name " + quote_name(inv.name) + " must be non-empty, without spaces");
        } else if (const auto [it, fresh] = names.emplace(inv.name, inv.name_site); !fresh) {
          sink_.error(inv.name_site,
                      "duplicate invariant " + quote_name(inv.name) + " (first at " + sink_.at(it->second) + ")");
        }
      }
      if (!inv.has_formula) continue;
      const std::string ctx = "invariant " + quote_name(inv.name);
      // A position inside the string: one column for the opening quote, then the offset (exact
      // for formulas without escapes, which the grammar does not need).
      const auto inside = [&](std::size_t offset) {
        Site s = inv.formula_site;
        s.position.column += 1 + static_cast<int>(offset);
        return s;
      };
      auto parsed = parse_formula(inv.formula);
      if (!parsed) {
        sink_.error(inside(parsed.error().offset), ctx + ": " + parsed.error().message);
        continue;
      }
      std::vector<const Formula*> atoms;
      parsed->atoms(atoms);
      for (const Formula* a : atoms) {
        if (const std::string problem = address_problem(a->address); !problem.empty()) {
          sink_.error(inside(a->offset), ctx + ": address " + quote_name(a->address) + " does not exist: " + problem);
        }
      }
    }
  }

  Model& m_;
  const FilterRegistry& registry_;
  Sink& sink_;
  std::map<std::string, std::size_t, std::less<>> components_;
  std::map<std::string, EventInfo, std::less<>> events_;
  std::map<std::string, SignalInfo, std::less<>> signals_;
  std::map<std::string, Site, std::less<>> filters_;
  std::map<std::string, Site, std::less<>> pipelines_;
  std::map<std::string, const ConnectionItem*, std::less<>> connected_;
  std::map<std::string, std::string> coordinator_of_;
  std::set<std::string, std::less<>> invalid_components_;
  bool connection_errors_ = false;
};

}  // namespace

void validate(Model& model, const FilterRegistry& registry, Sink& sink) { Validator(model, registry, sink).run(); }

}  // namespace safecass::spec
