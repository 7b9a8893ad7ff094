// Seeded random model test (DESIGN §2). Each seed builds a random component graph — random
// provided and required interfaces, service dependencies (default, `{}`, explicit subsets,
// propagate Warning), connections with cycles — and random event definitions, then runs a long
// random sequence of onsets, completions, resets, broadcasts and late connections. After every
// step an oracle written here, independently of the coordinator's internals, predicts every
// machine's condition set and checks states, outstanding events, mirrors (defined by
// reachability), derived states, callback order, the observer stream and explain().
//
// The oracle reads the model only through the public API (connections(), service(),
// provided_machines(), ...); it keeps its own set of root conditions and derives the mirrors by
// its own breadth-first search.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "safecass/core/id_vector.hpp"

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

constexpr std::uint64_t kSeeds = 20;
constexpr int kSteps = 2000;

// ---- deterministic random numbers: splitmix64, the same sequence with every standard library ----

class Rng {
public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 0x1234567ull) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint32_t below(std::size_t n) { return static_cast<std::uint32_t>(next() % n); }
  int between(int lo, int hi) { return lo + static_cast<int>(below(static_cast<std::size_t>(hi - lo) + 1)); }
  bool chance(double p) { return static_cast<double>(next() >> 11) * 0x1.0p-53 < p; }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[below(v.size())];
  }
  template <class T>
  void shuffle(std::vector<T>& v) {
    for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[below(i)]);
  }

private:
  std::uint64_t s_;
};

// ---- the oracle's own state algebra (deliberately not product(), onset_level(), transition_between()) ----

int rank(State s) { return s == State::Error ? 2 : s == State::Warning ? 1 : 0; }
State worse(State a, State b) { return rank(a) >= rank(b) ? a : b; }

/// DESIGN §2.3: from Normal, Error if N2E is listed, else Warning; from Warning, Error if W2E is
/// listed; otherwise the highest level the listed transitions reach.
State expected_onset_level(TransitionSet t, State current) {
  const bool n2e = t.contains(Transition::N2E);
  const bool w2e = t.contains(Transition::W2E);
  if (current == State::Normal) return n2e ? State::Error : State::Warning;
  if (current == State::Warning && w2e) return State::Error;
  return (n2e || w2e) ? State::Error : State::Warning;
}

Transition expected_transition(State from, State to) {
  static const std::map<std::pair<int, int>, Transition> table = {{{0, 1}, Transition::N2W}, {{0, 2}, Transition::N2E},
                                                                  {{1, 2}, Transition::W2E}, {{1, 0}, Transition::W2N},
                                                                  {{2, 0}, Transition::E2N}, {{2, 1}, Transition::E2W}};
  return table.at({rank(from), rank(to)});
}

// ---- the random system specification --------------------------------------------------------

struct ComponentSpec {
  std::string name;
  std::vector<std::string> provided;
  std::vector<std::string> required;
  std::vector<std::optional<ServiceDependency>> services;  ///< nullopt: no `service` entry
};

struct ConnectionSpec {
  std::string client_required;
  std::string provider_provided;
  bool deferred = false;  ///< made in the middle of the run, while faults may be active
};

struct SystemSpec {
  std::vector<ComponentSpec> components;
  std::vector<ConnectionSpec> connections;
  std::vector<EventDef> events;  ///< in the order they are added
};

TransitionSet random_subset(Rng& rng, std::initializer_list<Transition> from) {
  TransitionSet s;
  while (s.empty()) {
    for (Transition t : from) {
      if (rng.chance(0.5)) s.insert(t);
    }
  }
  return s;
}

ServiceDependency random_service(Rng& rng, const ComponentSpec& c) {
  ServiceDependency d;
  d.framework = rng.chance(0.5);
  d.application = rng.chance(0.5);
  d.all_required = rng.chance(0.2);
  if (!d.all_required) {
    for (const std::string& r : c.required) {
      if (rng.chance(0.5)) d.required.push_back(r);
    }
  }
  return d;
}

SystemSpec generate_spec(std::uint64_t seed) {
  Rng rng(seed);
  SystemSpec spec;
  const int n = rng.between(5, 30);
  for (int i = 0; i < n; ++i) {
    ComponentSpec c;
    c.name = "C" + std::to_string(i);
    const int np = rng.between(0, 3);
    const int nr = rng.between(0, 3);
    for (int k = 0; k < np; ++k) c.provided.push_back("p" + std::to_string(k));
    for (int k = 0; k < nr; ++k) c.required.push_back("r" + std::to_string(k));
    spec.components.push_back(std::move(c));
  }
  // A ring of connected components in most seeds guarantees a cycle; random connections add more.
  std::vector<std::size_t> ring;
  if (rng.chance(0.7)) {
    std::vector<std::size_t> all(spec.components.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    rng.shuffle(all);
    ring.assign(all.begin(), all.begin() + rng.between(2, std::min(n, 6)));
    for (std::size_t i : ring) {
      spec.components[i].provided.push_back("ring");
      spec.components[i].required.push_back("ring");
    }
  }
  for (ComponentSpec& c : spec.components) {
    for (const std::string& p : c.provided) {
      std::optional<ServiceDependency> d;
      const std::uint32_t mode = rng.below(10);
      if (p == "ring") {
        d = random_service(rng, c);
        d->all_required = false;
        d->required = {"ring"};
      } else if (mode < 3) {
        // no entry: the conservative default
      } else if (mode < 5) {
        d = ServiceDependency::provided_only();
      } else if (mode < 6) {
        d = ServiceDependency{};  // an explicit entry equal to the default
      } else {
        d = random_service(rng, c);
      }
      if (d && rng.chance(0.35)) d->propagate = State::Warning;
      c.services.push_back(d);
    }
  }
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const ComponentSpec& client = spec.components[ring[k]];
    const ComponentSpec& provider = spec.components[ring[(k + 1) % ring.size()]];
    spec.connections.push_back({client.name + ".ring", provider.name + ".ring", false});
  }
  for (std::size_t i = 0; i < spec.components.size(); ++i) {
    for (const std::string& r : spec.components[i].required) {
      if (r == "ring" || !rng.chance(0.8)) continue;
      std::vector<std::size_t> providers;
      for (std::size_t j = 0; j < spec.components.size(); ++j) {
        if (j != i && !spec.components[j].provided.empty()) providers.push_back(j);
      }
      if (providers.empty()) continue;
      const ComponentSpec& provider = spec.components[rng.pick(providers)];
      spec.connections.push_back(
          {spec.components[i].name + "." + r, provider.name + "." + rng.pick(provider.provided), rng.chance(0.1)});
    }
  }
  // Events: onsets E<i> (some latched, some without a completion), completions "/E<i>" or
  // "CLR<i>" (an explicit `completes`), sometimes both; two broadcasts; one orphan completion.
  const int ne = rng.between(6, 16);
  for (int i = 0; i < ne; ++i) {
    EventDef onset;
    onset.name = "E" + std::to_string(i);
    onset.severity = rng.chance(0.15) ? rng.between(201, 250) : rng.between(1, 200);
    onset.transitions = random_subset(rng, {Transition::N2W, Transition::N2E, Transition::W2E});
    onset.latched = rng.chance(0.15);
    onset.hazard = "H-" + std::to_string(i);
    spec.events.push_back(onset);
    const std::uint32_t mode = rng.below(10);
    auto completion = [&](std::string name, std::string completes) {
      EventDef c;
      c.name = std::move(name);
      c.completes = std::move(completes);
      c.severity = onset.severity;
      c.transitions = random_subset(rng, {Transition::W2N, Transition::E2N, Transition::E2W});
      spec.events.push_back(c);
    };
    if (mode < 7) completion("/" + onset.name, "");
    if (mode == 7 || mode == 8) completion("CLR" + std::to_string(i), onset.name);
    if (mode == 8) completion("/" + onset.name, "");
    // mode 9: no completion; only reset clears it
  }
  for (int i = 0; i < 2; ++i) {
    EventDef b;
    b.name = "B" + std::to_string(i);
    b.severity = rng.between(251, 255);
    b.transitions = random_subset(rng, {Transition::N2W, Transition::N2E, Transition::W2E});
    b.latched = i == 1 && rng.chance(0.5);
    spec.events.push_back(b);
    EventDef c;
    c.name = "/" + b.name;
    c.severity = b.severity;
    c.transitions = random_subset(rng, {Transition::W2N, Transition::E2N, Transition::E2W});
    spec.events.push_back(c);
  }
  EventDef ghost;
  ghost.name = "/GHOST";
  ghost.severity = 7;
  ghost.transitions = {Transition::E2N};
  spec.events.push_back(ghost);
  // Completions may be defined before their onsets.
  rng.shuffle(spec.events);
  return spec;
}

// ---- the oracle ------------------------------------------------------------------------------

/// The model read back through the public API: every hop a condition can take, as machine → machine.
struct Hop {
  MachineId to;
  State min_level;
  ConnectionId via;
};

bool depends_on(const Coordinator& co, ComponentId c, std::uint32_t p, MachineId m) {
  if (co.structure().machine_component(m) != c) return false;
  const ServiceDependency& d = co.structure().service(c, p);
  switch (co.structure().machine_kind(m)) {
    case MachineKind::Framework: return d.framework;
    case MachineKind::Application: return d.application;
    case MachineKind::Provided: return co.structure().provided_machines(c)[p] == m;
    case MachineKind::Required:
      return d.all_required || std::find(d.required.begin(), d.required.end(),
                                         std::string(co.structure().interface_name(m))) != d.required.end();
  }
  return false;
}

std::vector<MachineId> machines_of(const Coordinator& co, ComponentId c) {
  std::vector<MachineId> out{co.structure().framework_machine(c), co.structure().application_machine(c)};
  for (MachineId m : co.structure().provided_machines(c)) out.push_back(m);
  for (MachineId m : co.structure().required_machines(c)) out.push_back(m);
  return out;
}

IdVector<std::vector<Hop>, MachineId> read_hops(const Coordinator& co) {
  IdVector<std::vector<Hop>, MachineId> hops(co.structure().machine_count());
  const auto& conns = co.structure().connections();
  for (ConnectionId k : id_range<ConnectionId>(conns.size())) {
    const Connection& conn = conns[to_index(k)];
    const MachineId client = co.structure().required_machines(conn.client)[conn.required];
    const State min_level = co.structure().service(conn.provider, conn.provided).propagate;
    for (MachineId m : machines_of(co, conn.provider)) {
      if (depends_on(co, conn.provider, conn.provided, m)) hops[m].push_back(Hop{client, min_level, k});
    }
  }
  return hops;
}

/// True when the machine graph (hops passable at Error) contains a cycle.
bool has_cycle(const IdVector<std::vector<Hop>, MachineId>& hops) {
  IdVector<int, MachineId> color(hops.size(), 0);
  std::vector<std::pair<MachineId, std::size_t>> stack;
  for (MachineId s : hops.ids()) {
    if (color[s] != 0) continue;
    stack.push_back({s, 0});
    color[s] = 1;
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      if (next == hops[node].size()) {
        color[node] = 2;
        stack.pop_back();
        continue;
      }
      const MachineId to = hops[node][next++].to;
      if (color[to] == 1) return true;
      if (color[to] == 0) {
        color[to] = 1;
        stack.push_back({to, 0});
      }
    }
  }
  return false;
}

struct EventInfo {
  bool onset = true;
  bool broadcast = false;
  TransitionSet transitions;
  bool latched = false;
  int severity = 0;
  std::optional<EventId> clears;  ///< completion: the onset it clears, when defined
};

struct RootModel {
  EventId event;
  State level;
  Time first;
  Time last;
  std::uint32_t count;
  SampleCause cause;
};

/// The record a directly targeted machine must publish for one application of an event (§2.4).
struct ExpectedRecord {
  MachineId machine;
  EventId event;
  Outcome outcome;
  State from;
  State to;
  std::string text;  ///< Ignored: the reason
};

struct MirrorModel {
  EventId root_event;
  MachineId origin;
  State level;
  Time first;
  SampleCause cause;
};

bool same_cause(const SampleCause& a, const SampleCause& b) {
  return a.filter == b.filter && a.signal == b.signal && a.value == b.value && a.sample_time == b.sample_time &&
         a.injected == b.injected;
}

class Oracle {
public:
  Oracle(const Coordinator& co, std::map<EventId, EventInfo> events)
      : co_(co),
        events_(std::move(events)),
        roots_(co.structure().machine_count()),
        mirrors_(co.structure().machine_count()) {
    reread_graph();
  }

  void reread_graph() {
    hops_ = read_hops(co_);
    recompute();
  }

  const EventInfo& info(EventId e) const { return events_.at(e); }
  const std::vector<RootModel>& roots(MachineId m) const { return roots_[m]; }
  const std::vector<MirrorModel>& mirrors(MachineId m) const { return mirrors_[m]; }
  const IdVector<std::vector<Hop>, MachineId>& hops() const { return hops_; }

  State state(MachineId m) const {
    State s = State::Normal;
    for (const RootModel& r : roots_[m]) s = worse(s, r.level);
    for (const MirrorModel& r : mirrors_[m]) s = worse(s, r.level);
    return s;
  }

  void generate(EventId e, MachineId target, Time now, const SampleCause& cause) {
    const EventInfo& ev = info(e);
    if (ev.broadcast) {
      for (ComponentId c : id_range<ComponentId>(co_.structure().component_count()))
        apply(e, co_.structure().application_machine(c), now, cause);
      return;
    }
    apply(e, target, now, cause);
  }

  /// Returns the number of root conditions cleared.
  std::size_t reset(const std::vector<MachineId>& targets) {
    std::size_t cleared = 0;
    for (MachineId m : targets) {
      cleared += roots_[m].size();
      roots_[m].clear();
    }
    recompute();
    return cleared;
  }

  /// The records the applications since the last call must have published, in order.
  std::vector<ExpectedRecord> take_expected() { return std::exchange(expected_, {}); }

  /// The active roots, for choosing a completion to send.
  std::vector<std::pair<MachineId, EventId>> active_roots() const {
    std::vector<std::pair<MachineId, EventId>> out;
    for (MachineId m : id_range<MachineId>(roots_.size())) {
      for (const RootModel& r : roots_[m]) out.push_back({m, r.event});
    }
    return out;
  }

private:
  /// Highest severity among the conditions at the machine's current level (0 if Normal).
  int outstanding_severity(MachineId m) const {
    const State s = state(m);
    int best = 0;
    for (const RootModel& r : roots_[m]) {
      if (r.level == s) best = std::max(best, info(r.event).severity);
    }
    for (const MirrorModel& r : mirrors_[m]) {
      if (r.level == s) best = std::max(best, r.level == State::Error ? 220 : 215);
    }
    return best;
  }

  void apply(EventId e, MachineId m, Time now, const SampleCause& cause) {
    const EventInfo& ev = info(e);
    auto& roots = roots_[m];
    const State before = state(m);
    if (ev.onset) {
      for (RootModel& r : roots) {
        if (r.event == e) {  // §2.4 onset rule 1: refresh only, not in the stream
          r.last = now;
          ++r.count;
          return;
        }
      }
      const State level = expected_onset_level(ev.transitions, before);
      Outcome outcome = Outcome::Masked;
      if (rank(level) > rank(before)) {
        outcome = Outcome::Raised;
      } else if (level == before) {
        outcome = ev.severity >= outstanding_severity(m) ? Outcome::Override : Outcome::Joined;
      }
      roots.push_back(RootModel{e, level, now, now, 1, cause});
      recompute();
      expected_.push_back({m, e, outcome, before, state(m), {}});
      return;
    }
    auto ignored = [&](const char* why) { expected_.push_back({m, e, Outcome::Ignored, before, before, why}); };
    if (!ev.clears) return ignored("completes an onset that is not defined");
    const auto it = std::find_if(roots.begin(), roots.end(), [&](const RootModel& r) { return r.event == *ev.clears; });
    if (it == roots.end()) return ignored("not active");
    if (info(*ev.clears).latched) return ignored("latched: needs reset");
    roots.erase(it);
    recompute();
    expected_.push_back({m, e, Outcome::Cleared, before, state(m), {}});
  }

  /// Mirrors are defined by reachability (DESIGN §2.6): one per root X at origin O in every machine
  /// reachable from O by hops each of which X's level passes; never in O itself.
  void recompute() {
    for (auto& v : mirrors_) v.clear();
    IdVector<char, MachineId> seen(hops_.size());
    std::vector<MachineId> queue;
    for (MachineId o : id_range<MachineId>(roots_.size())) {
      for (const RootModel& r : roots_[o]) {
        std::fill(seen.begin(), seen.end(), 0);
        queue.assign(1, o);
        seen[o] = 1;
        for (std::size_t head = 0; head < queue.size(); ++head) {
          for (const Hop& h : hops_[queue[head]]) {
            if (rank(r.level) < rank(h.min_level) || seen[h.to]) continue;
            seen[h.to] = 1;
            queue.push_back(h.to);
            mirrors_[h.to].push_back(MirrorModel{r.event, o, r.level, r.first, r.cause});
          }
        }
      }
    }
  }

  const Coordinator& co_;
  std::map<EventId, EventInfo> events_;
  IdVector<std::vector<RootModel>, MachineId> roots_;
  IdVector<std::vector<MirrorModel>, MachineId> mirrors_;
  IdVector<std::vector<Hop>, MachineId> hops_;
  std::vector<ExpectedRecord> expected_;
};

// ---- what the callbacks and the observer saw -------------------------------------------------

enum class Phase { Exit, Transition, Entry };

struct CallbackCall {
  Phase phase;
  bool component;                   ///< extended-state callback (else machine callback)
  std::uint32_t id;                 ///< machine or component
  State state = State::Normal;      ///< on_exit: old; on_entry: new
  State read_back = State::Normal;  ///< on_entry: the lock-free state read inside the callback
  TransitionInfo info;
};

/// What a run exercised, reported as test properties (visible in --gtest_output=xml).
struct Coverage {
  std::map<Outcome, int> outcomes;  ///< of Event records, roots and mirrors
  int machine_transitions = 0;
  int warning_mirrors = 0;  ///< mirrors at Warning level seen in checks
  int error_mirrors = 0;
  std::size_t max_conditions = 0;  ///< most conditions active at once, all machines
  int explained_mirrors = 0;       ///< mirrors whose hop path was checked
  int late_connections = 0;
};

// ---- one seed --------------------------------------------------------------------------------

class RandomModel {
public:
  explicit RandomModel(std::uint64_t seed)
      : seed_(seed), rng_(seed ^ 0xABCDEF12345ull), spec_(generate_spec(seed)), co_("rand", &clock_) {}

  /// Builds the coordinator from the spec; returns an error text on failure.
  std::string build() {
    for (const ComponentSpec& c : spec_.components) {
      auto id = co_.add_component(c.name);
      if (!id) return id.error().message;
      // Interleave provided and required interfaces so machine ids are not grouped by kind.
      std::size_t p = 0, r = 0;
      while (p < c.provided.size() || r < c.required.size()) {
        if (p < c.provided.size() && (r == c.required.size() || rng_.chance(0.5))) {
          if (auto m = co_.add_provided(*id, c.provided[p++]); !m) return m.error().message;
        } else {
          if (auto m = co_.add_required(*id, c.required[r++]); !m) return m.error().message;
        }
      }
    }
    for (ComponentId c : id_range<ComponentId>(spec_.components.size())) {
      const ComponentSpec& cs = spec_.components[to_index(c)];
      for (std::size_t p = 0; p < cs.provided.size(); ++p) {
        if (cs.services[p]) {
          if (auto ok = co_.set_service(c, cs.provided[p], *cs.services[p]); !ok) return ok.error().message;
        }
      }
    }
    std::map<std::string, EventId> ids;
    for (const EventDef& def : spec_.events) {
      auto id = co_.add_event(def);
      if (!id) return id.error().message;
      ids[def.name] = *id;
    }
    for (const ConnectionSpec& k : spec_.connections) {
      if (k.deferred) {
        deferred_.push_back(k);
        continue;
      }
      if (auto ok = co_.connect(k.client_required, k.provider_provided); !ok) return ok.error().message;
    }
    if (std::string err = check_read_back(); !err.empty()) return err;

    // The oracle's event table: user events from the spec, framework events as documented (§2.7).
    std::map<EventId, EventInfo> events;
    for (const EventDef& def : spec_.events) {
      EventInfo e;
      e.onset = def.transitions.worsening_only();
      e.broadcast = def.severity >= 251;
      e.transitions = def.transitions;
      e.latched = def.latched;
      e.severity = def.severity;
      if (!e.onset) {
        const std::string clears = def.completes.empty() ? def.name.substr(1) : def.completes;
        if (auto it = ids.find(clears); it != ids.end()) e.clears = it->second;
      }
      events[ids.at(def.name)] = e;
      (e.onset ? (e.broadcast ? broadcast_onsets_ : onsets_) : (e.broadcast ? broadcast_completions_ : completions_))
          .push_back(ids.at(def.name));
    }
    // Framework events (§2.7): every event the spec did not define; their definitions are data.
    for (EventId id : id_range<EventId>(co_.structure().event_count())) {
      if (events.count(id) != 0) continue;
      const Event& ev = co_.structure().event(id);
      EventInfo e;
      e.onset = ev.is_onset;
      e.transitions = ev.transitions;
      e.severity = ev.severity;
      if (!e.onset) {
        const auto onset = co_.structure().find_event(ev.name.substr(1));
        if (!onset) return "framework completion without its onset: " + ev.name;
        e.clears = *onset;
      }
      events[id] = e;
      (e.onset ? onsets_ : completions_).push_back(id);
    }
    service_failure_ = *co_.structure().find_event("EVT_SERVICE_FAILURE");
    service_degraded_ = *co_.structure().find_event("EVT_SERVICE_DEGRADED");
    oracle_.emplace(co_, std::move(events));

    filter_name_ = co_.intern("random_filter");
    signal_name_ = co_.intern("C0.signal");
    for (MachineId m : id_range<MachineId>(co_.structure().machine_count())) {
      co_.on_machine(m, callbacks(false, to_index(m)));
    }
    for (ComponentId c : id_range<ComponentId>(co_.structure().component_count()))
      co_.on_component(c, callbacks(true, to_index(c)));
    co_.subscribe([this](const Record& r) { records_.push_back(r); });
    machine_state_.assign(co_.structure().machine_count(), State::Normal);
    component_state_.assign(co_.structure().component_count(), State::Normal);
    return check();
  }

  bool cyclic() const { return has_cycle(read_hops(co_)); }
  const Coverage& coverage() const { return coverage_; }
  std::size_t components() const { return co_.structure().component_count(); }
  std::size_t machines() const { return co_.structure().machine_count(); }
  std::size_t connections() const { return co_.structure().connections().size(); }

  /// Runs one random step; returns an error text when an invariant fails.
  std::string step(int n) {
    step_ = n;
    clock_.advance(Time{rng_.chance(0.2) ? 0 : rng_.between(1, 1000) * 1000});
    const Time now = clock_.now();
    const std::uint32_t roll = rng_.below(1000);
    std::ostringstream op;
    if (roll < 430) {
      // An onset on a random machine; a quarter of them with the data of a filter that fired.
      const EventId e = rng_.pick(onsets_);
      const MachineId m = id_at<MachineId>(rng_.below(co_.structure().machine_count()));
      SampleCause cause;
      if (rng_.chance(0.25)) {
        cause.filter = filter_name_;
        cause.signal = signal_name_;
        cause.value = rng_.between(-1000, 1000) * 0.5;
        cause.sample_time = now - Time{rng_.between(0, 1000)};
        cause.injected = rng_.chance(0.3);
      }
      op << "generate " << co_.structure().event(e).name << " on " << co_.structure().address_of(m);
      if (!cause.present() && rng_.chance(0.2)) {
        if (!generate(co_, co_.structure().event(e).name, co_.structure().address_of(m)))
          return op.str() + ": name-based generate failed";
      } else {
        co_.generate(e, m, cause);
      }
      oracle_->generate(e, m, now, cause);
    } else if (roll < 500) {
      // Repeat an active onset at its origin: a refresh (level-triggered filters do this).
      const auto active = oracle_->active_roots();
      if (active.empty()) return finish("nothing active");
      const auto [m, e] = rng_.pick(active);
      op << "refresh " << co_.structure().event(e).name << " on " << co_.structure().address_of(m);
      co_.generate(e, m);
      oracle_->generate(e, m, now, {});
    } else if (roll < 850) {
      // A completion: mostly one that matches an active root, otherwise anything anywhere.
      const auto active = oracle_->active_roots();
      EventId e;
      MachineId m;
      if (!active.empty() && rng_.chance(0.7)) {
        const auto [origin, onset] = rng_.pick(active);
        std::vector<EventId> matching;
        for (const auto* pool : {&completions_, &broadcast_completions_}) {
          for (EventId c : *pool) {
            if (oracle_->info(c).clears == onset) matching.push_back(c);
          }
        }
        if (matching.empty()) matching = completions_;
        e = rng_.pick(matching);
        m = origin;
      } else {
        e = rng_.pick(completions_);
        m = id_at<MachineId>(rng_.below(co_.structure().machine_count()));
      }
      op << "generate " << co_.structure().event(e).name << " on " << co_.structure().address_of(m);
      const bool orphan = !oracle_->info(e).clears.has_value();
      if (rng_.chance(0.2)) {
        const auto result = generate(co_, co_.structure().event(e).name, co_.structure().address_of(m));
        if (orphan != !result) return op.str() + ": name-based generate of a completion returned the wrong result";
        if (orphan && result.error().code != ErrorCode::InvalidState) return op.str() + ": expected InvalidState";
        if (!orphan) oracle_->generate(e, m, now, {});  // a refused request is not processed at all
      } else {
        co_.generate(e, m);  // the id-based form processes it: recorded as ignored
        oracle_->generate(e, m, now, {});
      }
    } else if (roll < 890) {
      const bool onset = rng_.chance(0.6);
      const EventId e = rng_.pick(onset ? broadcast_onsets_ : broadcast_completions_);
      op << "broadcast " << co_.structure().event(e).name;
      if (rng_.chance(0.5)) {
        if (!broadcast(co_, co_.structure().event(e).name)) return op.str() + ": broadcast failed";
      } else {
        co_.generate(
            e, id_at<MachineId>(rng_.below(co_.structure().machine_count())));  // the target of a broadcast is ignored
      }
      oracle_->generate(e, kNoMachine, now, {});
    } else if (roll < 920) {
      // Reset a machine, a component, the system (by SYSTEM or by the coordinator's name).
      const std::uint32_t kind = rng_.below(20);
      std::string target;
      std::vector<MachineId> machines;
      if (kind < 8) {
        const MachineId m = id_at<MachineId>(rng_.below(co_.structure().machine_count()));
        target = co_.structure().address_of(m);
        machines = {m};
      } else if (kind < 16) {
        const ComponentId c = id_at<ComponentId>(rng_.below(co_.structure().component_count()));
        target = std::string(co_.structure().component_name(c));
        machines = machines_of(co_, c);
      } else {
        target = kind < 19 ? "SYSTEM" : "rand";
        for (MachineId m : id_range<MachineId>(co_.structure().machine_count())) machines.push_back(m);
      }
      op << "reset " << target;
      if (!reset(co_, target, "random", "step " + std::to_string(n))) return op.str() + ": reset failed";
      expected_reset_clears_ = oracle_->reset(machines);
      expected_resets_ = machines;
      reset_text_ = "random: step " + std::to_string(n);
    } else if (roll < 930) {
      // Resetting a derived service state is refused and changes nothing.
      std::vector<std::string> services;
      for (const ComponentSpec& c : spec_.components) {
        for (const std::string& p : c.provided) services.push_back(c.name + ".s_S." + p);
      }
      if (services.empty()) return finish("no services");
      const std::string target = rng_.pick(services);
      op << "reset " << target << " (refused)";
      const auto result = reset(co_, target, "random", "service");
      if (result || result.error().code != ErrorCode::InvalidArgument) return op.str() + ": expected InvalidArgument";
    } else if (roll < 940 && !deferred_.empty()) {
      // A connection made while faults are active carries them at once.
      const ConnectionSpec k = deferred_.back();
      deferred_.pop_back();
      op << "connect " << k.client_required << " -> " << k.provider_provided;
      if (!co_.connect(k.client_required, k.provider_provided)) return op.str() + ": connect failed";
      oracle_->reread_graph();
      ++coverage_.late_connections;
    } else {
      op << "idle";
    }
    return finish(op.str());
  }

private:
  std::string finish(const std::string& op) {
    last_ops_.push_back(op);
    if (last_ops_.size() > 8) last_ops_.erase(last_ops_.begin());
    std::string err = check();
    if (err.empty()) return err;
    std::ostringstream out;
    out << "seed " << seed_ << " step " << step_ << ": " << err << "\n  recent operations (oldest first):";
    for (const std::string& o : last_ops_) out << "\n    " << o;
    return out.str();
  }

  StateCallbacks callbacks(bool component, std::uint32_t id) {
    StateCallbacks cb;
    cb.on_exit = [this, component, id](State s) {
      calls_.push_back(CallbackCall{Phase::Exit, component, id, s, s, {}});
    };
    cb.on_transition = [this, component, id](const TransitionInfo& info) {
      calls_.push_back(CallbackCall{Phase::Transition, component, id, State::Normal, State::Normal, info});
    };
    cb.on_entry = [this, component, id](State s) {
      const State now = component ? co_.extended(ComponentId{id}).state : co_.state(MachineId{id});
      calls_.push_back(CallbackCall{Phase::Entry, component, id, s, now, {}});
    };
    return cb;
  }

  /// The configuration reads back as the spec wrote it.
  std::string check_read_back() {
    if (co_.structure().component_count() != spec_.components.size()) return "component count";
    for (ComponentId c : id_range<ComponentId>(spec_.components.size())) {
      const ComponentSpec& cs = spec_.components[to_index(c)];
      if (co_.structure().component_name(c) != cs.name) return "component name";
      if (co_.structure().provided_machines(c).size() != cs.provided.size()) return "provided count of " + cs.name;
      if (co_.structure().required_machines(c).size() != cs.required.size()) return "required count of " + cs.name;
      for (std::uint32_t p = 0; p < cs.provided.size(); ++p) {
        if (co_.structure().interface_name(co_.structure().provided_machines(c)[p]) != cs.provided[p])
          return "provided name";
        const ServiceDependency& got = co_.structure().service(c, p);
        const ServiceDependency want = cs.services[p].value_or(ServiceDependency{});
        if (got.framework != want.framework || got.application != want.application ||
            got.all_required != want.all_required || got.propagate != want.propagate ||
            (!want.all_required && got.required != want.required)) {
          return "service " + cs.name + "." + cs.provided[p] + " does not read back as set";
        }
      }
    }
    return {};
  }

  std::string check() {
    const Oracle& o = *oracle_;
    std::set<std::uint64_t> seqs;
    std::size_t total_conditions = 0;
    IdVector<State, MachineId> states(co_.structure().machine_count());

    for (MachineId m : id_range<MachineId>(co_.structure().machine_count())) {
      const std::string& at = co_.structure().address_of(m);
      const std::vector<Condition> conds = co_.conditions(m);
      // Roots: exactly the oracle's, with level, count, times, severity and cause.
      std::size_t roots = 0;
      for (const Condition& c : conds) {
        if (!seqs.insert(c.seq).second) return at + ": duplicate condition seq " + std::to_string(c.seq);
        if (c.mirror) continue;
        ++roots;
        const auto& want = o.roots(m);
        const auto it = std::find_if(want.begin(), want.end(), [&](const RootModel& r) { return r.event == c.event; });
        if (it == want.end()) return at + ": unexpected root condition " + co_.structure().event(c.event).name;
        if (c.level != it->level) {
          return at + ": root " + co_.structure().event(c.event).name + " has level " +
                 std::string(to_string(c.level)) + ", oracle says " + std::string(to_string(it->level));
        }
        if (c.count != it->count)
          return at + ": root " + co_.structure().event(c.event).name + " count " + std::to_string(c.count) +
                 ", oracle says " + std::to_string(it->count);
        if (c.first != it->first || c.last != it->last)
          return at + ": root " + co_.structure().event(c.event).name + " times";
        if (c.severity != o.info(c.event).severity) return at + ": root severity";
        if (c.via != kNoConnection) return at + ": a root condition names a connection";
        if (c.root.event != c.event || c.root.origin != m || c.root.time != it->first)
          return at + ": root cause of a root";
        if (!same_cause(c.root.sample, it->cause))
          return at + ": sample cause of root " + co_.structure().event(c.event).name;
      }
      if (roots != o.roots(m).size()) {
        return at + ": " + std::to_string(roots) + " root conditions, oracle says " + std::to_string(o.roots(m).size());
      }
      // Mirrors: exactly one per reachable active root.
      std::size_t mirrors = 0;
      for (const Condition& c : conds) {
        if (!c.mirror) continue;
        ++mirrors;
        const auto& want = o.mirrors(m);
        const auto it = std::find_if(want.begin(), want.end(), [&](const MirrorModel& x) {
          return x.root_event == c.root.event && x.origin == c.root.origin;
        });
        const std::string what =
            "mirror of " + co_.structure().address_of(c.root.origin) + ":" + co_.structure().event(c.root.event).name;
        if (it == want.end()) return at + ": unexpected " + what;
        if (c.root.origin == m) return at + ": holds a mirror of its own root";
        if (c.level != it->level) return at + ": " + what + " has the wrong level";
        const EventId mirror_event = c.level == State::Error ? service_failure_ : service_degraded_;
        if (c.event != mirror_event) return at + ": " + what + " has event " + co_.structure().event(c.event).name;
        if (c.severity != (c.level == State::Error ? 220 : 215)) return at + ": " + what + " severity";
        if (c.count != 1) return at + ": " + what + " was refreshed";
        if (c.first != it->first || c.root.time != it->first) return at + ": " + what + " times";
        if (!same_cause(c.root.sample, it->cause)) return at + ": " + what + " lost the sample cause";
        if (to_index(c.via) >= co_.structure().connections().size()) return at + ": " + what + " names no connection";
        const Connection& via = co_.structure().connections()[to_index(c.via)];
        if (co_.structure().required_machines(via.client)[via.required] != m)
          return at + ": " + what + " arrived via another machine's connection";
      }
      total_conditions += conds.size();
      for (const Condition& c : conds) {
        if (c.mirror) ++(c.level == State::Error ? coverage_.error_mirrors : coverage_.warning_mirrors);
      }
      if (mirrors != o.mirrors(m).size()) {
        std::string missing;
        for (const MirrorModel& x : o.mirrors(m)) {
          missing += " " + co_.structure().address_of(x.origin) + ":" + co_.structure().event(x.root_event).name + "/" +
                     std::string(to_string(x.level));
        }
        return at + ": " + std::to_string(mirrors) + " mirrors, oracle expects " + std::to_string(o.mirrors(m).size()) +
               ":" + missing;
      }
      // State = max level; outstanding = highest severity at that level, most recent on ties.
      State max_level = State::Normal;
      for (const Condition& c : conds) max_level = worse(max_level, c.level);
      if (max_level != o.state(m)) return at + ": oracle state differs";
      const StateSnapshot snap = co_.snapshot(m);
      if (co_.state(m) != max_level || snap.state != max_level) {
        return at + ": state " + std::string(to_string(co_.state(m))) + " but max level of conditions is " +
               std::string(to_string(max_level));
      }
      const Condition* best = nullptr;
      for (const Condition& c : conds) {
        if (c.level != max_level) continue;
        if (best == nullptr || c.severity > best->severity || (c.severity == best->severity && c.seq > best->seq))
          best = &c;
      }
      const EventId want_outstanding = best == nullptr ? kNoEvent : best->event;
      if (snap.outstanding != want_outstanding)
        return at + ": snapshot outstanding event is not the highest severity at the current level";
      const auto out = co_.outstanding(m);
      if (out.has_value() != (best != nullptr) ||
          (best != nullptr && (out->seq != best->seq || out->event != best->event))) {
        return at + ": outstanding() is not the highest severity, most recent condition at the current level";
      }
      states[m] = max_level;
    }

    // Components: extended state = product of its machines; outstanding over its machines.
    State all = State::Normal;
    for (ComponentId c : id_range<ComponentId>(co_.structure().component_count())) {
      const std::string name(co_.structure().component_name(c));
      State ext = State::Normal;
      const Condition* best = nullptr;
      std::vector<std::vector<Condition>> held;
      for (MachineId m : machines_of(co_, c)) ext = worse(ext, states[m]);
      for (MachineId m : machines_of(co_, c)) held.push_back(co_.conditions(m));
      for (const auto& conds : held) {
        for (const Condition& x : conds) {
          if (x.level != ext) continue;
          if (best == nullptr || x.severity > best->severity || (x.severity == best->severity && x.seq > best->seq))
            best = &x;
        }
      }
      const StateSnapshot snap = co_.extended(c);
      if (snap.state != ext || co_.extended(c).state != ext)
        return name + ": extended state is not the product of its machines";
      if (snap.outstanding != (best == nullptr ? kNoEvent : best->event)) return name + ": extended outstanding event";
      int calls = 0;
      State dispatched = State::Normal;
      EventId passed = kNoEvent;
      co_.dispatch(
          c, [&] { ++calls; }, [&](const Event& e) { ++calls, dispatched = State::Warning, passed = e.id; },
          [&](const Event& e) { ++calls, dispatched = State::Error, passed = e.id; });
      if (calls != 1 || dispatched != ext || passed != snap.outstanding) return name + ": dispatch";
      const auto addr = co_.structure().resolve(name);
      if (!addr || co_.state_of(*addr) != ext) return name + ": state_of(component)";
      // Service states: s_P.p ⊗ [s_F] ⊗ [s_A] ⊗ listed (or all) required interfaces.
      for (std::uint32_t p = 0; p < co_.structure().provided_machines(c).size(); ++p) {
        const ServiceDependency& d = co_.structure().service(c, p);
        State s = states[co_.structure().provided_machines(c)[p]];
        if (d.framework) s = worse(s, states[co_.structure().framework_machine(c)]);
        if (d.application) s = worse(s, states[co_.structure().application_machine(c)]);
        for (MachineId r : co_.structure().required_machines(c)) {
          const std::string rname(co_.structure().interface_name(r));
          if (d.all_required || std::find(d.required.begin(), d.required.end(), rname) != d.required.end()) {
            s = worse(s, states[r]);
          }
        }
        if (co_.service_state(c, p) != s) return name + ": service state of provided interface " + std::to_string(p);
        const auto sa = co_.structure().resolve(
            name + ".s_S." + std::string(co_.structure().interface_name(co_.structure().provided_machines(c)[p])));
        if (!sa || co_.state_of(*sa) != s) return name + ": state_of(service)";
      }
      all = worse(all, ext);
    }
    coverage_.max_conditions = std::max(coverage_.max_conditions, total_conditions);
    if (co_.coordinator_state() != all) return "coordinator state is not the product of the components";
    if (const auto sys = co_.structure().resolve("SYSTEM"); !sys || co_.state_of(*sys) != all)
      return "state_of(SYSTEM)";

    // The product is order-independent: fold the machine states in several random orders.
    {
      std::vector<State> shuffled(states.begin(), states.end());
      State expected = State::Normal;
      for (State s : states) expected = worse(expected, s);
      if (expected != all) return "product of machine states differs from the product of components";
      for (int k = 0; k < 4; ++k) {
        rng_.shuffle(shuffled);
        State folded = State::Normal;
        for (State s : shuffled) folded = product(folded, s);
        State right = State::Normal;  // right fold, also in the shuffled order
        for (auto it = shuffled.rbegin(); it != shuffled.rend(); ++it) right = *it * right;
        if (folded != expected || right != expected) return "the state product depends on the order";
      }
    }

    if (std::string e = check_callbacks(); !e.empty()) return e;
    if (step_ % 16 == 0) {
      if (std::string e = check_explain(); !e.empty()) return e;
    }
    return {};
  }

  /// Every transition fired on_exit(old) → on_transition → on_entry(new), with consistent states.
  std::string check_callbacks() {
    if (calls_.size() % 3 != 0) return "callback calls do not come in exit/transition/entry triples";
    std::map<std::pair<bool, std::uint32_t>, int> triples;
    for (std::size_t i = 0; i < calls_.size(); i += 3) {
      const CallbackCall& x = calls_[i];
      const CallbackCall& t = calls_[i + 1];
      const CallbackCall& n = calls_[i + 2];
      const std::string who = x.component ? std::string(co_.structure().component_name(ComponentId{x.id}))
                                          : co_.structure().address_of(MachineId{x.id});
      if (x.phase != Phase::Exit || t.phase != Phase::Transition || n.phase != Phase::Entry) {
        return who + ": callbacks out of order (want on_exit, on_transition, on_entry)";
      }
      if (t.component != x.component || n.component != x.component || t.id != x.id || n.id != x.id) {
        return who + ": a transition's callbacks are interleaved with another's";
      }
      State& tracked = x.component ? component_state_[ComponentId{x.id}] : machine_state_[MachineId{x.id}];
      if (x.state != tracked)
        return who + ": on_exit(" + std::string(to_string(x.state)) + ") but the state was " +
               std::string(to_string(tracked));
      if (x.state == n.state) return who + ": a transition to the same state";
      if (t.info.transition != expected_transition(x.state, n.state))
        return who + ": on_transition names the wrong transition";
      if (x.component ? (t.info.component != ComponentId{x.id} || t.info.machine != kNoMachine)
                      : (t.info.machine != MachineId{x.id} ||
                         t.info.component != co_.structure().machine_component(MachineId{x.id}))) {
        return who + ": on_transition names the wrong machine or component";
      }
      // Callbacks run once the write that caused them is complete (docs/semantics.md §5.2): on_entry
      // reads the state that write left, the `to` of this transition or of a later one of the same
      // machine in this step.
      bool read_back_known = n.read_back == n.state;
      for (std::size_t k = i + 3; !read_back_known && k < calls_.size(); k += 3) {
        const CallbackCall& later = calls_[k + 2];
        read_back_known = later.component == x.component && later.id == x.id && later.state == n.read_back;
      }
      if (!read_back_known) return who + ": on_entry(new) reads a state the write never left it in";
      tracked = n.state;
      ++triples[{x.component, x.id}];
    }
    calls_.clear();
    for (MachineId m : id_range<MachineId>(co_.structure().machine_count())) {
      if (machine_state_[m] != co_.state(m))
        return co_.structure().address_of(m) + ": a state change fired no callbacks";
    }
    for (ComponentId c : id_range<ComponentId>(co_.structure().component_count())) {
      if (component_state_[c] != co_.extended(c).state)
        return std::string(co_.structure().component_name(c)) + ": a change fired no callbacks";
    }
    // The observer stream has one Transition record per machine transition, in seq order.
    std::map<std::pair<bool, std::uint32_t>, int> recorded;
    const std::vector<ExpectedRecord> expected = oracle_->take_expected();
    std::size_t next_expected = 0;
    std::size_t reset_clears = 0;
    std::vector<MachineId> resets;
    for (const Record& r : records_) {
      if (r.seq <= last_record_seq_) return "observer records out of order";
      last_record_seq_ = r.seq;
      if (r.kind == RecordKind::Event) ++coverage_.outcomes[r.outcome];
      if (r.kind == RecordKind::Transition) {
        ++coverage_.machine_transitions;
        if (r.from == r.to) return "a Transition record without a change";
        ++recorded[{false, to_index(r.machine)}];
      }
      if (r.kind == RecordKind::ComponentTransition) ++recorded[{true, to_index(r.component)}];
      if (r.kind == RecordKind::Reset) {
        if (r.text != reset_text_) return "reset record text '" + std::string(r.text) + "'";
        resets.push_back(r.machine);
      }
      if (r.kind != RecordKind::Event) continue;
      const std::string at =
          to_index(r.machine) < co_.structure().machine_count() ? co_.structure().address_of(r.machine) : "?";
      // Every Event record is consistent with its outcome (§2.4).
      bool consistent = true;
      switch (r.outcome) {
        case Outcome::Raised: consistent = rank(r.level) > rank(r.from) && r.to == r.level; break;
        case Outcome::Override:
        case Outcome::Joined: consistent = r.level == r.from && r.to == r.from; break;
        case Outcome::Masked: consistent = rank(r.level) < rank(r.from) && r.to == r.from; break;
        case Outcome::Cleared: consistent = rank(r.to) <= rank(r.from); break;
        case Outcome::Ignored: consistent = r.to == r.from; break;
        case Outcome::None: consistent = false; break;
      }
      if (!consistent)
        return at + ": Event record " + std::string(to_string(r.outcome)) + " inconsistent with its states";
      if (r.mirror) continue;
      if (r.event == kNoEvent) {  // a root cleared by reset
        if (r.outcome != Outcome::Cleared || r.text != reset_text_) return at + ": reset clear record";
        ++reset_clears;
        continue;
      }
      // Records of the machines an operation targeted directly: predicted one by one.
      if (next_expected == expected.size())
        return at + ": unexpected Event record for " + co_.structure().event(r.event).name;
      const ExpectedRecord& want = expected[next_expected++];
      if (r.machine != want.machine || r.event != want.event || r.outcome != want.outcome || r.from != want.from ||
          r.to != want.to || r.text != want.text) {
        return at + ": " + co_.structure().event(r.event).name + " recorded " + std::string(to_string(r.outcome)) +
               " " + std::string(to_string(r.from)) + "->" + std::string(to_string(r.to)) + " '" + std::string(r.text) +
               "', oracle expects " + co_.structure().address_of(want.machine) + " " +
               co_.structure().event(want.event).name + " " + std::string(to_string(want.outcome)) + " " +
               std::string(to_string(want.from)) + "->" + std::string(to_string(want.to)) + " '" + want.text + "'";
      }
    }
    records_.clear();
    if (next_expected != expected.size()) return "an operation published fewer Event records than the oracle expects";
    if (reset_clears != expected_reset_clears_) return "reset cleared a different number of root conditions";
    if (resets != expected_resets_) return "reset records do not name every reset machine";
    expected_reset_clears_ = 0;
    expected_resets_.clear();
    if (recorded != triples) return "observer Transition records do not match the callbacks";
    return {};
  }

  /// explain() lists every condition with a hop path from its origin that the model allows.
  std::string check_explain() {
    const MachineId m = id_at<MachineId>(rng_.below(co_.structure().machine_count()));
    const std::string& at = co_.structure().address_of(m);
    const auto why = explain(co_, at);
    if (!why) return at + ": explain failed";
    const auto conds = co_.conditions(m);
    if (why->size() != conds.size()) return at + ": explain lists a different number of conditions";
    const auto& hops = oracle_->hops();
    for (const Explanation& x : *why) {
      const std::string what = at + ": explain " + x.root.name();
      if (x.machine != at) return what + ": wrong machine";
      if (x.path.empty() || x.path.front() != x.root.origin || x.path.back() != at) {
        std::string p;
        for (const std::string& s : x.path) p += " " + s;
        return what + ": hop path does not lead from the origin to the holder:" + p;
      }
      if (!x.mirror) {
        if (x.path.size() != 1) return what + ": a root condition has a hop path";
        continue;
      }
      ++coverage_.explained_mirrors;
      if (x.path.size() % 2 == 0) return what + ": hop path does not alternate services and interfaces";
      State level = x.level;
      for (std::size_t i = 1; i + 1 < x.path.size(); i += 2) {
        const auto from = co_.structure().find_machine(x.path[i - 1]);
        const auto svc = co_.structure().resolve(x.path[i]);
        const auto to = co_.structure().find_machine(x.path[i + 1]);
        if (!from || !svc || svc->kind != Address::Kind::Service || !to) return what + ": malformed hop path";
        if (!depends_on(co_, svc->component, svc->service, *from))
          return what + ": hop path leaves through a service that does not depend on " + x.path[i - 1];
        bool ok = false;
        for (const Hop& h : hops[*from]) {
          const Connection& k = co_.structure().connections()[to_index(h.via)];
          if (h.to == *to && k.provider == svc->component && k.provided == svc->service &&
              rank(level) >= rank(h.min_level))
            ok = true;
        }
        if (!ok)
          return what + ": hop path takes a connection the condition cannot pass: " + x.path[i] + " -> " +
                 x.path[i + 1];
      }
    }
    return {};
  }

  std::uint64_t seed_;
  Rng rng_;
  SystemSpec spec_;
  SimulatedClock clock_{Time{1'000'000}};
  Coordinator co_;
  std::optional<Oracle> oracle_;
  std::vector<EventId> onsets_, completions_, broadcast_onsets_, broadcast_completions_;
  std::vector<ConnectionSpec> deferred_;
  EventId service_failure_ = kNoEvent;
  EventId service_degraded_ = kNoEvent;
  NameId filter_name_ = kNoName;
  NameId signal_name_ = kNoName;
  std::vector<CallbackCall> calls_;
  std::vector<Record> records_;
  std::uint64_t last_record_seq_ = 0;
  IdVector<State, MachineId> machine_state_;
  IdVector<State, ComponentId> component_state_;
  std::vector<std::string> last_ops_;
  std::size_t expected_reset_clears_ = 0;
  std::vector<MachineId> expected_resets_;
  std::string reset_text_;
  int step_ = 0;
  Coverage coverage_;
};

class RandomModelTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(RandomModelTest, EveryInvariantHoldsAfterEveryStepOfARandomSequence) {
  RandomModel model(GetParam());
  const std::string built = model.build();
  ASSERT_TRUE(built.empty()) << "seed " << GetParam() << " set-up: " << built;
  for (int step = 1; step <= kSteps; ++step) {
    const std::string err = model.step(step);
    ASSERT_TRUE(err.empty()) << err;
  }
  const Coverage& c = model.coverage();
  RecordProperty("components", static_cast<int>(model.components()));
  RecordProperty("machines", static_cast<int>(model.machines()));
  RecordProperty("connections", static_cast<int>(model.connections()));
  RecordProperty("cyclic", model.cyclic() ? 1 : 0);
  RecordProperty("machine_transitions", c.machine_transitions);
  RecordProperty("max_conditions", static_cast<int>(c.max_conditions));
  RecordProperty("error_mirror_checks", c.error_mirrors);
  RecordProperty("warning_mirror_checks", c.warning_mirrors);
  RecordProperty("explained_mirrors", c.explained_mirrors);
  RecordProperty("late_connections", c.late_connections);
  for (const auto& [outcome, n] : c.outcomes) RecordProperty("outcome_" + std::string(to_string(outcome)), n);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomModelTest, ::testing::Range<std::uint64_t>(1, kSeeds + 1),
                         [](const ::testing::TestParamInfo<std::uint64_t>& param) {
                           return "Seed" + std::to_string(param.param);
                         });

TEST(RandomModelCoverage, MostRandomGraphsContainACycleOfConnections) {
  int cyclic = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    RandomModel model(seed);
    ASSERT_TRUE(model.build().empty());
    if (model.cyclic()) ++cyclic;
  }
  EXPECT_GE(cyclic, static_cast<int>(kSeeds) / 2) << "only " << cyclic << " of " << kSeeds << " graphs have a cycle";
}

}  // namespace
}  // namespace safecass
