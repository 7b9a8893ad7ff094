// The trace report: one self-contained HTML page (web/trace/, compiled in), printable to PDF.
// The matrix, the gaps and the summary are static HTML written here; the timeline excerpts are
// drawn in the browser by the timeline page's renderer from models built by the timeline's code.

#include <sodium.h>

#include <map>
#include <set>

#include "safecass/introspect/format.hpp"
#include "safecass/timeline/timeline.hpp"
#include "safecass/trace/trace.hpp"
#include "trace_assets.hpp"

#ifndef SAFECASS_VERSION
#define SAFECASS_VERSION "unknown"
#endif

namespace safecass::trace {

namespace {

std::string marker(Severity s, const std::string& kind, const std::string& text) {
  const std::string sev(to_string(s));
  std::string label = sev;
  for (char& c : label) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return "<span class=\"marker-gap " + sev + "\" data-gap=\"" + introspect::markup_text(kind) + "\">" + label + ": " +
         introspect::markup_text(text) + "</span>";
}

/// The gaps about one subject of one hazard ("" hazard: gaps of no hazard).
std::vector<const Gap*> gaps_about(const Trace& t, const std::string& hazard, const std::string& subject) {
  std::vector<const Gap*> out;
  for (const Gap& g : t.gaps) {
    if (g.hazard == hazard && g.subject == subject) out.push_back(&g);
  }
  return out;
}

std::string markers(const std::vector<const Gap*>& gaps) {
  std::string out;
  for (const Gap* g : gaps) {
    std::string short_text = g->kind;
    if (g->kind == "hazard-undetected")
      short_text = "no detecting filter";
    else if (g->kind == "event-not-fired")
      short_text = "no scenario fires it";
    else if (g->kind == "onset-not-cleared")
      short_text = "no scenario clears it";
    else if (g->kind == "reaction-unchecked")
      short_text = "no scenario checks it";
    else if (g->kind == "filter-without-hazard")
      short_text = "linked to no hazard";
    else if (g->kind == "reaction-violated")
      short_text = "violated";
    out += "<br>" + marker(g->severity, g->kind, short_text);
  }
  return out;
}

Severity worst(const std::vector<const Gap*>& gaps, Severity none) {
  Severity s = none;
  for (const Gap* g : gaps) s = std::min(s, g->severity);
  return s;
}

std::string filter_cell(const FilterLink& f) {
  std::string out = "<b>" + introspect::markup_text(f.name) + "</b> <span class=\"small\">(" +
                    introspect::markup_text(f.role) + ")</span><br>" + introspect::markup_text(f.type) + ", " +
                    introspect::markup_text(f.execution) + ", every " + introspect::markup_text(f.period) + "<br>on " +
                    introspect::markup_text(f.target);
  if (!f.signals.empty()) out += "<br>reads " + introspect::markup_text(f.signals);
  if (!f.threshold.empty()) out += "<br>threshold <b>" + introspect::markup_text(f.threshold) + "</b>";
  if (!f.parameters.empty())
    out += "<br><span class=\"small\">" + introspect::markup_text(introspect::joined(f.parameters, ", ")) + "</span>";
  if (!f.pipeline.empty())
    out += "<br><span class=\"small\">pipeline " + introspect::markup_text(f.pipeline) + ": " +
           introspect::markup_text(introspect::joined(f.chain, " → ")) + "</span>";
  return out;
}

std::string event_cell(const EventLink& e) {
  std::string out = "<b>" + introspect::markup_text(e.name) + "</b> <span class=\"small\">(" +
                    (e.onset ? "onset" : "completion") + ")</span><br>" + introspect::markup_text(e.component) +
                    ", severity " + std::to_string(e.severity) + "<br>" + introspect::markup_text(e.transitions);
  if (e.onset) out += " → " + introspect::markup_text(e.level);
  if (e.latched) out += "<br><b>latched</b> (cleared by reset)";
  out += "<br>to " + introspect::markup_text(introspect::joined(e.targets, ", "));
  return out;
}

std::string scenarios_cell(const EventLink& e) {
  if (e.fired_by.empty()) return "<span class=\"bad\">none</span>";
  std::string out = "<ul class=\"plain\">";
  for (const ScenarioUse& u : e.fired_by) {
    out += "<li>" + introspect::markup_text(u.scenario) +
           (u.transitions.empty() ? ""
                                  : " <span class=\"small\">(" +
                                        introspect::markup_text(introspect::joined(u.transitions, " ")) + ")</span>") +
           "</li>";
  }
  out += "</ul>";
  if (e.onset) {
    out +=
        "<span class=\"small\">cleared by: " +
        (e.cleared_by.empty() ? std::string("none") : introspect::markup_text(introspect::joined(e.cleared_by, ", "))) +
        "</span>";
  }
  return out;
}

std::string reaction_cell(const Trace& t, const HazardTrace& h) {
  if (h.reaction.empty()) return "<span class=\"small\">none declared</span>";
  std::string out = "<ul class=\"plain\">";
  for (const ReactionLink& r : h.reaction) {
    out += "<li data-address=\"" + introspect::markup_text(r.address) + "\"><b>" + introspect::markup_text(r.address) +
           "</b> ≥ " + introspect::markup_text(r.level) + "<br><span class=\"small\">" +
           (r.checked_by.empty() ? std::string("checked by no expect")
                                 : "expect in " + introspect::markup_text(introspect::joined(r.checked_by, ", "))) +
           "</span>" + markers(gaps_about(t, h.id, r.address)) + "</li>";
  }
  return out + "</ul>";
}

std::string verify_cell(const HazardTrace& h) {
  const std::string v(to_string(h.verified));
  const char* cls = h.verified == Verdict::Holds ? "ok" : h.verified == Verdict::Violated ? "bad" : "small";
  return "<span class=\"" + std::string(cls) + "\" data-verify=\"" + v + "\">" + introspect::markup_text(v) +
         "</span><br><span class=\"small\">" + introspect::markup_text(h.verify_detail) + "</span>";
}

std::string row_class(Severity s) {
  switch (s) {
    case Severity::Error: return " class=\"gap-error\"";
    case Severity::Warning: return " class=\"gap-warning\"";
    case Severity::Info: return " class=\"gap-info\"";
  }
  return "";
}

constexpr Severity kNoGap = static_cast<Severity>(3);

std::string row_class_or_none(Severity s) { return s == kNoGap ? std::string() : row_class(s); }

std::string matrix(const Trace& t) {
  std::string out =
      "<table id=\"matrix-table\"><thead><tr><th>Hazard</th><th>Reaction (required, checked by)</th><th>Event</th>"
      "<th>Filter</th><th>Scenarios that fire it (transitions)</th><th>Verified</th></tr></thead>\n";
  for (const HazardTrace& h : t.hazards) {
    struct Row {
      const EventLink* event;
      const FilterLink* filter;
    };
    std::vector<Row> rows;
    for (const EventLink& e : h.events) {
      if (e.filters.empty()) rows.push_back({&e, nullptr});
      for (const FilterLink& f : e.filters) rows.push_back({&e, &f});
    }
    if (rows.empty()) rows.push_back({nullptr, nullptr});
    const auto hazard_gaps = gaps_about(t, h.id, h.id);
    out += "<tbody class=\"hazard\" data-hazard=\"" + introspect::markup_text(h.id) + "\">\n";
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Row& r = rows[k];
      std::vector<const Gap*> row_gaps = k == 0 ? hazard_gaps : std::vector<const Gap*>{};
      std::vector<const Gap*> event_gaps;
      if (r.event != nullptr) event_gaps = gaps_about(t, h.id, r.event->name);
      const bool first_of_event = r.event == nullptr || k == 0 || rows[k - 1].event != r.event;
      if (first_of_event) row_gaps.insert(row_gaps.end(), event_gaps.begin(), event_gaps.end());
      out += "<tr data-event=\"" + introspect::markup_text(r.event != nullptr ? r.event->name : "") +
             "\" data-filter=\"" + introspect::markup_text(r.filter != nullptr ? r.filter->name : "") + "\"" +
             row_class_or_none(worst(row_gaps, kNoGap)) + ">";
      if (k == 0) {
        const std::string span = " rowspan=\"" + std::to_string(rows.size()) + "\"";
        out += "<td class=\"hazard-id\"" + span + ">" + introspect::markup_text(h.id) + "<br><span class=\"desc\">" +
               introspect::markup_text(h.description) + "</span>" + markers(hazard_gaps) + "</td>";
        out += "<td" + span + ">" + reaction_cell(t, h) + "</td>";
      }
      if (r.event == nullptr) {
        out += "<td colspan=\"3\"><span class=\"bad\">no linked event</span></td>";
      } else {
        out += "<td>" + event_cell(*r.event) + (first_of_event ? markers(event_gaps) : std::string()) + "</td>";
        out += "<td>" +
               (r.filter != nullptr
                    ? filter_cell(*r.filter)
                    : std::string("<span class=\"small\">no filter: generated by the component's code</span>")) +
               "</td>";
        out += "<td>" + scenarios_cell(*r.event) + "</td>";
      }
      if (k == 0) out += "<td rowspan=\"" + std::to_string(rows.size()) + "\">" + verify_cell(h) + "</td>";
      out += "</tr>\n";
    }
    out += "</tbody>\n";
  }
  if (!t.unlinked.empty()) {
    out += "<tbody class=\"hazard unlinked\" data-hazard=\"\">\n";
    std::size_t rows = 0;
    for (const EventLink& e : t.unlinked) rows += std::max<std::size_t>(1, e.filters.size());
    bool first = true;
    for (const EventLink& e : t.unlinked) {
      for (const FilterLink& f : e.filters) {
        const auto g = gaps_about(t, "", f.name);
        out += "<tr data-event=\"" + introspect::markup_text(e.name) + "\" data-filter=\"" +
               introspect::markup_text(f.name) + "\"" + row_class_or_none(worst(g, kNoGap)) + ">";
        if (first)
          out += "<td class=\"hazard-id\" rowspan=\"" + std::to_string(rows) +
                 "\">no hazard<br><span class=\"desc\">onsets generated by filters and linked to no declared "
                 "hazard</span></td><td rowspan=\"" +
                 std::to_string(rows) + "\"></td>";
        out += "<td>" + event_cell(e) + "</td><td>" + filter_cell(f) + markers(g) + "</td><td>" + scenarios_cell(e) +
               "</td>";
        if (first) out += "<td rowspan=\"" + std::to_string(rows) + "\"></td>";
        out += "</tr>\n";
        first = false;
      }
    }
    out += "</tbody>\n";
  }
  return out + "</table>\n";
}

std::string gap_table(const Trace& t) {
  if (t.gaps.empty()) return "<p id=\"no-gaps\">No gaps.</p>\n";
  std::string out =
      "<table id=\"gap-table\"><thead><tr><th>Severity</th><th>Gap</th><th>Hazard</th><th>About</th><th>What is "
      "missing</th><th>Where</th></tr></thead><tbody>\n";
  for (const Gap& g : t.gaps) {
    std::string where = g.where.file;
    if (g.where.line > 0) where += ":" + std::to_string(g.where.line) + ":" + std::to_string(g.where.column);
    out += "<tr class=\"gap gap-" + std::string(to_string(g.severity)) + "\" data-kind=\"" +
           introspect::markup_text(g.kind) + "\" data-severity=\"" + std::string(to_string(g.severity)) + "\"><td>" +
           marker(g.severity, g.kind, g.kind) + "</td><td>" + introspect::markup_text(g.kind) + "</td><td>" +
           introspect::markup_text(g.hazard) + "</td><td>" + introspect::markup_text(g.subject) + "</td><td>" +
           introspect::markup_text(g.message) + "</td><td>" + introspect::markup_text(where) + "</td></tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string excerpts(const Trace& t) {
  std::map<std::string, std::vector<timeline::HistoryRecord>> drawn;  // by scenario
  std::string out;
  for (const HazardTrace& h : t.hazards) {
    out += "<h3>" + introspect::markup_text(h.id) + " <span class=\"desc\">" + introspect::markup_text(h.description) +
           "</span></h3>\n";
    if (h.excerpt_scenario.empty()) {
      out += "<p class=\"bad\" data-excerpt-missing=\"" + introspect::markup_text(h.id) + "\">No scenario exercises " +
             introspect::markup_text(h.id) + ".</p>\n";
      continue;
    }
    const ScenarioResult* run = nullptr;
    for (const ScenarioResult& s : t.scenarios) {
      if (s.path == h.excerpt_scenario) run = &s;
    }
    if (run == nullptr || run->history.empty()) {
      out += "<p class=\"small\">" + introspect::markup_text(h.id) + " is exercised by " +
             introspect::markup_text(h.excerpt_scenario) + " (no history kept).</p>\n";
      continue;
    }
    auto it = drawn.find(run->path);
    if (it == drawn.end()) it = drawn.emplace(run->path, timeline::records_of(run->history)).first;
    const std::set<std::string> shown(h.excerpt_components.begin(), h.excerpt_components.end());
    std::vector<timeline::HistoryRecord> records;
    for (const timeline::HistoryRecord& r : it->second) {
      const introspect::HistoryEntry& e = r.entry;
      const std::string component = !e.component.empty() ? e.component : e.machine.substr(0, e.machine.find('.'));
      if (r.overflow || shown.count(component) != 0) records.push_back(r);
    }
    out += "<figure class=\"excerpt\" data-hazard=\"" + introspect::markup_text(h.id) + "\" data-scenario=\"" +
           introspect::markup_text(run->path) + "\" data-from=\"" + number_text(h.excerpt_from) + "\" data-to=\"" +
           number_text(h.excerpt_to) + "\">\n<figcaption>" + introspect::markup_text(h.id) + " in " +
           introspect::markup_text(run->path) + ", t = " + number_text(h.excerpt_from) + " s to " +
           number_text(h.excerpt_to) + " s; " +
           introspect::markup_text(introspect::joined(h.excerpt_components, ", ")) +
           "</figcaption>\n<div class=\"excerpt-box\"><svg class=\"timeline-axis\" role=\"img\" aria-label=\"Time axis "
           "in seconds\"></svg>"
           "<svg class=\"timeline-lanes\" role=\"img\" aria-label=\"States during " +
           introspect::markup_text(h.id) +
           "\"></svg></div>\n"
           "<script type=\"application/json\" class=\"excerpt-model\">" +
           timeline::timeline_model_json(records) + "</script>\n</figure>\n";
  }
  return out;
}

std::string coverage_table(const Trace& t) {
  const Coverage& c = t.coverage;
  const auto row = [](const std::string& what, std::size_t n, std::size_t of) {
    return "<tr><td>" + what + "</td><td>" + std::to_string(n) + " of " + std::to_string(of) + "</td></tr>\n";
  };
  std::string out = "<table id=\"coverage-table\"><tbody>\n";
  out += row("hazards detected by a filter", c.hazards_detected, c.hazards);
  out += row("hazards exercised by a scenario", c.hazards_exercised, c.hazards);
  out += row("reaction addresses checked by an expect", c.reactions_checked, c.reactions);
  out += row("events fired", c.events_fired, c.events_defined);
  out += row("defined transitions taken", c.transitions_taken, c.transitions_defined);
  out +=
      "</tbody></table>\n<table "
      "id=\"scenario-table\"><thead><tr><th>Scenario</th><th>Result</th><th>Checks</th></tr></thead><tbody>\n";
  for (const ScenarioResult& s : t.scenarios) {
    out += "<tr><td>" + introspect::markup_text(s.path) + "</td><td class=\"" + (s.passed ? "ok" : "bad") + "\">" +
           (s.passed ? "passed" : "FAILED") + "</td><td>" + std::to_string(s.checks) + "</td></tr>\n";
  }
  return out + "</tbody></table>\n";
}

}  // namespace

std::string_view tool_version() noexcept { return SAFECASS_VERSION; }

std::string fill_template(std::string_view tmpl, const std::map<std::string, std::string, std::less<>>& values) {
  std::string out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t open = tmpl.find("{{", pos);
    if (open == std::string_view::npos) break;
    const std::size_t close = tmpl.find("}}", open);
    if (close == std::string_view::npos) break;
    out.append(tmpl.substr(pos, open - pos));
    const auto it = values.find(tmpl.substr(open + 2, close - open - 2));
    if (it != values.end())
      out += it->second;
    else
      out.append(tmpl.substr(open, close + 2 - open));
    pos = close + 2;
  }
  out.append(tmpl.substr(pos));
  return out;
}

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned char b : digest) {
    out += kHex[b >> 4];
    out += kHex[b & 0x0f];
  }
  return out;
}

std::string render_trace_page(const Trace& t, const std::string& date) {
  std::size_t errors = 0, warnings = 0, infos = 0;
  for (const Gap& g : t.gaps) {
    (g.severity == Severity::Error ? errors : g.severity == Severity::Warning ? warnings : infos) += 1;
  }
  std::string body = "<header class=\"report\">\n<h1>Hazard trace: <span id=\"system-name\">" +
                     introspect::markup_text(t.system) + "</span></h1>\n<dl class=\"meta\">";
  body += "<dt>System file</dt><dd>" + introspect::markup_text(t.system_path) + "</dd>";
  body += "<dt>Tool</dt><dd id=\"tool-version\">safecass " + introspect::markup_text(tool_version()) +
          " (safecass trace)</dd>";
  body += "<dt>Date</dt><dd id=\"report-date\">" + introspect::markup_text(date) + "</dd>";
  body += "<dt>Scenarios</dt><dd>" + std::to_string(t.scenarios.size()) + "</dd>";
  body += "<dt>Verification</dt><dd>" +
          (t.verify_source.empty() ? std::string("not run (no `safecass verify --json` result given)")
                                   : introspect::markup_text(t.verify_source)) +
          "</dd>";
  body +=
      "</dl>\n<table class=\"files\" id=\"file-table\"><thead><tr><th>Specification "
      "file</th><th>SHA-256</th></tr></thead><tbody>\n";
  for (const SpecFile& f : t.files)
    body += "<tr><td>" + introspect::markup_text(f.path) + "</td><td class=\"hash\">" + f.sha256 + "</td></tr>\n";
  body += "</tbody></table>\n<p id=\"verdict\" class=\"verdict " + std::string(errors == 0 ? "pass" : "fail") + "\">" +
          (errors == 0 ? "No gap of error severity."
                       : std::to_string(errors) + " gap" + (errors == 1 ? "" : "s") + " of error severity.") +
          " " + std::to_string(warnings) + " warning" + (warnings == 1 ? "" : "s") + ", " + std::to_string(infos) +
          " info.</p>\n</header>\n";
  body += "<section id=\"matrix\"><h2>Traceability matrix</h2>\n" + matrix(t) + "</section>\n";
  body += "<section id=\"gaps\"><h2>Gaps</h2>\n" + gap_table(t) + "</section>\n";
  body +=
      "<section id=\"excerpts\"><h2>Timeline excerpts</h2>\n<p class=\"small\">Per hazard, the scenario that exercises "
      "it, from its first linked onset to its clearing.</p>\n" +
      excerpts(t) + "</section>\n";
  body += "<section id=\"coverage\"><h2>Coverage</h2>\n" + coverage_table(t) + "</section>\n";
  const std::map<std::string, std::string, std::less<>> values{
      {"TITLE", introspect::markup_text(t.system)},   {"TIMELINE_CSS", std::string(web::kTimelineCss)},
      {"CSS", std::string(web::kTraceCss)},           {"BODY", body},
      {"TIMELINE_JS", std::string(web::kTimelineJs)}, {"JS", std::string(web::kTraceJs)},
  };
  return fill_template(web::kTraceHtml, values);
}

}  // namespace safecass::trace
