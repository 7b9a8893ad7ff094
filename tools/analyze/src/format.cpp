// The analysis as text, CSV and JSON. One formatter per format; every format shows the same facts.

#include <algorithm>
#include <cstdio>
#include <map>

#include "safecass/analyze/analyze.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/json/write.hpp"

namespace safecass::analyze {

namespace {

using json::JsonArray;
using json::JsonObject;

std::string effects_text(const std::vector<Reached>& effects) {
  std::vector<std::string> out;
  for (const Reached& r : effects) out.push_back(r.address + "=" + std::string(to_string(r.level)));
  return introspect::joined(out, " ");
}

std::string hazard_text(const HazardLink& l) {
  std::string s = l.id + " (" + l.role;
  if (l.role == "detected") {
    s += l.missed.empty() ? ", reaction reached" : ", reaction MISSED: " + introspect::joined(l.missed, "; ");
    s += ", verify: " + std::string(trace::to_string(l.verified));
  }
  return s + ")";
}

std::vector<std::string> hazards_of(const FailureMode& m) {
  std::vector<std::string> out;
  for (const HazardLink& l : m.hazards) out.push_back(hazard_text(l));
  return out;
}

std::vector<std::string> tests_of(const FailureMode& m) {
  std::vector<std::string> out;
  for (const Evidence& t : m.tests) out.push_back(t.scenario + (t.passed ? " (passes)" : " (FAILS)"));
  return out;
}

std::vector<std::string> gaps_of(const FailureMode& m) {
  std::vector<std::string> out;
  for (const Gap& g : m.gaps)
    out.push_back(std::string(trace::to_string(g.severity)) + " " + g.kind + ": " + g.message);
  return out;
}

std::string where_text(const spec::Position& p) {
  if (p.file.empty()) return {};
  if (p.line == 0) return p.file;
  return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

/// A probability or factor to six significant digits.
std::string probability_text(double p) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", p);
  return buf;
}

/// "FM3 (EVT_X@C.s_A)": a mode as a cut set names it.
std::string mode_label(const Analysis& a, const std::string& id) {
  for (const FailureMode& m : a.modes) {
    if (m.id == id) return id + " (" + m.name + ")";
  }
  return id;
}

}  // namespace

std::string fmea_text(const Analysis& a) {
  std::string out = "FMEA of " + a.trace.system + " (" + a.trace.system_path + "): " + std::to_string(a.modes.size()) +
                    " failure modes\n";
  for (const FailureMode& m : a.modes) {
    out += "\n" + m.id + "  " + m.name + "  [" + std::string(to_string(m.kind)) + "]\n";
    out += "  failure:    " + m.description + "\n";
    out += "  raises:     " + m.event + " (severity " + std::to_string(m.severity) + ", " +
           std::string(to_string(m.level)) + (m.escalates ? "; Error on a machine already at Warning" : "") + ")\n";
    out += "  local:      " + m.local_effect + "\n";
    out += "  system:     " + (m.effects.empty() ? std::string("nothing") : effects_text(m.effects)) + "\n";
    if (m.escalates) out += "  escalated:  " + effects_text(m.escalated) + "\n";
    out += "  detection:  " + m.detection + "\n";
    if (m.rate) out += "  rate:       " + probability_text(*m.rate) + " per hour\n";
    if (m.probability) out += "  probability: " + probability_text(*m.probability) + "\n";
    out +=
        "  hazards:    " + (m.hazards.empty() ? std::string("none") : introspect::joined(hazards_of(m), "; ")) + "\n";
    out += "  tests:      " + (m.tests.empty() ? std::string("none") : introspect::joined(tests_of(m), "; ")) + "\n";
    for (const std::string& g : gaps_of(m)) out += "  GAP " + g + "\n";
  }
  out += "\nGaps: " + std::to_string(a.gap_count(trace::Severity::Error)) + " error, " +
         std::to_string(a.gap_count(trace::Severity::Warning)) + " warning, " +
         std::to_string(a.gap_count(trace::Severity::Info)) + " info\n";
  return out;
}

std::string fault_trees_text(const Analysis& a) {
  std::string out = "\nFault trees (" + (a.trees.scram.empty() ? std::string("SCRAM not run") : a.trees.scram) +
                    ", cut sets up to order " + std::to_string(a.trees.order) + ")\n";
  out += a.trees.unquantified.empty()
             ? "Probabilities over a mission of " + probability_text(a.trees.mission_time) + " h\n"
             : "Not quantified: " + a.trees.unquantified + "\n";
  for (const TopEvent& t : a.trees.tops) {
    out += "\n" + t.gate + "  " + t.address + " at " + std::string(to_string(t.level)) + " or worse  (" + t.why +
           "): " + std::to_string(t.cut_sets.size()) + " minimal cut set" + (t.cut_sets.size() == 1 ? "" : "s");
    if (t.probability) out += ", probability " + probability_text(*t.probability);
    out += "\n";
    for (const CutSet& c : t.cut_sets) {
      std::vector<std::string> names;
      for (const std::string& id : c.modes) names.push_back(mode_label(a, id));
      out += "  {" + introspect::joined(names, ", ") + "}" +
             (c.probability ? "  p=" + probability_text(*c.probability) : "") + "\n";
    }
    std::vector<Importance> ranked = t.importance;
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const Importance& x, const Importance& y) { return x.cif > y.cif; });
    if (!ranked.empty()) out += "  importance (criticality CIF, Birnbaum MIF, RAW, RRW):\n";
    for (const Importance& i : ranked) {
      out += "    " + mode_label(a, i.mode) + "  CIF " + probability_text(i.cif) + "  MIF " + probability_text(i.mif) +
             "  RAW " + probability_text(i.raw) + "  RRW " + probability_text(i.rrw) + "\n";
    }
  }
  return out;
}

std::string safety_case_text(const Analysis& a) {
  std::map<std::string, const GsnNode*> by_id;
  for (const GsnNode& n : a.safety_case.nodes) by_id[n.id] = &n;
  std::string out = "\nSafety case (GSN)\n";
  // Depth-first from the top goal, indented by depth.
  std::vector<std::pair<std::string, int>> stack{
      {a.safety_case.nodes.empty() ? "" : a.safety_case.nodes.front().id, 1}};
  while (!stack.empty()) {
    const auto [id, depth] = stack.back();
    stack.pop_back();
    const auto it = by_id.find(id);
    if (it == by_id.end()) continue;
    const GsnNode& n = *it->second;
    out += std::string(static_cast<std::size_t>(depth) * 2, ' ') + n.id + " [" + n.type + "] " + n.text +
           (n.undeveloped ? "  <UNDEVELOPED>" : "") + "\n";
    for (auto c = n.parts.rbegin(); c != n.parts.rend(); ++c) stack.emplace_back(*c, depth + 1);
    for (auto c = n.context.rbegin(); c != n.context.rend(); ++c) stack.emplace_back(*c, depth + 1);
  }
  return out;
}

std::string fmea_csv(const Analysis& a) {
  std::string out =
      trace::csv_row({"id", "name", "kind", "failure", "event", "severity", "level", "escalates", "local_effect",
                      "system_effect", "escalated_effect", "detection", "hazards", "tests", "gaps", "where"});
  for (const FailureMode& m : a.modes) {
    out += trace::csv_row({m.id, m.name, std::string(to_string(m.kind)), m.description, m.event,
                           std::to_string(m.severity), std::string(to_string(m.level)), m.escalates ? "yes" : "no",
                           m.local_effect, effects_text(m.effects), effects_text(m.escalated), m.detection,
                           introspect::joined(hazards_of(m), "; "), introspect::joined(tests_of(m), "; "),
                           introspect::joined(gaps_of(m), "; "), where_text(m.where)});
  }
  return out;
}

namespace {

std::string json_effects(const std::vector<Reached>& effects) {
  JsonArray arr;
  for (const Reached& r : effects)
    arr.raw(JsonObject().str("address", r.address).str("level", std::string(to_string(r.level))).text());
  return arr.text();
}

std::string json_mode(const FailureMode& m) {
  JsonArray hazards, tests, gaps;
  for (const HazardLink& l : m.hazards) {
    hazards.raw(JsonObject()
                    .str("id", l.id)
                    .str("role", l.role)
                    .strings("missed", l.missed)
                    .str("verify", trace::to_string(l.verified))
                    .text());
  }
  for (const Evidence& t : m.tests)
    tests.raw(JsonObject().str("scenario", t.scenario).boolean("passed", t.passed).text());
  for (const Gap& g : m.gaps)
    gaps.raw(JsonObject()
                 .str("severity", trace::to_string(g.severity))
                 .str("kind", g.kind)
                 .str("message", g.message)
                 .text());
  JsonArray filters;
  for (const trace::FilterLink& f : m.filters) filters.str(f.name);
  return JsonObject()
      .str("id", m.id)
      .str("name", m.name)
      .str("kind", to_string(m.kind))
      .str("failure", m.description)
      .str("event", m.event)
      .integer("severity", m.severity)
      .str("level", std::string(to_string(m.level)))
      .boolean("escalates", m.escalates)
      .str("local_effect", m.local_effect)
      .raw("effects", json_effects(m.effects))
      .raw("escalated_effects", json_effects(m.escalated))
      .str("detection", m.detection)
      .raw("filters", filters.text())
      .raw("hazards", hazards.text())
      .raw("tests", tests.text())
      .raw("gaps", gaps.text())
      .raw("rate", m.rate ? json::json_number(*m.rate) : "null")
      .raw("probability", m.probability ? json::json_number(*m.probability) : "null")
      .str("where", where_text(m.where))
      .text();
}

std::string json_trees(const FaultTrees& trees) {
  JsonArray tops(JsonArray::Layout::OnePerLine);
  for (const TopEvent& t : trees.tops) {
    JsonArray cuts, importance;
    for (const CutSet& c : t.cut_sets) {
      cuts.raw(JsonObject()
                   .raw("modes", json::json_string_array(c.modes))
                   .raw("probability", c.probability ? json::json_number(*c.probability) : "null")
                   .text());
    }
    for (const Importance& i : t.importance) {
      importance.raw(JsonObject()
                         .str("mode", i.mode)
                         .num("probability", i.probability)
                         .num("mif", i.mif)
                         .num("cif", i.cif)
                         .num("dif", i.dif)
                         .num("raw", i.raw)
                         .num("rrw", i.rrw)
                         .text());
    }
    tops.raw(JsonObject()
                 .str("gate", t.gate)
                 .str("address", t.address)
                 .str("level", std::string(to_string(t.level)))
                 .str("why", t.why)
                 .raw("cut_sets", cuts.text())
                 .raw("probability", t.probability ? json::json_number(*t.probability) : "null")
                 .raw("importance", importance.text())
                 .text());
  }
  return JsonObject()
      .integer("order", trees.order)
      .str("scram", trees.scram)
      .num("mission_time", trees.mission_time)
      .opt("unquantified", trees.unquantified)
      .raw("tops", tops.text())
      .text();
}

}  // namespace

std::string safety_case_json(const SafetyCase& c) {
  JsonArray nodes(JsonArray::Layout::OnePerLine);
  for (const GsnNode& n : c.nodes) {
    nodes.raw(JsonObject()
                  .str("id", n.id)
                  .str("type", n.type)
                  .str("text", n.text)
                  .boolean("undeveloped", n.undeveloped)
                  .strings("supported_by", n.parts)
                  .strings("in_context_of", n.context)
                  .text());
  }
  return JsonObject().str("notation", "GSN Community Standard v3").raw("nodes", nodes.text()).text();
}

std::string analysis_json(const Analysis& a) {
  JsonArray modes(JsonArray::Layout::OnePerLine);
  for (const FailureMode& m : a.modes) modes.raw(json_mode(m));
  return JsonObject()
             .str("system", a.trace.system)
             .str("path", a.trace.system_path)
             .str("version", trace::tool_version())
             .raw("fmea", modes.text())
             .raw("fault_trees", json_trees(a.trees))
             .raw("safety_case", safety_case_json(a.safety_case))
             .raw("gaps", JsonObject()
                              .integer("error", static_cast<long long>(a.gap_count(trace::Severity::Error)))
                              .integer("warning", static_cast<long long>(a.gap_count(trace::Severity::Warning)))
                              .integer("info", static_cast<long long>(a.gap_count(trace::Severity::Info)))
                              .text())
             .text() +
         "\n";
}

}  // namespace safecass::analyze
