// The analysis report: one self-contained HTML page (web/analyze/, compiled in), printable to PDF.
// The FMEA, the fault trees and the gaps are static HTML written here; the GSN diagram is drawn in
// the browser from the page's JSON, laid out by dagre as the live viewer's graph is (its module is
// inlined); without it the page keeps the indented tree written here.

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "analyze_assets.hpp"
#include "safecass/analyze/analyze.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/verify/command.hpp"

namespace safecass::analyze {

namespace {

using introspect::markup_text;

std::string level_cell(State s) {
  const std::string level(to_string(s));
  return "<span class=\"level-" + level + "\">" + level + "</span>";
}

std::string effects_cell(const std::vector<Reached>& effects) {
  if (effects.empty()) return "nothing";
  std::string out = "<span class=\"effects\">";
  for (const Reached& r : effects) out += markup_text(r.address) + "=" + level_cell(r.level) + " ";
  return out + "</span>";
}

std::string marker(const Gap& g) {
  const std::string sev(trace::to_string(g.severity));
  std::string label = sev;
  for (char& c : label) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return "<span class=\"marker-gap " + sev + "\" data-gap=\"" + markup_text(g.kind) + "\">" + label + " " +
         markup_text(g.kind) + ": " + markup_text(g.message) + "</span><br>";
}

std::string worst_class(const FailureMode& m) {
  std::string out;
  for (const Gap& g : m.gaps) {
    if (g.severity == trace::Severity::Error) return " class=\"gap-error\"";
    if (g.severity == trace::Severity::Warning) out = " class=\"gap-warning\"";
  }
  return out;
}

std::string header(const Analysis& a, const std::string& date) {
  const std::size_t errors = a.gap_count(trace::Severity::Error), warnings = a.gap_count(trace::Severity::Warning),
                    infos = a.gap_count(trace::Severity::Info);
  std::string out = "<header class=\"report\">\n<h1>Safety analysis: <span id=\"system-name\">" +
                    markup_text(a.trace.system) + "</span></h1>\n<dl class=\"meta\">";
  out += "<dt>System file</dt><dd>" + markup_text(a.trace.system_path) + "</dd>";
  out += "<dt>Tool</dt><dd id=\"tool-version\">safecass " + markup_text(trace::tool_version()) +
         " (safecass analyze)</dd>";
  out += "<dt>Date</dt><dd id=\"report-date\">" + markup_text(date) + "</dd>";
  out += "<dt>Failure modes</dt><dd>" + std::to_string(a.modes.size()) + "</dd>";
  out += "<dt>Scenarios</dt><dd>" + std::to_string(a.trace.scenarios.size()) + "</dd>";
  out += "<dt>Verification</dt><dd>" +
         (a.trace.verify_source.empty() ? std::string("not run (no `safecass verify --json` result given)")
                                        : markup_text(a.trace.verify_source)) +
         "</dd>";
  out += "<dt>Cut sets</dt><dd>" + markup_text(a.trees.scram.empty() ? "SCRAM not run" : a.trees.scram) +
         ", up to order " + std::to_string(a.trees.order) + "</dd></dl>\n";
  out +=
      "<table class=\"files\" id=\"file-table\"><thead><tr><th>Specification file</th><th>SHA-256</th></tr></thead>"
      "<tbody>\n";
  for (const trace::SpecFile& f : a.trace.files)
    out += "<tr><td>" + markup_text(f.path) + "</td><td class=\"hash\">" + f.sha256 + "</td></tr>\n";
  out += "</tbody></table>\n<p id=\"verdict\" class=\"verdict " + std::string(errors == 0 ? "pass" : "fail") + "\">" +
         (errors == 0 ? "No gap of error severity."
                      : std::to_string(errors) + " gap" + (errors == 1 ? "" : "s") + " of error severity.") +
         " " + std::to_string(warnings) + " warning" + (warnings == 1 ? "" : "s") + ", " + std::to_string(infos) +
         " info.</p>\n</header>\n";
  return out;
}

std::string fmea_table(const Analysis& a) {
  std::string out =
      "<table id=\"fmea-table\"><thead><tr><th>Id</th><th>Failure mode</th><th>Raises</th><th>Local "
      "effect</th><th>System effect</th><th>Detection</th><th>Hazards</th><th>Tests</th><th>Gaps</th></tr></thead>"
      "<tbody>\n";
  for (const FailureMode& m : a.modes) {
    std::string hazards, tests, gaps;
    for (const HazardLink& l : m.hazards) {
      hazards += markup_text(l.id) + " (" + markup_text(l.role) +
                 (l.role == "detected" ? ", verify: " + std::string(trace::to_string(l.verified)) : "") + ")<br>";
    }
    for (const Evidence& t : m.tests)
      tests += markup_text(t.scenario) + (t.passed ? " (passes)" : " (<b>FAILS</b>)") + "<br>";
    for (const Gap& g : m.gaps) gaps += marker(g);
    out += "<tr" + worst_class(m) + " data-mode=\"" + markup_text(m.id) + "\" data-kind=\"" +
           std::string(to_string(m.kind)) + "\"><td>" + markup_text(m.id) + "</td><td><b>" + markup_text(m.name) +
           "</b><br><span class=\"small\">" + markup_text(m.description) + "</span></td><td>" + markup_text(m.event) +
           " (" + std::to_string(m.severity) + ", " + level_cell(m.level) + (m.escalates ? "; Error on Warning" : "") +
           ")</td><td>" + markup_text(m.local_effect) + "</td><td>" + effects_cell(m.effects) + "</td><td>" +
           markup_text(m.detection) + "</td><td>" + (hazards.empty() ? "none" : hazards) + "</td><td>" +
           (tests.empty() ? "none" : tests) + "</td><td>" + gaps + "</td></tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string trees_section(const Analysis& a) {
  std::map<std::string, const FailureMode*> by_id;
  for (const FailureMode& m : a.modes) by_id[m.id] = &m;
  const auto name = [&](const std::string& id) {
    const auto it = by_id.find(id);
    return markup_text(id) + (it == by_id.end() ? "" : " " + markup_text(it->second->name));
  };
  std::string out = "<p class=\"small\">" +
                    (a.trees.unquantified.empty()
                         ? "Probabilities over a mission of " + number_text(a.trees.mission_time) + " h (SCRAM)."
                         : "Not quantified: " + markup_text(a.trees.unquantified) + ".") +
                    "</p>\n";
  for (const TopEvent& t : a.trees.tops) {
    out += "<div class=\"top\" data-gate=\"" + markup_text(t.gate) + "\"><h3>" + markup_text(t.gate) + ": " +
           markup_text(t.address) + " at " + level_cell(t.level) + " or worse <span class=\"small\">(" +
           markup_text(t.why) + ")</span>" +
           (t.probability ? " &mdash; probability " + number_text(*t.probability) : std::string()) +
           "</h3>\n<table class=\"cut-sets\"><thead><tr><th>Minimal cut set</th><th>Order</th><th>Probability</th>"
           "</tr></thead><tbody>\n";
    for (const CutSet& c : t.cut_sets) {
      std::string names;
      for (const std::string& id : c.modes) names += (names.empty() ? "" : " AND ") + name(id);
      out += "<tr class=\"cut-set\"><td>" + names + "</td><td>" + std::to_string(c.modes.size()) + "</td><td>" +
             (c.probability ? number_text(*c.probability) : std::string("&ndash;")) + "</td></tr>\n";
    }
    out += "</tbody></table></div>\n";
  }
  return out;
}

/// The goal structure as an indented list: what the page shows until (or unless) the diagram is drawn.
std::string gsn_tree(const SafetyCase& c) {
  std::map<std::string, const GsnNode*> by_id;
  for (const GsnNode& n : c.nodes) by_id[n.id] = &n;
  std::string out;
  const auto item = [&](const auto& self, const std::string& id) -> void {
    const auto it = by_id.find(id);
    if (it == by_id.end()) return;
    const GsnNode& n = *it->second;
    out += "<li><b>" + markup_text(n.id) + "</b> [" + markup_text(n.type) + "] " + markup_text(n.text) +
           (n.undeveloped ? " <span class=\"marker-gap warning\">UNDEVELOPED</span>" : "");
    if (!n.parts.empty() || !n.context.empty()) {
      out += "<ul>";
      for (const std::string& k : n.context) self(self, k);
      for (const std::string& k : n.parts) self(self, k);
      out += "</ul>";
    }
    out += "</li>";
  };
  out += "<ul class=\"gsn-tree\">";
  if (!c.nodes.empty()) item(item, c.nodes.front().id);
  return out + "</ul>";
}

/// The JSON of the goal structure, safe inside a script element.
std::string script_safe(std::string json) {
  for (std::size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at + 3))
    json.insert(at + 1, "\\");
  return json;
}

}  // namespace

std::string render_analysis_page(const Analysis& a, const std::string& date) {
  std::string body = header(a, date);
  body +=
      "<section id=\"fmea\"><h2>FMEA</h2>\n<p class=\"small\">Each failure mode raised alone in the engine (the "
      "propagation the robot runs); the system effect is every address it reaches.</p>\n" +
      fmea_table(a) + "</section>\n";
  body += "<section id=\"fault-trees\"><h2>Fault trees</h2>\n" + trees_section(a) + "</section>\n";
  body += "<section id=\"safety-case\"><h2>Safety case (GSN)</h2>\n<div id=\"gsn-figure\">" + gsn_tree(a.safety_case) +
          "</div></section>\n";
  body +=
      "<section id=\"limits\"><h2>Limits</h2>\n<p class=\"small\">The analysis knows the model: what a failure does to "
      "the states, and what the specification says detects and answers it. It cannot know the physical effect of a "
      "state, failure modes the model does not name (a plausible wrong value, a wrong threshold, a common cause), "
      "timing (detection latency, the loss bound, the order of two faults), or probabilities beyond the rates given "
      "(docs/analyze.md).</p></section>\n";
  const std::string gsn = safety_case_json(a.safety_case);
  const std::map<std::string, std::string, std::less<>> values{
      {"TITLE", markup_text(a.trace.system)},
      {"TIMELINE_CSS", std::string(web::kTimelineCss)},
      {"TRACE_CSS", std::string(web::kTraceCss)},
      {"CSS", std::string(web::kAnalyzeCss)},
      {"BODY", body},
      {"GSN", script_safe(gsn)},
      {"DAGRE", std::string(web::kDagreJs)},
      {"JS", std::string(web::kAnalyzeJs)},
  };
  return trace::fill_template(web::kAnalyzeHtml, values);
}

[[nodiscard]] Expected<void> print_pdf(const std::string& html_path, const std::string& pdf_path,
                                       const std::string& chromium) {
  std::error_code ec;
  const std::string html = std::filesystem::absolute(html_path, ec).string();
  const std::string pdf = std::filesystem::absolute(pdf_path, ec).string();
  if (ec) return fail(ErrorCode::Io, "cannot resolve '" + pdf_path + "': " + ec.message());
  auto dir = verify::WorkDir::create("", "safecass-analyze-chromium-");
  if (!dir) return tl::unexpected(dir.error());
  // Chromium's sandbox refuses to run as root; the page is our own, offline, and has no input.
  const std::string sandbox = ::geteuid() == 0 ? " --no-sandbox" : "";
  const std::string command =
      verify::shell_quote(chromium) + " --headless --disable-gpu" + sandbox +
      " --user-data-dir=" + verify::shell_quote(dir->path()) +
      " --no-pdf-header-footer --virtual-time-budget=10000 --print-to-pdf=" + verify::shell_quote(pdf) + " " +
      verify::shell_quote("file://" + html);
  auto run = verify::run_command(dir->path(), command);
  if (!run) return tl::unexpected(run.error());
  if (run->status != 0 || !std::filesystem::exists(pdf, ec))
    return fail(ErrorCode::Io, "Chromium ('" + chromium + "') did not print the report (status " +
                                   std::to_string(run->status) + "): " + run->output.substr(0, 400));
  return {};
}

}  // namespace safecass::analyze
