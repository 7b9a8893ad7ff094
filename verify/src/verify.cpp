// `safecass verify`: properties, their models, SPIN's verdicts, counterexamples as scenarios.

#include "safecass/verify/verify.hpp"
#include "safecass/core/named.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "model.hpp"
#include "promela.hpp"
#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"
#include "spin.hpp"

namespace safecass::verify {

std::string_view to_string(PropertyResult::Kind kind) noexcept {
  switch (kind) {
    case PropertyResult::Kind::Reaction: return "hazard";
    case PropertyResult::Kind::Invariant: return "invariant";
    case PropertyResult::Kind::NeedsReset: return "needs-reset";
    case PropertyResult::Kind::Undetectable: return "undetectable";
    case PropertyResult::Kind::NeverLeavesNormal: return "never-leaves-normal";
  }
  return "property";
}

std::string_view to_string(PropertyResult::Verdict verdict) noexcept {
  switch (verdict) {
    case PropertyResult::Verdict::Holds: return "holds";
    case PropertyResult::Verdict::Violated: return "violated";
    case PropertyResult::Verdict::Undecided: return "undecided";
  }
  return "undecided";
}

int Report::exit_code() const {
  bool undecided = false;
  for (const PropertyResult& p : properties) {
    const bool checked = p.kind == PropertyResult::Kind::Reaction || p.kind == PropertyResult::Kind::Invariant;
    if (!checked) continue;
    if (p.verdict == PropertyResult::Verdict::Violated) return 1;
    if (p.verdict == PropertyResult::Verdict::Undecided) undecided = true;
  }
  return undecided ? 3 : 0;
}

namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string level_name(State s) { return std::string(safecass::to_string(s)); }

/// A file name for a property: letters, digits, '-', '_' and '.'; anything else becomes '_'.
std::string file_name(const std::string& name) {
  std::string out;
  for (char c : name)
    out += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' || c == '.') ? c : '_';
  if (out.empty() || out[0] == '.') out = "_" + out;
  return out;
}

/// What an atom must tell apart: Error or not (false), or all three levels (true).
bool needs_warning(spec::Formula::Compare c, State level) {
  using C = spec::Formula::Compare;
  if (level == State::Error && (c == C::Eq || c == C::Ne || c == C::Ge || c == C::Lt)) return false;
  if (level == State::Warning && (c == C::Gt || c == C::Le)) return false;
  return true;
}

/// A property ready to check: its model's roots and the text of what is checked.
struct Check {
  PropertyResult result;
  std::vector<std::size_t> seed_roots;
  std::vector<std::pair<std::size_t, bool>> seed_addresses;
  std::vector<std::size_t> linked;                      ///< reactions: the hazard's roots
  std::vector<std::pair<std::size_t, State>> reaction;  ///< reactions: address, level
  std::optional<spec::Formula> formula;                 ///< invariants
};

class Verifier {
public:
  Verifier(Model& model, const Options& options, const std::string& dir) : m_(model), options_(options), dir_(dir) {}

  /// Checks every property. Properties are grouped into one model (one compilation of SPIN's
  /// verifier, one claim each) while the union of their cones stays small; a property's search
  /// then explores its group's model.
  std::vector<PropertyResult> run_all(std::vector<Check>& checks) {
    struct Item {
      Check* check;
      std::vector<std::size_t> cone;
      bool ltl;
    };
    std::vector<Item> items;
    for (Check& c : checks) {
      Item it{&c, {}, c.formula && !c.formula->is_state_invariant()};
      if (options_.slice) {
        it.cone = m_.cone(c.seed_roots, c.seed_addresses);
      } else {
        for (std::size_t i = 0; i < m_.roots().size(); ++i) it.cone.push_back(i);
      }
      items.push_back(std::move(it));
    }
    // Greedy grouping, in file order, by kind of search.
    std::vector<std::vector<std::size_t>> groups;
    std::vector<std::set<std::size_t>> unions;
    std::vector<bool> group_ltl;
    for (std::size_t i = 0; i < items.size(); ++i) {
      bool placed = false;
      for (std::size_t g = 0; g < groups.size() && !placed; ++g) {
        if (group_ltl[g] != items[i].ltl) continue;
        std::set<std::size_t> u = unions[g];
        u.insert(items[i].cone.begin(), items[i].cone.end());
        if (state_bits(std::vector<std::size_t>(u.begin(), u.end())) > kGroupBits) continue;
        groups[g].push_back(i);
        unions[g] = std::move(u);
        placed = true;
      }
      if (placed) continue;
      groups.push_back({i});
      unions.emplace_back(items[i].cone.begin(), items[i].cone.end());
      group_ltl.push_back(items[i].ltl);
    }
    std::vector<PropertyResult> results(items.size());
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto start = std::chrono::steady_clock::now();
      const std::vector<std::size_t> roots(unions[g].begin(), unions[g].end());
      const std::vector<RootClass> classes = m_.classes(roots, options_.merge);
      std::map<std::size_t, std::size_t> class_of;
      for (std::size_t c = 0; c < classes.size(); ++c) {
        for (std::size_t x : classes[c].members) class_of[x] = c;
      }
      PromelaSpec spec;
      spec.title = "system " + m_.system().name + ": ";
      spec.classes = classes;
      std::set<std::size_t> addresses;
      for (std::size_t i : groups[g]) {
        Check& check = *items[i].check;
        spec.title +=
            (i == groups[g].front() ? "" : ", ") + std::string(to_string(check.result.kind)) + " " + check.result.name;
        for (const auto& [a, warning] : check.seed_addresses) addresses.insert(a);
        spec.claims.emplace_back("p" + std::to_string(i), claim(check, class_of));
      }
      spec.addresses.assign(addresses.begin(), addresses.end());
      const std::string model = write_promela(m_, spec);
      PanOptions pan;
      pan.ltl = group_ltl[g];
      pan.memory_mb = options_.memory_mb;
      // Slots for the states the classes allow; the table (8 bytes a slot) takes at most a
      // quarter of the memory bound.
      const int most = std::max(
          10, static_cast<int>(std::floor(std::log2(static_cast<double>(options_.memory_mb) * 1024 * 1024 / 32))));
      pan.hash_bits = std::clamp(static_cast<int>(std::ceil(state_bits(roots))) + 2, 10, std::min(26, most));
      pan.spin = options_.spin;
      pan.cc = options_.cc;
      const std::string name = "model" + std::to_string(g);
      auto binary = compile(dir_, name, model, pan);
      const double compile_seconds = seconds_since(start);
      for (std::size_t k = 0; k < groups[g].size(); ++k) {
        const std::size_t i = groups[g][k];
        const auto claim_start = std::chrono::steady_clock::now();
        Check& check = *items[i].check;
        PropertyResult& r = results[i];
        r = check.result;
        r.onsets_total = m_.roots().size();
        r.onsets = classes.size();
        if (!binary) {
          r.verdict = PropertyResult::Verdict::Undecided;
          r.message = binary.error().message;
          continue;
        }
        auto result = check_claim(dir_, name, *binary, "p" + std::to_string(i), pan);
        // The compilation is shared: each property of the group is charged its share.
        r.seconds = compile_seconds / static_cast<double>(groups[g].size()) + seconds_since(claim_start);
        if (!result) {
          r.verdict = PropertyResult::Verdict::Undecided;
          r.message = result.error().message;
          continue;
        }
        r.states = result->states;
        r.memory_mb = result->memory_mb;
        switch (result->outcome) {
          case PanResult::Outcome::Holds: r.verdict = PropertyResult::Verdict::Holds; break;
          case PanResult::Outcome::MemoryLimit:
            r.verdict = PropertyResult::Verdict::Undecided;
            r.message = "the search reached the memory bound (" + std::to_string(options_.memory_mb) + " MB) after " +
                        std::to_string(r.states) + " states";
            r.advice = advice(classes);
            break;
          case PanResult::Outcome::Failed:
            r.verdict = PropertyResult::Verdict::Undecided;
            r.message = "SPIN's verifier did not finish:\n" + result->output;
            break;
          case PanResult::Outcome::Violated:
            r.verdict = PropertyResult::Verdict::Violated;
            counterexample(check, r, classes, *result, model);
            break;
        }
        r.seconds = compile_seconds / static_cast<double>(groups[g].size()) + seconds_since(claim_start);
      }
    }
    return results;
  }

private:
  /// Properties share a model while it has at most 2^kGroupBits states.
  static constexpr double kGroupBits = 20;

  /// log2 of the number of states the merged classes of `roots` allow (an upper bound).
  double state_bits(const std::vector<std::size_t>& roots) const {
    double bits = 0;
    for (const RootClass& k : m_.classes(roots, options_.merge)) {
      const double n = static_cast<double>(k.members.size());
      bits += std::log2((n + 1) * (n + 2) / 2);
    }
    return bits;
  }

  /// The property as an LTL claim over the model's macros.
  std::string claim(const Check& check, const std::map<std::size_t, std::size_t>& class_of) const {
    if (check.result.kind == PropertyResult::Kind::Reaction) {
      std::set<std::size_t> active;
      for (std::size_t x : check.linked) {
        if (const auto it = class_of.find(x); it != class_of.end()) active.insert(it->second);
      }
      std::string any;
      for (std::size_t c : active) any += (any.empty() ? "" : " || ") + std::string("ACTIVE_") + std::to_string(c);
      std::string need;
      for (const auto& [a, level] : check.reaction) {
        need += (need.empty() ? "" : " && ") + compare_text(a, spec::Formula::Compare::Ge, level);
      }
      if (any.empty() || need.empty()) return "[] true";
      return "[] (!(" + any + ") || (" + need + "))";
    }
    if (check.formula->is_state_invariant()) return "[] " + formula_text(m_, check.formula->operands[0], false);
    return formula_text(m_, *check.formula, true);
  }

  /// Which abstraction would help a property whose state space is too large.
  std::string advice(const std::vector<RootClass>& classes) const {
    std::map<MachineId, std::size_t> per_machine;
    for (const RootClass& k : classes) per_machine[m_.roots()[k.first()].machine] += 1;
    std::vector<std::pair<std::size_t, MachineId>> sorted;
    for (const auto& [m, n] : per_machine) sorted.emplace_back(n, m);
    std::sort(sorted.rbegin(), sorted.rend());
    std::string most;
    for (std::size_t i = 0; i < sorted.size() && i < 5; ++i) {
      most += (i ? ", " : "") + m_.machine_address(sorted[i].second) + " (" + std::to_string(sorted[i].first) + ")";
    }
    std::string off;
    if (!options_.slice)
      off += " without --no-slice only the onsets that can influence the property stay in its model;";
    if (!options_.merge) off += " without --no-merge interchangeable onsets are counted, not tracked;";
    if (!off.empty()) off = " First:" + off;
    return "the property depends on " + std::to_string(classes.size()) +
           " independent classes of onsets (most at: " + most +
           "). What would help: (1) onsets that are interchangeable for every property are counted, not "
           "tracked, when they share machine, transitions, latching, completion and hazard: give onsets that "
           "mean the same thing the same definition; (2) a property reads fewer onsets when it names fewer "
           "addresses: split an invariant over SYSTEM or many components into one per component; (3) narrower "
           "service dependencies (\"dependency\") and \"propagate\": \"error\" shrink what reaches an address; "
           "(4) --memory MB raises the bound." +
           off;
  }

  /// Replays the trail on the coordinator, writes the scenario, and says what failed.
  void counterexample(const Check& check, PropertyResult& r, const std::vector<RootClass>& classes,
                      const PanResult& pan, const std::string& model) {
    Coordinator& co = m_.coordinator();
    (void)reset(co, std::string_view("SYSTEM"), "verify", "counterexample");
    std::vector<Step> steps;
    std::string problem;
    for (const std::string& line : pan.trail) {
      std::istringstream in(line);
      std::string kind;
      in >> kind;
      std::size_t a = 0;
      int level = 0;
      in >> a >> level;
      if (kind == "on" || kind == "off") {
        if (a >= classes.size()) continue;
        bool done = false;
        for (std::size_t x : classes[a].members) {
          const Root& root = m_.roots()[x];
          const auto id = co.structure().find_event(root.event);
          const Condition* active = nullptr;
          std::vector<Condition> conditions = co.conditions(root.machine);
          for (const Condition& c : conditions) {
            if (!c.mirror && id && c.event == *id) active = &c;
          }
          if (kind == "on" && active == nullptr) {
            steps.push_back(Step{Step::Kind::Generate, root.event, co.structure().address_of(root.machine)});
          } else if (kind == "off" && active != nullptr && static_cast<int>(active->level) == level) {
            steps.push_back(Step{Step::Kind::Generate, root.completion, co.structure().address_of(root.machine)});
          } else {
            continue;
          }
          (void)generate(co, steps.back().event, steps.back().target);
          done = true;
          break;
        }
        if (!done) problem = "the trail's step '" + line + "' has no counterpart in the coordinator";
      } else if (kind == "reset") {
        const auto m = static_cast<MachineId>(a);
        if (to_index(m) >= co.structure().machine_count()) continue;
        steps.push_back(Step{Step::Kind::Reset, "", co.structure().address_of(m)});
        (void)reset(co, co.structure().address_of(m), "verify", "counterexample");
      } else if (kind == "bon" || kind == "boff") {
        if (a >= m_.broadcasts().size()) continue;
        const Broadcast& b = m_.broadcasts()[a];
        steps.push_back(Step{Step::Kind::Generate, kind == "bon" ? b.event : b.completion, ""});
        (void)generate(co, steps.back().event, "");
      }
    }
    // The failing expectation: what the property required and the coordinator does not show.
    std::vector<std::pair<std::string, State>> expect;
    if (r.kind == PropertyResult::Kind::Reaction) {
      for (const auto& [a, level] : check.reaction) {
        const std::string& address = m_.addresses()[a].address;
        const auto resolved = co.structure().resolve(address);
        if (resolved && co.state_of(*resolved) < level) expect.emplace_back(address, level);
      }
      std::string active;
      for (std::size_t x : check.linked) {
        const Root& root = m_.roots()[x];
        const auto id = co.structure().find_event(root.event);
        for (const Condition& c : co.conditions(root.machine)) {
          if (!c.mirror && id && c.event == *id)
            active += (active.empty() ? "" : ", ") + root.event + " on " + co.structure().address_of(root.machine);
        }
      }
      std::string below;
      for (const auto& [address, level] : expect) {
        const auto resolved = co.structure().resolve(address);
        below += (below.empty() ? "" : ", ") + address + " is " + level_name(co.state_of(*resolved)) +
                 ", not at least " + level_name(level);
      }
      const bool several = active.find(", ") != std::string::npos;
      r.message = "while " + (active.empty() ? std::string("an onset of the hazard") : active) +
                  (several ? " are" : " is") + " active, " +
                  (below.empty() ? std::string("the reaction fails") : below);
    } else if (check.formula->is_state_invariant()) {
      expect = repair(check.formula->operands[0]);
      std::string actual;
      std::vector<const spec::Formula*> atoms;
      check.formula->atoms(atoms);
      std::set<std::string> seen;
      for (const spec::Formula* atom : atoms) {
        if (!seen.insert(atom->address).second) continue;
        const auto resolved = co.structure().resolve(atom->address);
        if (resolved)
          actual += (actual.empty() ? "" : ", ") + atom->address + " is " + level_name(co.state_of(*resolved));
      }
      r.message = "reachable state where " + actual;
    } else {
      r.message = std::string("a run that violates the formula") +
                  (pan.cycle ? " (it ends in a cycle that repeats for ever)" : "");
    }
    if (problem.empty() && r.kind != PropertyResult::Kind::Invariant && expect.empty()) {
      problem = "the coordinator does not reproduce the violation the model found";
    }
    if (!problem.empty()) {
      r.verdict = PropertyResult::Verdict::Undecided;
      r.message = "internal: " + problem + " (please report this with the specification)";
      return;
    }
    r.message += " after " + std::to_string(steps.size()) + " step" + (steps.size() == 1 ? "" : "s");
    if (options_.out_dir.empty()) return;
    std::error_code ec;
    fs::create_directories(options_.out_dir, ec);
    const std::string base = options_.out_dir + "/" + file_name(r.name);
    r.scenario = base + ".scenario.json";
    std::ofstream(base + ".pml", std::ios::binary) << model;
    std::string system_path = m_.system().path;
    const fs::path rel = fs::absolute(system_path, ec).lexically_relative(fs::absolute(options_.out_dir, ec));
    if (!rel.empty()) system_path = rel.generic_string();
    std::string text =
        "// Counterexample of " + std::string(to_string(r.kind)) + " " + r.name + " found by `safecass verify`\n";
    text += "// (SPIN's shortest trail). `safecass run` replays it and fails at the last step.\n";
    text += "{\n  \"system\": " + json::json_string(system_path) + ",\n";
    text += "  \"description\": " +
            json::json_string(std::string(to_string(r.kind)) + " " + r.name + " violated: " + r.message) + ",\n";
    text += "  \"period\": 0.001,\n  \"duration\": 0.0,\n  \"steps\": [\n";
    std::vector<std::string> lines;
    for (const Step& s : steps) {
      if (s.kind == Step::Kind::Reset) {
        lines.push_back("    { \"at\": 0.0, \"reset\": { \"target\": " + json::json_string(s.target) +
                        ", \"reason\": \"counterexample step\" } }");
      } else if (s.target.empty()) {
        lines.push_back("    { \"at\": 0.0, \"generate\": { \"event\": " + json::json_string(s.event) + " } }");
      } else {
        lines.push_back("    { \"at\": 0.0, \"generate\": { \"event\": " + json::json_string(s.event) +
                        ", \"target\": " + json::json_string(s.target) + " } }");
      }
    }
    if (!expect.empty()) {
      std::string e;
      for (const auto& [address, level] : expect) {
        e += (e.empty() ? "" : ", ") + json::json_string(address) + ": " + json::json_string(level_name(level));
      }
      lines.push_back("    { \"at\": 0.0, \"expect\": { " + e + " } }");
    }
    for (std::size_t i = 0; i < lines.size(); ++i) text += lines[i] + (i + 1 < lines.size() ? ",\n" : "\n");
    text += "  ]\n}\n";
    std::ofstream f(r.scenario, std::ios::binary);
    f << text;
    if (!f) {
      r.message += " (cannot write " + r.scenario + ")";
      r.scenario.clear();
    }
  }

  /// The fewest address levels that would make the state formula true in the coordinator's
  /// current state: the expectation that a correct specification meets and this one fails.
  std::vector<std::pair<std::string, State>> repair(const spec::Formula& p) {
    Coordinator& co = m_.coordinator();
    std::vector<const spec::Formula*> atoms;
    p.atoms(atoms);
    std::vector<std::string> addresses;
    for (const spec::Formula* a : atoms) {
      if (std::find(addresses.begin(), addresses.end(), a->address) == addresses.end()) addresses.push_back(a->address);
    }
    std::vector<State> actual;
    for (const std::string& a : addresses) {
      const auto resolved = co.structure().resolve(a);
      actual.push_back(resolved ? co.state_of(*resolved) : State::Normal);
    }
    const std::size_t n = std::min<std::size_t>(addresses.size(), 10);
    std::size_t combos = 1;
    for (std::size_t i = 0; i < n; ++i) combos *= 3;
    std::vector<State> best;
    std::size_t best_changes = n + 1;
    std::size_t best_last = 0;
    int best_distance = 1 << 20;
    for (std::size_t k = 0; k < combos; ++k) {
      std::vector<State> v = actual;
      std::size_t x = k, changes = 0;
      for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<State>(x % 3);
        x /= 3;
        if (v[i] != actual[i]) ++changes;
      }
      // Fewest changes; on a tie, the change furthest right (the consequent of an implication).
      std::size_t last = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (v[i] != actual[i]) last = i;
      }
      int distance = 0;
      for (std::size_t i = 0; i < n; ++i) distance += std::abs(static_cast<int>(v[i]) - static_cast<int>(actual[i]));
      const bool better =
          changes < best_changes ||
          (changes == best_changes && (last > best_last || (last == best_last && distance < best_distance)));
      if (changes == 0 || !better) continue;
      if (eval(p, addresses, v)) {
        best = v;
        best_changes = changes;
        best_last = last;
        best_distance = distance;
      }
    }
    std::vector<std::pair<std::string, State>> out;
    for (std::size_t i = 0; i < best.size(); ++i) {
      if (best[i] != actual[i]) out.emplace_back(addresses[i], best[i]);
    }
    return out;
  }

  static bool eval(const spec::Formula& f, const std::vector<std::string>& addresses, const std::vector<State>& v) {
    using K = spec::Formula::Kind;
    switch (f.kind) {
      case K::True: return true;
      case K::False: return false;
      case K::Atom: {
        const auto i =
            static_cast<std::size_t>(std::find(addresses.begin(), addresses.end(), f.address) - addresses.begin());
        return spec::holds(f.compare, v[i], f.level);
      }
      case K::Not: return !eval(f.operands[0], addresses, v);
      case K::And: return eval(f.operands[0], addresses, v) && eval(f.operands[1], addresses, v);
      case K::Or: return eval(f.operands[0], addresses, v) || eval(f.operands[1], addresses, v);
      case K::Implies: return !eval(f.operands[0], addresses, v) || eval(f.operands[1], addresses, v);
      case K::Equiv: return eval(f.operands[0], addresses, v) == eval(f.operands[1], addresses, v);
      default: return true;
    }
  }

  Model& m_;
  const Options& options_;
  std::string dir_;
};

}  // namespace

namespace {

/// The properties to search: each hazard's reaction while a linked onset is active, each
/// invariant; only `options.property` when it is given.
[[nodiscard]] Expected<std::vector<Check>> property_checks(const spec::SystemSpec& system, const Model& model,
                                                           const Options& options) {
  std::vector<Check> checks;
  for (const spec::HazardSpec& h : system.hazards) {
    Check c;
    c.result.kind = PropertyResult::Kind::Reaction;
    c.result.name = h.id;
    c.result.where = h.where;
    std::string text;
    for (const auto& [address, level] : h.reaction) {
      text += (text.empty() ? "" : ", ") + address + " >= " + level_name(level);
      const int a = model.address_index(address);
      if (a < 0)
        return fail(ErrorCode::InvalidArgument, "hazard '" + h.id + "': no address '" + address + "' in the model");
      c.reaction.emplace_back(static_cast<std::size_t>(a), level);
      c.seed_addresses.emplace_back(static_cast<std::size_t>(a), level == State::Warning);
    }
    c.result.text = "while an onset of " + h.id + " is active: " + (text.empty() ? std::string("(no reaction)") : text);
    c.linked = model.linked(h.id);
    c.seed_roots = c.linked;
    checks.push_back(std::move(c));
  }
  for (const spec::InvariantSpec& inv : system.invariants) {
    auto f = spec::parse_formula(inv.formula);
    if (!f) return fail(ErrorCode::InvalidArgument, "invariant '" + inv.name + "': " + f.error().message);
    Check c;
    c.result.kind = PropertyResult::Kind::Invariant;
    c.result.name = inv.name;
    c.result.where = inv.where;
    c.result.text = inv.formula;
    std::vector<const spec::Formula*> atoms;
    f->atoms(atoms);
    for (const spec::Formula* atom : atoms) {
      const int a = model.address_index(atom->address);
      if (a < 0)
        return fail(ErrorCode::InvalidArgument,
                    "invariant '" + inv.name + "': no address '" + atom->address + "' in the model");
      const bool warning = needs_warning(atom->compare, atom->level);
      const auto it = std::find_if(c.seed_addresses.begin(), c.seed_addresses.end(),
                                   [&](const auto& s) { return s.first == static_cast<std::size_t>(a); });
      if (it == c.seed_addresses.end())
        c.seed_addresses.emplace_back(static_cast<std::size_t>(a), warning);
      else
        it->second = it->second || warning;
    }
    c.formula = std::move(*f);
    checks.push_back(std::move(c));
  }
  if (!options.property.empty()) {
    std::erase_if(checks, [&](const Check& c) { return c.result.name != options.property; });
    if (checks.empty()) {
      std::string known;
      for (const spec::HazardSpec& h : system.hazards) known += (known.empty() ? "" : ", ") + h.id;
      for (const spec::InvariantSpec& i : system.invariants) known += (known.empty() ? "" : ", ") + i.name;
      return fail(ErrorCode::NotFound, "no property '" + options.property + "' (hazard ids and invariant names: " +
                                           (known.empty() ? std::string("none") : known) + ")");
    }
  }

  return checks;
}

/// Properties of the specification itself, decided on the model's structure: onsets that only a
/// reset can clear, undetectable hazards, addresses that can never leave Normal.
void structural_properties(const spec::SystemSpec& system, const Model& model, Report& report) {
  const Coordinator& co = model.coordinator();
  std::set<std::string> reported;
  for (const Root& r : model.roots()) {
    if (r.clearable() || r.latched) continue;
    const std::string subject =
        r.event + (r.broadcast >= 0 ? std::string() : "@" + co.structure().address_of(r.machine));
    if (!reported.insert(subject).second) continue;
    PropertyResult p;
    p.kind = PropertyResult::Kind::NeedsReset;
    p.verdict = PropertyResult::Verdict::Violated;
    p.structural = true;
    p.name = subject;
    p.where = r.where;
    p.text = "every onset can be cleared";
    p.message = "onset '" + r.event + "' on " +
                (r.broadcast >= 0 ? std::string("every s_A") : co.structure().address_of(r.machine)) + " (from " +
                r.source + ") has no completion and is not latched: nothing but a reset can clear it";
    report.properties.push_back(std::move(p));
  }
  for (const spec::HazardSpec& h : system.hazards) {
    if (!model.linked(h.id).empty()) continue;
    PropertyResult p;
    p.kind = PropertyResult::Kind::Undetectable;
    p.verdict = PropertyResult::Verdict::Violated;
    p.structural = true;
    p.name = h.id;
    p.where = h.where;
    p.text = "some onset of the model detects the hazard";
    p.message = "hazard '" + h.id +
                "' is undetectable: no onset in the model is linked to it, so its reaction holds "
                "vacuously and nothing will ever raise it";
    report.properties.push_back(std::move(p));
  }
  // Components, and every address a reaction or an invariant names.
  std::vector<std::pair<std::string, spec::Position>> subjects;
  for (const spec::ComponentSpec& c : system.components) subjects.emplace_back(c.name, c.where);
  for (const spec::HazardSpec& h : system.hazards) {
    for (std::size_t i = 0; i < h.reaction.size(); ++i) {
      subjects.emplace_back(h.reaction[i].first, i < h.reaction_where.size() ? h.reaction_where[i] : h.where);
    }
  }
  for (const spec::InvariantSpec& inv : system.invariants) {
    auto f = spec::parse_formula(inv.formula);
    if (!f) continue;
    std::vector<const spec::Formula*> atoms;
    f->atoms(atoms);
    for (const spec::Formula* a : atoms) subjects.emplace_back(a->address, inv.where);
  }
  std::set<std::string> done;
  for (const auto& [address, where] : subjects) {
    if (!done.insert(address).second) continue;
    const int a = model.address_index(address);
    if (a < 0 || model.can_leave_normal(static_cast<std::size_t>(a))) continue;
    PropertyResult p;
    p.kind = PropertyResult::Kind::NeverLeavesNormal;
    p.verdict = PropertyResult::Verdict::Violated;
    p.structural = true;
    p.name = address;
    p.where = where;
    p.text = "the address can leave Normal";
    p.message = "address '" + address +
                "' can never leave Normal: no onset of the model reaches it, so a reaction "
                "that requires it at Warning or Error cannot be met";
    report.properties.push_back(std::move(p));
  }
}

}  // namespace

[[nodiscard]] Expected<Report> verify(const spec::SystemSpec& system, const FilterRegistry& registry,
                                      const Options& options) {
  const auto start = std::chrono::steady_clock::now();
  auto built = Model::build(system, registry);
  if (!built) return tl::unexpected(built.error());
  Model& model = **built;
  Report report;
  report.system = system.name;

  auto property_list = property_checks(system, model, options);
  if (!property_list) return tl::unexpected(property_list.error());
  std::vector<Check>& checks = *property_list;

  auto dir = WorkDir::create(options.work_dir);
  if (!dir) return tl::unexpected(dir.error());
  if (!checks.empty()) {
    if (auto v = spin_version(options.spin); !v) return tl::unexpected(v.error());
    if (auto c = compiler_check(options.cc); !c) return tl::unexpected(c.error());
  }
  Verifier verifier(model, options, dir->path());
  std::vector<Check> searched;
  for (Check& c : checks) {
    if (c.result.kind == PropertyResult::Kind::Reaction && (c.reaction.empty() || c.linked.empty())) {
      c.result.structural = true;
      c.result.message =
          c.reaction.empty() ? "no reaction to check" : "vacuously: no onset of the model is linked to the hazard";
      report.properties.push_back(c.result);
      continue;
    }
    searched.push_back(std::move(c));
  }
  for (PropertyResult& r : verifier.run_all(searched)) report.properties.push_back(std::move(r));

  if (options.property.empty()) structural_properties(system, model, report);
  report.seconds = seconds_since(start);
  return report;
}

[[nodiscard]] Expected<Simulation> simulate(const spec::SystemSpec& system, const FilterRegistry& registry,
                                            unsigned seed, std::size_t steps, const Options& options) {
  auto built = Model::build(system, registry);
  if (!built) return tl::unexpected(built.error());
  Model& model = **built;
  std::vector<std::size_t> all;
  for (std::size_t i = 0; i < model.roots().size(); ++i) all.push_back(i);
  PromelaSpec spec;
  spec.title = "system " + system.name + ": random simulation";
  spec.classes = model.classes(all, false);
  for (std::size_t a = 0; a < model.addresses().size(); ++a) spec.addresses.push_back(a);
  spec.print_states = true;
  auto dir = WorkDir::create(options.work_dir);
  if (!dir) return tl::unexpected(dir.error());
  // SPIN counts statements, not model steps; it stops where it stops, and the last step may be
  // cut short: ask for more and keep the whole steps.
  std::vector<std::string> printed;
  auto ran = simulate_model(dir->path(), write_promela(model, spec), seed, 1,
                            steps * (spec.addresses.size() + 3 * spec.classes.size() + 16), options.spin, options.cc,
                            [&](unsigned, std::vector<std::string>& lines) {
                              printed = std::move(lines);
                              return true;
                            });
  if (!ran) return tl::unexpected(ran.error());
  Simulation sim;
  for (const AddressInfo& a : model.addresses()) sim.addresses.push_back(a.address);
  const Coordinator& co = model.coordinator();
  for (const std::string& line : printed) {
    std::istringstream in(line);
    std::string kind;
    in >> kind;
    if (kind == "st") {
      std::vector<State> states;
      std::string word;
      while (in >> word && !word.empty() && std::isdigit(static_cast<unsigned char>(word[0])) != 0) {
        states.push_back(static_cast<State>(word[0] - '0'));
      }
      if (sim.states.size() + 1 != sim.steps.size()) {
        return fail(ErrorCode::Io, "SPIN's simulation printed an unexpected line: " + line);
      }
      if (states.size() != sim.addresses.size()) break;  // cut short at the end of the run
      sim.states.push_back(std::move(states));
      if (sim.states.size() == steps) break;
      continue;
    }
    std::size_t a = 0;
    int level = 0;
    in >> a >> level;
    // Without merging, class c is root c.
    if (kind == "on" || kind == "off") {
      const Root& r = model.roots()[spec.classes.at(a).first()];
      sim.steps.push_back(
          Step{Step::Kind::Generate, kind == "on" ? r.event : r.completion, co.structure().address_of(r.machine)});
    } else if (kind == "reset") {
      sim.steps.push_back(Step{Step::Kind::Reset, "", co.structure().address_of(static_cast<MachineId>(a))});
    } else if (kind == "bon" || kind == "boff") {
      const Broadcast& b = model.broadcasts().at(a);
      sim.steps.push_back(Step{Step::Kind::Generate, kind == "bon" ? b.event : b.completion, ""});
    }
  }
  sim.steps.resize(sim.states.size());
  return sim;
}

[[nodiscard]] Expected<std::string> promela(const spec::SystemSpec& system, const FilterRegistry& registry) {
  auto built = Model::build(system, registry);
  if (!built) return tl::unexpected(built.error());
  Model& model = **built;
  std::vector<std::size_t> all;
  for (std::size_t i = 0; i < model.roots().size(); ++i) all.push_back(i);
  PromelaSpec spec;
  spec.title = "system " + system.name;
  spec.classes = model.classes(all, false);
  for (std::size_t a = 0; a < model.addresses().size(); ++a) spec.addresses.push_back(a);
  return write_promela(model, spec);
}

}  // namespace safecass::verify
