// The trace as text, JSON and CSV. One formatter per format; every format shows the same facts.

#include <string>

#include "safecass/introspect/format.hpp"
#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"
#include "safecass/trace/trace.hpp"

namespace safecass::trace {

namespace {

std::string where_text(const spec::Position& p) {
  if (p.file.empty()) return {};
  if (p.line == 0) return p.file;
  return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

std::string uses_text(const std::vector<ScenarioUse>& uses) {
  std::vector<std::string> out;
  for (const ScenarioUse& u : uses)
    out.push_back(u.scenario + (u.transitions.empty() ? "" : " (" + introspect::joined(u.transitions, " ") + ")"));
  return introspect::joined(out, "; ");
}

std::string filter_text(const FilterLink& f) {
  std::string out = f.name + " [" + f.type + ", " + f.execution + ", every " + f.period + "] on " + f.target;
  if (!f.signals.empty()) out += ", reads " + f.signals;
  if (!f.threshold.empty()) out += ", threshold " + f.threshold;
  if (!f.parameters.empty()) out += ", " + introspect::joined(f.parameters, ", ");
  if (!f.pipeline.empty()) out += ", pipeline " + f.pipeline + ": " + introspect::joined(f.chain, " -> ");
  return out;
}

using json::JsonArray;
using json::JsonObject;

std::string json_where(const spec::Position& p) {
  return JsonObject()
      .str("file", p.file)
      .integer("line", static_cast<long long>(p.line))
      .integer("column", static_cast<long long>(p.column))
      .text();
}

std::string json_filter(const FilterLink& f) {
  return JsonObject()
      .str("name", f.name)
      .str("pipeline", f.pipeline)
      .strings("chain", f.chain)
      .str("class", f.type)
      .str("component", f.component)
      .str("target", f.target)
      .str("signals", f.signals)
      .str("threshold", f.threshold)
      .strings("parameters", f.parameters)
      .str("execution", f.execution)
      .str("period", f.period)
      .str("role", f.role)
      .raw("where", json_where(f.where))
      .text();
}

std::string json_event(const EventLink& e) {
  JsonArray filters;
  for (const FilterLink& f : e.filters) filters.raw(json_filter(f));
  JsonArray fired_by;
  for (const ScenarioUse& u : e.fired_by) {
    fired_by.raw(JsonObject().str("scenario", u.scenario).strings("transitions", u.transitions).text());
  }
  return JsonObject()
      .str("name", e.name)
      .str("component", e.component)
      .str("role", e.onset ? "onset" : "completion")
      .integer("severity", e.severity)
      .str("level", e.level)
      .str("transitions", e.transitions)
      .strings("targets", e.targets)
      .boolean("latched", e.latched)
      .str("completion", e.completion)
      .raw("filters", filters.text())
      .raw("fired_by", fired_by.text())
      .strings("cleared_by", e.cleared_by)
      .raw("where", json_where(e.where))
      .text();
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
  return introspect::joined(out, "; ");
}

}  // namespace

std::string trace_text(const Trace& t) {
  std::string out = "Hazard trace of " + t.system + " (" + t.system_path + ")\n";
  for (const HazardTrace& h : t.hazards) {
    out += "\n" + h.id + ": " + h.description + "\n";
    std::vector<std::string> reaction;
    for (const ReactionLink& r : h.reaction) {
      reaction.push_back(r.address + " >= " + r.level +
                         (r.checked_by.empty() ? " (checked by no scenario)"
                                               : " (checked by " + introspect::joined(r.checked_by, ", ") + ")"));
    }
    out += "  reaction: " + (reaction.empty() ? std::string("none") : introspect::joined(reaction, "; ")) + "\n";
    out += "  verify: " + std::string(to_string(h.verified)) +
           (h.verify_detail.empty() ? "" : " (" + h.verify_detail + ")") + "\n";
    if (h.events.empty()) out += "  no linked event\n";
    for (const EventLink& e : h.events) {
      out += "  " + std::string(e.onset ? "onset " : "completion ") + e.name + " (" + e.component + ", severity " +
             std::to_string(e.severity) + (e.onset ? ", " + e.level + ", " + e.transitions : ", " + e.transitions) +
             (e.latched ? ", latched" : "") + ") -> " + introspect::joined(e.targets, ", ") + "\n";
      for (const FilterLink& f : e.filters) out += "    filter " + filter_text(f) + "\n";
      if (e.filters.empty()) out += "    no filter generates it\n";
      out += "    fired by: " + (e.fired_by.empty() ? std::string("no scenario") : uses_text(e.fired_by)) + "\n";
      if (e.onset)
        out += "    cleared by: " +
               (e.cleared_by.empty() ? std::string("no scenario") : introspect::joined(e.cleared_by, ", ")) + "\n";
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
  JsonArray files;
  for (const SpecFile& f : t.files) files.raw(JsonObject().str("path", f.path).str("sha256", f.sha256).text());
  JsonArray hazards;
  for (const HazardTrace& h : t.hazards) {
    JsonArray events;
    for (const EventLink& e : h.events) events.raw(json_event(e));
    JsonArray reaction;
    for (const ReactionLink& r : h.reaction) {
      reaction.raw(JsonObject()
                       .str("address", r.address)
                       .str("level", r.level)
                       .strings("checked_by", r.checked_by)
                       .raw("where", json_where(r.where))
                       .text());
    }
    hazards.raw(
        JsonObject()
            .str("id", h.id)
            .str("description", h.description)
            .raw("events", events.text())
            .raw("reaction", reaction.text())
            .str("verify", to_string(h.verified))
            .str("verify_detail", h.verify_detail)
            .raw("excerpt",
                 JsonObject().str("scenario", h.excerpt_scenario).strings("components", h.excerpt_components).text())
            .raw("where", json_where(h.where))
            .text());
  }
  JsonArray unlinked;
  for (const EventLink& e : t.unlinked) unlinked.raw(json_event(e));
  JsonArray scenarios;
  for (const ScenarioResult& sc : t.scenarios) {
    scenarios.raw(JsonObject()
                      .str("path", sc.path)
                      .boolean("passed", sc.passed)
                      .integer("checks", static_cast<long long>(sc.checks))
                      .strings("failures", sc.failures)
                      .text());
  }
  JsonArray gaps;
  for (const Gap& g : t.gaps) {
    gaps.raw(JsonObject()
                 .str("severity", to_string(g.severity))
                 .str("kind", g.kind)
                 .str("hazard", g.hazard)
                 .str("subject", g.subject)
                 .str("message", g.message)
                 .raw("where", json_where(g.where))
                 .text());
  }
  const Coverage& c = t.coverage;
  const std::string coverage = JsonObject()
                                   .integer("hazards", static_cast<long long>(c.hazards))
                                   .integer("hazards_detected", static_cast<long long>(c.hazards_detected))
                                   .integer("hazards_exercised", static_cast<long long>(c.hazards_exercised))
                                   .integer("reactions", static_cast<long long>(c.reactions))
                                   .integer("reactions_checked", static_cast<long long>(c.reactions_checked))
                                   .integer("events_defined", static_cast<long long>(c.events_defined))
                                   .integer("events_fired", static_cast<long long>(c.events_fired))
                                   .integer("transitions_defined", static_cast<long long>(c.transitions_defined))
                                   .integer("transitions_taken", static_cast<long long>(c.transitions_taken))
                                   .text();
  return JsonObject()
             .str("system", t.system)
             .str("path", t.system_path)
             .str("version", tool_version())
             .raw("files", files.text())
             .raw("hazards", hazards.text())
             .raw("unlinked", unlinked.text())
             .raw("scenarios", scenarios.text())
             .raw("gaps", gaps.text())
             .raw("coverage", coverage)
             .str("verify_source", t.verify_source)
             .boolean("error_gaps", t.has_error_gap())
             .text() +
         "\n";
}

/// RFC 4180: a field with a comma, a quote, CR or LF is quoted, its quotes doubled.
static std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    out += c;
    if (c == '"') out += '"';
  }
  return out + "\"";
}

std::string csv_row(const std::vector<std::string>& fields) {
  std::string out;
  for (std::size_t k = 0; k < fields.size(); ++k) out += (k == 0 ? "" : ",") + csv_field(fields[k]);
  return out + "\r\n";
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
  std::string out = csv_row(std::vector<std::string>(std::begin(kHeader), std::end(kHeader)));
  const auto row = [&](const std::vector<std::string>& fields) { out += csv_row(fields); };
  const auto rows_of = [&](const HazardTrace* h, const EventLink* e) {
    std::vector<std::string> head;
    if (h != nullptr) {
      std::vector<std::string> reaction, checked;
      for (const ReactionLink& r : h->reaction) {
        reaction.push_back(r.address + ">=" + r.level);
        checked.push_back(r.address + ": " +
                          (r.checked_by.empty() ? std::string("none") : introspect::joined(r.checked_by, " ")));
      }
      head = {h->id, h->description, introspect::joined(reaction, "; "), introspect::joined(checked, "; "),
              std::string(to_string(h->verified))};
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
                                            introspect::joined(e->targets, "; "),
                                            e->latched ? "yes" : "no"};
    const auto emit = [&](const FilterLink* f) {
      std::vector<std::string> fields = head;
      fields.insert(fields.end(), event.begin(), event.end());
      if (f != nullptr) {
        fields.insert(
            fields.end(),
            {f->name, f->pipeline.empty() ? "" : f->pipeline + ": " + introspect::joined(f->chain, " -> "), f->type,
             f->signals, f->threshold, introspect::joined(f->parameters, " "), f->execution, f->period});
      } else {
        fields.insert(fields.end(), 8, "");
      }
      fields.push_back(uses_text(e->fired_by));
      fields.push_back(introspect::joined(e->cleared_by, "; "));
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
