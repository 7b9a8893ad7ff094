// The fault trees (docs/analyze.md, "Fault trees"): per top event, the failure modes whose effects
// reach it (OR), and the escalations (AND) that reach it only together with another mode; written
// in the Open-PSA Model Exchange Format and handed to SCRAM for the minimal cut sets.

#include "fault_tree.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <map>
#include <set>

#include "safecass/verify/command.hpp"

namespace safecass::analyze {

namespace {

std::string xml_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// Builds the gates of every top event: one OR per top, and per escalating mode an AND of the mode
/// and an OR of the modes that put one of its machines at Warning or worse first.
///
/// No cut set needs more than two modes: a mirrored condition keeps its root's level along every
/// hop (DESIGN §2.6), so an enabler that is itself escalated stands at Error on the escalating
/// mode's machine and reaches, from there, everything the escalation would. Enablers are
/// therefore taken at their own level only.
class TreeBuilder {
public:
  explicit TreeBuilder(const std::vector<FailureMode>& modes, const std::vector<std::vector<Raise>>& raises)
      : modes_(modes), raises_(raises) {}

  void top(TopEvent& t, int order) {
    Gate g;
    g.name = t.gate;
    g.label = t.address + " at " + std::string(to_string(t.level)) + " or worse";
    for (std::size_t k = 0; k < modes_.size(); ++k) {
      const FailureMode& m = modes_[k];
      if (level_at(m.effects, t.address) >= t.level) {
        g.modes.push_back(m.id);
      } else if (m.escalates && order >= 2 && level_at(m.escalated, t.address) >= t.level) {
        if (std::string e = escalation(k); !e.empty()) g.gates.push_back(e);
      }
    }
    gates_.insert(gates_.begin() + static_cast<std::ptrdiff_t>(tops_++), std::move(g));
  }

  std::vector<Gate> take() { return std::move(gates_); }

private:
  /// The AND gate "mode k takes Error", or empty when nothing can put its machines at Warning first.
  std::string escalation(std::size_t k) {
    const std::string name = "ESC_" + modes_[k].id;
    if (const auto it = made_.find(name); it != made_.end()) return it->second;
    Gate enable;
    enable.name = "PRE_" + modes_[k].id;
    enable.label = "a machine " + modes_[k].id + " is raised at is already at Warning or worse";
    for (std::size_t j = 0; j < modes_.size(); ++j) {
      if (j == k) continue;
      const bool warns = std::any_of(raises_[k].begin(), raises_[k].end(), [&](const Raise& r) {
        return level_at(modes_[j].effects, r.machine) >= State::Warning;
      });
      if (warns) enable.modes.push_back(modes_[j].id);
    }
    if (enable.modes.empty()) return made_[name] = "";
    Gate esc;
    esc.name = name;
    esc.all = true;
    esc.label = modes_[k].id + " (" + modes_[k].name + ") takes Error: raised on a machine already at Warning";
    esc.modes.push_back(modes_[k].id);
    esc.gates.push_back(enable.name);
    gates_.push_back(std::move(esc));
    gates_.push_back(std::move(enable));
    return made_[name] = name;
  }

  const std::vector<FailureMode>& modes_;
  const std::vector<std::vector<Raise>>& raises_;
  std::vector<Gate> gates_;
  std::size_t tops_ = 0;
  std::map<std::string, std::string> made_;
};

void write_formula(std::string& out, const Gate& g) {
  const std::size_t n = g.modes.size() + g.gates.size();
  std::string args;
  for (const std::string& m : g.modes) args += "<basic-event name=\"" + m + "\"/>";
  for (const std::string& s : g.gates) args += "<gate name=\"" + s + "\"/>";
  if (n == 0)
    out += "<constant value=\"false\"/>";
  else if (n == 1)
    out += args;
  else
    out += std::string(g.all ? "<and>" : "<or>") + args + (g.all ? "</and>" : "</or>");
}

/// A double as MEF and SCRAM read it: the shortest text that reads back as the same double.
std::string number(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("0");
}

double attribute(const tinyxml2::XMLElement* e, const char* name) { return e->DoubleAttribute(name, 0.0); }

/// Why the trees cannot be quantified ("" when every mode has a rate or a probability).
std::string unquantified(const std::vector<FailureMode>& modes, bool has_section) {
  if (!has_section) return "the system file has no \"reliability\" section";
  std::vector<std::string> missing;
  for (const FailureMode& m : modes) {
    if (!m.rate && !m.probability) missing.push_back(m.id + " (" + m.name + ")");
  }
  if (missing.empty()) return {};
  std::string out = std::to_string(missing.size()) + " failure mode" + (missing.size() == 1 ? " has" : "s have") +
                    " no rate or probability: ";
  for (std::size_t k = 0; k < missing.size() && k < 5; ++k) out += (k == 0 ? "" : ", ") + missing[k];
  return out + (missing.size() > 5 ? ", …" : "");
}

const tinyxml2::XMLElement* child(const tinyxml2::XMLElement* e, const char* name) {
  return e == nullptr ? nullptr : e->FirstChildElement(name);
}

}  // namespace

FaultTrees fault_trees(const std::vector<FailureMode>& modes, const std::vector<std::vector<Raise>>& raises,
                       std::vector<TopEvent> tops, int order, const std::optional<spec::ReliabilitySpec>& reliability) {
  FaultTrees trees;
  trees.order = order;
  if (reliability) trees.mission_time = reliability->mission_time;
  trees.unquantified = unquantified(modes, reliability.has_value());
  TreeBuilder builder(modes, raises);
  for (std::size_t k = 0; k < tops.size(); ++k) {
    tops[k].gate = "TOP" + std::to_string(k + 1);
    builder.top(tops[k], order);
  }
  trees.tops = std::move(tops);
  trees.gates = builder.take();
  return trees;
}

std::string mef_document(const std::string& system, const std::vector<FailureMode>& modes, const FaultTrees& trees) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- safecass analyze: the fault trees of " +
                    xml_escape(system) + " (Open-PSA MEF) -->\n<opsa-mef>\n  <define-fault-tree name=\"system\">\n";
  for (const Gate& g : trees.gates) {
    out += "    <define-gate name=\"" + g.name + "\">\n      <label>" + xml_escape(g.label) + "</label>\n      ";
    write_formula(out, g);
    out += "\n    </define-gate>\n";
  }
  out += "  </define-fault-tree>\n  <model-data>\n";
  for (const FailureMode& m : modes) {
    out += "    <define-basic-event name=\"" + m.id + "\">\n      <label>" + xml_escape(m.name + ": " + m.description) +
           "</label>\n";
    if (m.probability)
      out += "      <float value=\"" + number(*m.probability) + "\"/>\n";
    else if (m.rate)
      out += "      <exponential><float value=\"" + number(*m.rate) + "\"/><system-mission-time/></exponential>\n";
    out += "    </define-basic-event>\n";
  }
  return out + "  </model-data>\n</opsa-mef>\n";
}

[[nodiscard]] Expected<std::string> run_scram(const std::string& system, const std::vector<FailureMode>& modes,
                                              FaultTrees& trees, const std::string& scram,
                                              const std::string& work_dir) {
  auto version = verify::run_command(".", verify::shell_quote(scram) + " --version");
  if (!version || version->status != 0)
    return fail(ErrorCode::Io,
                "SCRAM ('" + scram + "') does not run: install Debian's scram (scripts/install-deps.sh)");
  // "SCRAM 0.16.2 ()": its first line, without the empty build note.
  trees.scram = version->output.substr(0, version->output.find('\n'));
  if (trees.scram.ends_with(" ()")) trees.scram.resize(trees.scram.size() - 3);
  auto dir = verify::WorkDir::create(work_dir, "safecass-analyze-");
  if (!dir) return tl::unexpected(dir.error());
  trees.mef = mef_document(system, modes, trees);
  {
    std::ofstream f(dir->path() + "/trees.xml", std::ios::binary | std::ios::trunc);
    f << trees.mef;
    if (!f) return fail(ErrorCode::Io, "cannot write " + dir->path() + "/trees.xml");
  }
  std::string command = verify::shell_quote(scram) + " trees.xml --limit-order " + std::to_string(trees.order);
  if (trees.unquantified.empty())
    command += " --probability 1 --importance 1 --mission-time " + number(trees.mission_time);
  auto run = verify::run_command(dir->path(), command + " -o report.xml");
  if (!run) return tl::unexpected(run.error());
  if (run->status != 0)
    return fail(ErrorCode::Io, "SCRAM failed (status " + std::to_string(run->status) + "): " + run->output);
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile((dir->path() + "/report.xml").c_str()) != tinyxml2::XML_SUCCESS)
    return fail(ErrorCode::Io, "cannot read SCRAM's report: " + std::string(doc.ErrorStr()));
  std::map<std::string, TopEvent*> by_gate;
  for (TopEvent& t : trees.tops) by_gate[t.gate] = &t;
  const tinyxml2::XMLElement* results = child(doc.FirstChildElement("report"), "results");
  for (const tinyxml2::XMLElement* sop = child(results, "sum-of-products"); sop != nullptr;
       sop = sop->NextSiblingElement("sum-of-products")) {
    const char* name = sop->Attribute("name");
    const auto it = by_gate.find(name == nullptr ? "" : name);
    if (it == by_gate.end()) continue;
    if (trees.unquantified.empty()) it->second->probability = attribute(sop, "probability");
    for (const tinyxml2::XMLElement* p = sop->FirstChildElement("product"); p != nullptr;
         p = p->NextSiblingElement("product")) {
      CutSet cs;
      if (trees.unquantified.empty()) cs.probability = attribute(p, "probability");
      for (const tinyxml2::XMLElement* b = p->FirstChildElement("basic-event"); b != nullptr;
           b = b->NextSiblingElement("basic-event"))
        cs.modes.emplace_back(b->Attribute("name") == nullptr ? "" : b->Attribute("name"));
      std::sort(cs.modes.begin(), cs.modes.end(),
                [](const std::string& a, const std::string& b) { return mode_number(a) < mode_number(b); });
      it->second->cut_sets.push_back(std::move(cs));
    }
    // SCRAM lists products in its own order: smallest first, then by the modes' order, for a stable report.
    std::sort(it->second->cut_sets.begin(), it->second->cut_sets.end(), [](const CutSet& a, const CutSet& b) {
      if (a.modes.size() != b.modes.size()) return a.modes.size() < b.modes.size();
      return std::lexicographical_compare(
          a.modes.begin(), a.modes.end(), b.modes.begin(), b.modes.end(),
          [](const std::string& x, const std::string& y) { return mode_number(x) < mode_number(y); });
    });
  }
  for (const tinyxml2::XMLElement* imp = child(results, "importance"); imp != nullptr;
       imp = imp->NextSiblingElement("importance")) {
    const char* name = imp->Attribute("name");
    const auto it = by_gate.find(name == nullptr ? "" : name);
    if (it == by_gate.end()) continue;
    for (const tinyxml2::XMLElement* b = imp->FirstChildElement("basic-event"); b != nullptr;
         b = b->NextSiblingElement("basic-event")) {
      it->second->importance.push_back(Importance{b->Attribute("name") == nullptr ? "" : b->Attribute("name"),
                                                  attribute(b, "probability"), attribute(b, "MIF"), attribute(b, "CIF"),
                                                  attribute(b, "DIF"), attribute(b, "RAW"), attribute(b, "RRW")});
    }
  }
  return trees.scram;
}

}  // namespace safecass::analyze
