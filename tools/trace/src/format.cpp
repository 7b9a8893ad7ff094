// The trace as text, JSON and CSV. One formatter per format; every format shows the same facts.

#include <string>

#include "safecass/spec/json.hpp"
#include "safecass/trace/trace.hpp"

namespace safecass::trace {

namespace {

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k) out += (k == 0 ? "" : sep) + items[k];
  return out;
}

std::string where_text(const spec::Position& p) {
  if (p.file.empty()) return {};
  if (p.line == 0) return p.file;
  return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

std::string uses_text(const std::vector<ScenarioUse>& uses) {
  std::vector<std::string> out;
  for (const ScenarioUse& u : uses)
    out.push_back(u.scenario + (u.transitions.empty() ? "" : " (" + join(u.transitions, " ") + ")"));
  return join(out, "; ");
}

std::string filter_text(const FilterLink& f) {
  std::string out = f.name + " [" + f.type + ", " + f.execution + ", every " + f.period + "] on " + f.target;
  if (!f.signals.empty()) out += ", reads " + f.signals;
  if (!f.threshold.empty()) out += ", threshold " + f.threshold;
  if (!f.parameters.empty()) out += ", " + join(f.parameters, ", ");
  if (!f.pipeline.empty()) out += ", pipeline " + f.pipeline + ": " + join(f.chain, " -> ");
  return out;
}

std::string q(std::string_view s) { return spec::json_quote(s); }

std::string json_strings(const std::vector<std::string>& items) {
  std::string out = "[";
  for (std::size_t k = 0; k < items.size(); ++k) out += (k == 0 ? "" : ",") + q(items[k]);
  return out + "]";
}

std::string json_where(const spec::Position& p) {
  return "{\"file\":" + q(p.file) + ",\"line\":" + std::to_string(p.line) + ",\"column\":" + std::to_string(p.column) +
         "}";
}

std::string json_filter(const FilterLink& f) {
  return "{\"name\":" + q(f.name) + ",\"pipeline\":" + q(f.pipeline) + ",\"chain\":" + json_strings(f.chain) +
         ",\"class\":" + q(f.type) + ",\"component\":" + q(f.component) + ",\"target\":" + q(f.target) +
         ",\"signals\":" + q(f.signals) + ",\"threshold\":" + q(f.threshold) +
         ",\"parameters\":" + json_strings(f.parameters) + ",\"execution\":" + q(f.execution) +
         ",\"period\":" + q(f.period) + ",\"role\":" + q(f.role) + ",\"where\":" + json_where(f.where) + "}";
}

std::string json_event(const EventLink& e) {
  std::string out = "{\"name\":" + q(e.name) + ",\"component\":" + q(e.component) +
                    ",\"role\":" + q(e.onset ? "onset" : "completion") + ",\"severity\":" + std::to_string(e.severity) +
                    ",\"level\":" + q(e.level) + ",\"transitions\":" + q(e.transitions) +
                    ",\"targets\":" + json_strings(e.targets) + ",\"latched\":" + (e.latched ? "true" : "false") +
                    ",\"completion\":" + q(e.completion) + ",\"filters\":[";
  for (std::size_t k = 0; k < e.filters.size(); ++k) out += (k == 0 ? "" : ",") + json_filter(e.filters[k]);
  out += "],\"fired_by\":[";
  for (std::size_t k = 0; k < e.fired_by.size(); ++k) {
    out += std::string(k == 0 ? "" : ",") + "{\"scenario\":" + q(e.fired_by[k].scenario) +
           ",\"transitions\":" + json_strings(e.fired_by[k].transitions) + "}";
  }
  out += "],\"cleared_by\":" + json_strings(e.cleared_by) + ",\"where\":" + json_where(e.where) + "}";
  return out;
}

/// RFC 4180: a field with a comma, a quote, CR or LF is quoted, its quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    out += c;
    if (c == '"') out += '"';
  }
  return out + "\"";
}

std::string gaps_of(const Trace& t, const std::string& hazard, const std::string& event, const std::string& filter) {
  std::vector<std::string> out;
  for (const Gap& g : t.gaps) {
    const bool mine =
        (!hazard.empty() && g.hazard == hazard &&
         (g.subject == hazard || g.subject == event || (event.empty() && g.kind == "reaction-unchecked"))) ||
        (hazard.empty() && !filter.empty() && g.subject == filter);
    if (mine) out.push_back(std::string(to_string(g.severity)) + " " + g.kind + ": " + g.subject);
  }
  return join(out, "; ");
}

}  // namespace

std::string trace_text(const Trace& t) {
  std::string out = "Hazard trace of " + t.system + " (" + t.system_path + ")\n";
  for (const HazardTrace& h : t.hazards) {
    out += "\n" + h.id + ": " + h.description + "\n";
    std::vector<std::string> reaction;
    for (const ReactionLink& r : h.reaction) {
      reaction.push_back(
          r.address + " >= " + r.level +
          (r.checked_by.empty() ? " (checked by no scenario)" : " (checked by " + join(r.checked_by, ", ") + ")"));
    }
    out += "  reaction: " + (reaction.empty() ? std::string("none") : join(reaction, "; ")) + "\n";
    out += "  verify: " + std::string(to_string(h.verified)) +
           (h.verify_detail.empty() ? "" : " (" + h.verify_detail + ")") + "\n";
    if (h.events.empty()) out += "  no linked event\n";
    for (const EventLink& e : h.events) {
      out += "  " + std::string(e.onset ? "onset " : "completion ") + e.name + " (" + e.component + ", severity " +
             std::to_string(e.severity) + (e.onset ? ", " + e.level + ", " + e.transitions : ", " + e.transitions) +
             (e.latched ? ", latched" : "") + ") -> " + join(e.targets, ", ") + "\n";
      for (const FilterLink& f : e.filters) out += "    filter " + filter_text(f) + "\n";
      if (e.filters.empty()) out += "    no filter generates it\n";
      out += "    fired by: " + (e.fired_by.empty() ? std::string("no scenario") : uses_text(e.fired_by)) + "\n";
      if (e.onset)
        out +=
            "    cleared by: " + (e.cleared_by.empty() ? std::string("no scenario") : join(e.cleared_by, ", ")) + "\n";
    }
  }
  if (!t.unlinked.empty()) {
    out += "\nOnsets generated by filters and linked to no hazard\n";
    for (const EventLink& e : t.unlinked) {
      out += "  " + e.name + " (" + e.component + ", severity " + std::to_string(e.severity) + ")\n";
      for (const FilterLink& f : e.filters) out += "    filter " + filter_text(f) + "\n";
    }
  }
  out += "\nScenarios\n";
  for (const ScenarioResult& s : t.scenarios) {
    out += "  " + std::string(s.passed ? "PASS " : "FAIL ") + s.path + " (" + std::to_string(s.checks) + " checks)\n";
  }
  out += "\nGaps (" + std::to_string(t.gaps.size()) + ")\n";
  for (const Gap& g : t.gaps) {
    const std::string at = where_text(g.where);
    out += "  " + (at.empty() ? std::string() : at + ": ") + std::string(to_string(g.severity)) + ": " + g.message +
           " [" + g.kind + "]\n";
  }
  const Coverage& c = t.coverage;
  out += "\nCoverage: hazards " + std::to_string(c.hazards_detected) + "/" + std::to_string(c.hazards) + " detected, " +
         std::to_string(c.hazards_exercised) + "/" + std::to_string(c.hazards) + " exercised; reactions " +
         std::to_string(c.reactions_checked) + "/" + std::to_string(c.reactions) + " checked; events " +
         std::to_string(c.events_fired) + "/" + std::to_string(c.events_defined) + " fired; transitions " +
         std::to_string(c.transitions_taken) + "/" + std::to_string(c.transitions_defined) + " taken\n";
  return out;
}

std::string trace_json(const Trace& t) {
  std::string out = "{\"system\":" + q(t.system) + ",\"path\":" + q(t.system_path) +
                    ",\"version\":" + q(tool_version()) + ",\"files\":[";
  for (std::size_t k = 0; k < t.files.size(); ++k) {
    out += std::string(k == 0 ? "" : ",") + "{\"path\":" + q(t.files[k].path) + ",\"sha256\":" + q(t.files[k].sha256) +
           "}";
  }
  out += "],\"hazards\":[";
  for (std::size_t k = 0; k < t.hazards.size(); ++k) {
    const HazardTrace& h = t.hazards[k];
    out += std::string(k == 0 ? "" : ",") + "{\"id\":" + q(h.id) + ",\"description\":" + q(h.description) +
           ",\"events\":[";
    for (std::size_t e = 0; e < h.events.size(); ++e) out += (e == 0 ? "" : ",") + json_event(h.events[e]);
    out += "],\"reaction\":[";
    for (std::size_t r = 0; r < h.reaction.size(); ++r) {
      out += std::string(r == 0 ? "" : ",") + "{\"address\":" + q(h.reaction[r].address) +
             ",\"level\":" + q(h.reaction[r].level) + ",\"checked_by\":" + json_strings(h.reaction[r].checked_by) +
             ",\"where\":" + json_where(h.reaction[r].where) + "}";
    }
    out += "],\"verify\":" + q(to_string(h.verified)) + ",\"verify_detail\":" + q(h.verify_detail) +
           ",\"excerpt\":{\"scenario\":" + q(h.excerpt_scenario) +
           ",\"components\":" + json_strings(h.excerpt_components) + "}" + ",\"where\":" + json_where(h.where) + "}";
  }
  out += "],\"unlinked\":[";
  for (std::size_t k = 0; k < t.unlinked.size(); ++k) out += (k == 0 ? "" : ",") + json_event(t.unlinked[k]);
  out += "],\"scenarios\":[";
  for (std::size_t k = 0; k < t.scenarios.size(); ++k) {
    const ScenarioResult& s = t.scenarios[k];
    out += std::string(k == 0 ? "" : ",") + "{\"path\":" + q(s.path) + ",\"passed\":" + (s.passed ? "true" : "false") +
           ",\"checks\":" + std::to_string(s.checks) + ",\"failures\":" + json_strings(s.failures) + "}";
  }
  out += "],\"gaps\":[";
  for (std::size_t k = 0; k < t.gaps.size(); ++k) {
    const Gap& g = t.gaps[k];
    out += std::string(k == 0 ? "" : ",") + "{\"severity\":" + q(to_string(g.severity)) + ",\"kind\":" + q(g.kind) +
           ",\"hazard\":" + q(g.hazard) + ",\"subject\":" + q(g.subject) + ",\"message\":" + q(g.message) +
           ",\"where\":" + json_where(g.where) + "}";
  }
  const Coverage& c = t.coverage;
  out += "],\"coverage\":{\"hazards\":" + std::to_string(c.hazards) +
         ",\"hazards_detected\":" + std::to_string(c.hazards_detected) +
         ",\"hazards_exercised\":" + std::to_string(c.hazards_exercised) +
         ",\"reactions\":" + std::to_string(c.reactions) +
         ",\"reactions_checked\":" + std::to_string(c.reactions_checked) +
         ",\"events_defined\":" + std::to_string(c.events_defined) +
         ",\"events_fired\":" + std::to_string(c.events_fired) +
         ",\"transitions_defined\":" + std::to_string(c.transitions_defined) +
         ",\"transitions_taken\":" + std::to_string(c.transitions_taken) + "},\"verify_source\":" + q(t.verify_source) +
         ",\"error_gaps\":" + (t.has_error_gap() ? "true" : "false") + "}\n";
  return out;
}

std::string trace_csv(const Trace& t) {
  static const char* const kHeader[] = {"hazard",      "hazard_description",
                                        "reaction",    "reaction_checked_by",
                                        "verify",      "event",
                                        "role",        "component",
                                        "severity",    "level",
                                        "transitions", "targets",
                                        "latched",     "filter",
                                        "pipeline",    "class",
                                        "signals",     "threshold",
                                        "parameters",  "execution",
                                        "period",      "fired_by",
                                        "cleared_by",  "gaps"};
  std::string out;
  for (std::size_t k = 0; k < std::size(kHeader); ++k) out += std::string(k == 0 ? "" : ",") + kHeader[k];
  out += "\r\n";
  const auto row = [&](const std::vector<std::string>& fields) {
    for (std::size_t k = 0; k < fields.size(); ++k) out += (k == 0 ? "" : ",") + csv_field(fields[k]);
    out += "\r\n";
  };
  const auto rows_of = [&](const HazardTrace* h, const EventLink* e) {
    std::vector<std::string> head;
    if (h != nullptr) {
      std::vector<std::string> reaction, checked;
      for (const ReactionLink& r : h->reaction) {
        reaction.push_back(r.address + ">=" + r.level);
        checked.push_back(r.address + ": " + (r.checked_by.empty() ? std::string("none") : join(r.checked_by, " ")));
      }
      head = {h->id, h->description, join(reaction, "; "), join(checked, "; "), std::string(to_string(h->verified))};
    } else {
      head = {"", "", "", "", ""};
    }
    if (e == nullptr) {
      std::vector<std::string> fields = head;
      fields.resize(std::size(kHeader));
      fields.back() = gaps_of(t, h != nullptr ? h->id : "", "", "");
      row(fields);
      return;
    }
    const std::vector<std::string> event = {e->name,
                                            e->onset ? "onset" : "completion",
                                            e->component,
                                            std::to_string(e->severity),
                                            e->level,
                                            e->transitions,
                                            join(e->targets, "; "),
                                            e->latched ? "yes" : "no"};
    const auto emit = [&](const FilterLink* f) {
      std::vector<std::string> fields = head;
      fields.insert(fields.end(), event.begin(), event.end());
      if (f != nullptr) {
        fields.insert(fields.end(),
                      {f->name, f->pipeline.empty() ? "" : f->pipeline + ": " + join(f->chain, " -> "), f->type,
                       f->signals, f->threshold, join(f->parameters, " "), f->execution, f->period});
      } else {
        fields.insert(fields.end(), 8, "");
      }
      fields.push_back(uses_text(e->fired_by));
      fields.push_back(join(e->cleared_by, "; "));
      fields.push_back(gaps_of(t, h != nullptr ? h->id : "", e->name, f != nullptr ? f->name : ""));
      row(fields);
    };
    if (e->filters.empty()) emit(nullptr);
    for (const FilterLink& f : e->filters) emit(&f);
  };
  for (const HazardTrace& h : t.hazards) {
    if (h.events.empty()) rows_of(&h, nullptr);
    for (const EventLink& e : h.events) rows_of(&h, &e);
  }
  for (const EventLink& e : t.unlinked) rows_of(nullptr, &e);
  return out;
}

}  // namespace safecass::trace
