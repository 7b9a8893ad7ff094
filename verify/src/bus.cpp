#include "safecass/verify/bus.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include "spin.hpp"

namespace safecass::verify {

/// verify/bus/bus.pml, embedded at build time (bus_model.cpp.in).
extern const char* const kBusModel;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The model's constants that come from the protocol's code rather than from the deployment:
/// middleware/src/node.cpp (resync spacing 3 periods), ice_util.hpp (kResubscribeCheckEvery),
/// receiver.cpp (the Prover's 1 s question timeout).
constexpr int kResyncPeriods = 3;
constexpr std::chrono::milliseconds kProofTimeout{1000};
constexpr int kTicksPerPeriod = 2;
constexpr int kResubscribePeriods = kBusResubscribeTicks / kTicksPerPeriod;
static_assert(kBusResubscribeTicks % kTicksPerPeriod == 0, "a subscription round is whole periods");
/// Stream numbers this far behind P's latest compare equal (docs/verify.md "The bus").
constexpr int kStreamCap = 4;
// The receiver's wait at the model's scale outlasts any wait for a provider that settles in time.
static_assert(kBusSettleLimitTicks >= kBusSettleTicks + 3 * kTicksPerPeriod, "a provider that settles in time is held");
/// The largest loss bound the model takes, in ticks: beyond it the search outgrows its memory.
constexpr int kMaxBoundTicks = 24;

std::string ms_text(std::chrono::milliseconds ms) { return std::to_string(ms.count()) + " ms"; }

[[nodiscard]] Expected<int> ticks_of(std::chrono::milliseconds bound, std::chrono::milliseconds period,
                                     const std::string& what) {
  const auto tick = period.count() / kTicksPerPeriod;
  if (period.count() <= 0 || period.count() % kTicksPerPeriod != 0) {
    return fail(ErrorCode::InvalidArgument,
                "the heartbeat period (" + ms_text(period) + ") must be an even number of ms");
  }
  if (bound.count() <= 0 || bound.count() % tick != 0) {
    return fail(
        ErrorCode::InvalidArgument,
        what + " (" + ms_text(bound) + ") must be a whole number of half periods (" + std::to_string(tick) + " ms)");
  }
  const auto ticks = bound.count() / tick;
  if (ticks < kTicksPerPeriod + 2 || ticks > kMaxBoundTicks) {
    return fail(ErrorCode::InvalidArgument, what + " (" + ms_text(bound) + ") must be between " +
                                                std::to_string(kTicksPerPeriod + 2) + " and " +
                                                std::to_string(kMaxBoundTicks) + " half periods for the model");
  }
  return static_cast<int>(ticks);
}

int proof_ticks(std::chrono::milliseconds period) {
  const auto tick = period.count() / kTicksPerPeriod;
  return static_cast<int>((kProofTimeout.count() + tick - 1) / tick);
}

/// Periods of calm after which every view must equal the truth (P5): a subscription round, a
/// loss bound, the provider's settling and three periods (a proof, a resync, a heartbeat).
int calm_periods(const BusPattern& p) {
  return (kBusResubscribeTicks + p.bound_ticks + kBusSettleTicks + 3 * kTicksPerPeriod + kTicksPerPeriod - 1) /
         kTicksPerPeriod;
}

const char* const kPropertyNames[] = {"P1", "P2", "P3", "P4", "P5"};
const char* const kPropertyTokens[] = {"P1_fail_safe_bound", "P2_no_false_recovery", "P3_no_false_normal",
                                       "P4_ownership", "P5_convergence"};

std::vector<BusProperty> property_list(const std::vector<BusPattern>& patterns, const BusOptions& options) {
  int calm = 0;
  for (const BusPattern& p : patterns) {
    calm = std::max(calm, calm_periods(p));
  }
  const auto tick = options.period / kTicksPerPeriod;
  const std::string b = "its loss bound plus one period";
  return {
      {"P1",
       "fail-safe bound: a provider dead, cut off or unsubscribed for longer than " + b +
           " is lost at every receiver it feeds (its interfaces at Error)",
       {},
       0,
       0.0,
       0.0},
      {"P2",
       "no false recovery: a receiver leaves a loss only on a proof of life, asked after the loss began, "
       "from the incarnation it then believes",
       {},
       0,
       0.0,
       0.0},
      {"P3",
       "no false Normal: a receiver never shows Normal for a stream whose provider has been at Error for "
       "longer than " +
           b,
       {},
       0,
       0.0,
       0.0},
      {"P4",
       "ownership: a receiver holds of a stream only levels its provider sent on it, whatever another member "
       "sends",
       {},
       0,
       0.0,
       0.0},
      {"P5",
       "convergence without flapping: " + std::to_string(calm) + " periods (" + ms_text(calm * 2 * tick) +
           ") after the last fault, every view equals the provider's state; on the way a receiver loses the "
           "provider at most once and shows each stream change level at most once (once more only when the "
           "provider, held all along, settled losses of its own)",
       {},
       0,
       0.0,
       0.0},
  };
}

/// The property a violated assertion names (pan's report quotes the assertion).
std::string violated_property(const std::string& pan_output) {
  for (std::size_t i = 0; i < std::size(kPropertyTokens); ++i) {
    if (pan_output.find(kPropertyTokens[i]) != std::string::npos) return kPropertyNames[i];
  }
  return "an assertion";
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string x; in >> x;) w.push_back(x);
  return w;
}

std::string number_text(const std::string& relative) {
  // A stream number, as the model keeps it: distance below the provider's latest, plus one.
  if (relative == "255") return "#0 (none yet)";
  if (relative == "0") return "a number far ahead of its latest";
  if (relative == "1") return "its latest";
  return std::to_string(std::stoi(relative) - 1) + " behind its latest";
}

std::string level_text(const std::string& l) { return l == "0" ? "Normal" : l == "1" ? "Warning" : "Error"; }

/// A violation's "@ ..." lines as sentences, with the time of each tick.
std::vector<std::string> trace_text(const std::vector<std::string>& lines, const BusOptions& options) {
  const long tick_ms = options.period.count() / kTicksPerPeriod;
  std::vector<std::string> out;
  long tick = 0;
  std::string pending;  // the message a verdict ("v ...") completes
  const auto say = [&](const std::string& what) { out.push_back(std::to_string(tick * tick_ms) + " ms: " + what); };
  for (const std::string& line : lines) {
    const auto w = words(line);
    if (w.empty()) continue;
    const std::string& k = w[0];
    if (k == "tick") {
      ++tick;
    } else if (k == "v" && w.size() > 1) {
      say(pending + " -> " + w[1]);
    } else if (k == "hb" && w.size() >= 5) {
      pending = "R receives a heartbeat of P's incarnation " + w[1] + " sent " +
                std::to_string(std::stol(w[2]) * tick_ms) + " ms ago, listing stream 0 at " + number_text(w[3]) +
                (w.size() >= 6 && w[5] == "1" ? ", P settling" : "");
    } else if (k == "st" && w.size() >= 6) {
      pending = std::string("R receives a state update signed by ") + (w[1] == "0" ? "P" : "another member") +
                " for P's incarnation " + w[2] + ", stream " + w[3] + " at " + number_text(w[4]) + ": " +
                level_text(w[5]);
    } else if (k == "proof" && w.size() >= 4) {
      pending = "P (incarnation " + w[1] + ") answers R's question asked " + std::to_string(std::stol(w[3]) * tick_ms) +
                " ms ago" + (w.size() >= 5 && w[4] == "1" ? ", P settling" : "");
    } else if (k == "pub" && w.size() >= 3) {
      say("P publishes stream " + w[1] + ": " + level_text(w[2]));
    } else if (k == "beat") {
      say("P sends its heartbeat");
    } else if (k == "late") {
      say("  (what P sends now is delivered late)");
    } else if (k == "drop") {
      say("  (what P sends now is lost)");
    } else if (k == "flip" && w.size() >= 2) {
      say("P's stream " + w[1] + " changes level");
    } else if (k == "crash") {
      say("P crashes");
    } else if (k == "pstart" && w.size() >= 2) {
      say("P starts as incarnation " + w[1] + (w[1] == "9" ? " (its clock far ahead)" : ""));
    } else if (k == "rstart") {
      say("R restarts");
    } else if (k == "cut") {
      say("P is cut off the network");
    } else if (k == "heal") {
      say("the network heals");
    } else if (k == "settling") {
      say("P, cut off, loses its own peers: it is settling (Heartbeat::settling), its Normal streams at Warning");
    } else if (k == "settled") {
      say("P hears its own peers again: settled, its streams back to Normal");
    } else if (k == "unsub" && w.size() >= 2) {
      say(std::string("a member unsubscribes R from P's ") + (w[1] == "hb" ? "heartbeats" : "state"));
    } else if (k == "take" && w.size() >= 2) {
      say(std::string("a member takes R's subscription to P's ") + (w[1] == "hb" ? "heartbeats" : "state") +
          " (IceStorm still holds it, delivering to the member)");
    } else if (k == "broker") {
      say("the broker restarts: messages in flight and subscriptions are gone");
    } else if (k == "replay" && w.size() >= 2) {
      say(std::string("a member replays P's ") + (w[1] == "hb" ? "heartbeat" : "state update") + " it recorded");
    } else if (k == "forge") {
      say("another member sends a state update of P's stream 0, signed as itself");
    } else if (k == "wild") {
      say("P sends an update numbered far ahead (its own fault)");
    } else if (k == "ask") {
      say("R asks P for a proof of life");
    } else if (k == "noanswer") {
      say("R's question times out");
    } else if (k == "resync") {
      say("R asks P to republish");
    } else if (k == "lost") {
      say("R declares P lost");
    } else if (k == "recovered") {
      say("R clears P's loss");
    } else if (k == "resubscribed") {
      say("R's subscription round subscribes it again");
    } else if (k == "renew") {
      say("R, still holding P lost a round on, subscribes again under new identities");
    }
  }
  return out;
}

/// A violation the depth-first search found: its property and trace, taken from the breadth-first
/// search of the same model (a shortest trail, and the property it breaks first) unless the
/// options keep the first search's.
[[nodiscard]] Expected<void> tell_violation(BusSearch& search, const PanResult& found, const std::string& dir,
                                            const std::string& model, const PanOptions& pan,
                                            const BusOptions& options) {
  const auto tell = [&](const PanResult& r) {
    search.property = violated_property(r.output);
    search.trace = trace_text(r.trail, options);
  };
  if (!options.shortest_trail) {
    tell(found);
    return {};
  }
  PanOptions bfs = pan;
  bfs.shortest = true;
  auto shortest = compile(dir, "bus", model, bfs);
  if (!shortest) return tl::unexpected(shortest.error());
  auto again = check_claim(dir, "bus", *shortest, {}, bfs);
  if (!again) return tl::unexpected(again.error());
  tell(again->outcome == PanResult::Outcome::Violated ? *again : found);
  return {};
}

}  // namespace

std::string BusPattern::name() const {
  std::string r = forget ? "the supervisor's heartbeats" : std::to_string(streams_total) + " stream(s)";
  r += ", loss bound " + std::to_string(bound_ticks) + " ticks";
  r += loss_level == State::Warning ? ", lost shows Warning" : ", lost shows Error";
  return r;
}

int BusReport::exit_code() const {
  bool undecided = false;
  for (const BusProperty& p : properties) {
    if (p.verdict == BusVerdict::Violated) return 1;
    undecided = undecided || p.verdict == BusVerdict::Undecided;
  }
  return undecided ? 3 : 0;
}

std::string_view to_string(BusVerdict verdict) noexcept {
  switch (verdict) {
    case BusVerdict::Holds: return "holds";
    case BusVerdict::Violated: return "VIOLATED";
    case BusVerdict::Undecided: return "undecided";
  }
  return "?";
}

const std::vector<BusFaultClass>& bus_fault_classes() {
  // Each class is searched exhaustively: its faults at every time, in every order, with the
  // network delaying anything by up to half a period. The classes are chosen so that every
  // property meets every attack that could break it (docs/verify.md "The bus").
  static const std::vector<BusFaultClass> classes = [] {
    std::vector<BusFaultClass> c(8);
    c[0].name = "restarts";
    c[0].text = "the provider crashes and restarts, the receiver restarts, a level changes, a message is lost";
    c[0].crash = c[0].flip = c[0].receiver_restart = c[0].drop = 1;
    c[1].name = "cut";
    c[1].text = "the provider is cut off and the network heals, a level changes, a member replays, a message is lost";
    c[1].cut = c[1].flip = c[1].replay = c[1].drop = 1;
    c[2].name = "unsubscribed";
    c[2].text = "a member unsubscribes the receiver from a topic, a level changes, a member replays or relays";
    c[2].unsubscribe = c[2].flip = c[2].replay = 1;
    c[3].name = "broker";
    c[3].text = "the broker restarts (messages and subscriptions gone), a level changes, a message is lost";
    c[3].broker = c[3].flip = c[3].drop = 1;
    c[4].name = "members";
    c[4].text =
        "another member forges an update as itself; the provider numbers an update far ahead or starts "
        "with its clock far ahead; it crashes; a level changes";
    c[4].forge = c[4].wild = c[4].crash = c[4].flip = 1;
    c[5].name = "dead-replay";
    c[5].text = "the provider dies and a member replays what it recorded of it, twice";
    c[5].crash = 1;
    c[5].replay = 2;
    c[6].name = "two-streams";
    c[6].text = "two streams change level, two messages are lost";
    c[6].flip = c[6].drop = 2;
    c[6].two_streams = true;
    c[7].name = "settle";
    c[7].text =
        "the provider is cut off and loses its own peers (its state at Warning), the network heals and it "
        "hears them again, a message is lost";
    c[7].cut = c[7].settle = c[7].drop = 1;
    return c;
  }();
  return classes;
}

const std::vector<BusMutant>& bus_mutants() {
  static const std::vector<BusMutant> mutants = {
      {"unproven-heartbeat", "believe a heartbeat of a process not proven alive", "M_UNPROVEN"},
      {"no-catch-up", "skip the catch-up rule (a stream a heartbeat shows ahead never makes a loss)", "M_NOCATCHUP"},
      {"no-jump-limit", "drop the jump limit on stream numbers", "M_NOJUMP"},
      {"no-incarnation-bound", "forget the incarnation bound (an incarnation far ahead is believed)", "M_NOINCBOUND"},
      {"no-resubscribe", "never make a lost subscription again (no round, no renewal on a loss)", "M_NORESUB"},
      {"no-renewal-while-lost",
       "renew the subscriptions to a lost provider only as the loss begins, never while it lasts (a newcomer: never)",
       "M_NORENEW"},
      {"no-ownership", "take a state update from any member", "M_NOOWNER"},
      {"no-reproof", "clear a loss on heartbeats of the process believed, without a new proof", "M_NOREPROOF"},
      {"arrival-time", "count a heartbeat as fresh when it arrives, not when it was sent", "M_ARRIVAL"},
      {"no-settle-hold", "clear a loss while the provider still settles its own (Heartbeat::settling ignored)",
       "M_NOSETTLE"},
  };
  return mutants;
}

[[nodiscard]] Expected<std::vector<BusPattern>> bus_patterns(const spec::SystemSpec& system,
                                                             const BusOptions& options) {
  const std::chrono::milliseconds coordinator_bound =
      options.lost_after.count() > 0 ? options.lost_after : 3 * options.period;
  auto coordinator_ticks = ticks_of(coordinator_bound, options.period, "the coordinators' loss bound");
  if (!coordinator_ticks) return tl::unexpected(coordinator_ticks.error());
  Expected<int> supervisor_ticks = 0;
  if (options.supervisor) {
    supervisor_ticks = ticks_of(options.supervisor_lost_after, options.period, "the supervisor's loss bound");
    if (!supervisor_ticks) return tl::unexpected(supervisor_ticks.error());
  }
  std::map<std::string, std::string> owner;  // component -> coordinator
  for (const auto& [coordinator, components] : system.coordinators) {
    for (const std::string& c : components) owner[c] = coordinator;
  }
  const auto component_of = [](const std::string& address) { return address.substr(0, address.find('.')); };
  std::vector<BusPattern> patterns;
  const auto add = [&](const std::string& pair, std::size_t streams, int bound, bool watch, bool forget, State lost) {
    const std::size_t modelled = std::min<std::size_t>(streams, 2);
    for (BusPattern& p : patterns) {
      if (p.streams == modelled && p.bound_ticks == bound && p.watch_start == watch && p.forget == forget &&
          p.loss_level == lost) {
        p.pairs.push_back(pair);
        p.streams_total = std::max(p.streams_total, streams);
        return;
      }
    }
    BusPattern p;
    p.streams = modelled;
    p.streams_total = streams;
    p.bound_ticks = bound;
    p.watch_start = watch;
    p.forget = forget;
    p.loss_level = lost;
    p.pairs.push_back(pair);
    patterns.push_back(std::move(p));
  };
  // A coordinator feeding another: the interfaces the client requires of it.
  std::vector<std::string> names;
  for (const auto& entry : system.coordinators) names.push_back(entry.first);
  for (const std::string& provider : names) {
    for (const std::string& client : names) {
      if (provider == client) continue;
      std::set<std::string> held;
      for (const spec::ConnectionSpec& c : system.connections) {
        const auto p = owner.find(component_of(c.provided));
        const auto r = owner.find(component_of(c.required));
        if (p != owner.end() && r != owner.end() && p->second == provider && r->second == client)
          held.insert(c.provided);
      }
      if (!held.empty()) add(provider + " -> " + client, held.size(), *coordinator_ticks, true, false, State::Error);
    }
  }
  if (options.supervisor) {
    for (const auto& [coordinator, components] : system.coordinators) {
      std::size_t provided = 0;
      for (const spec::ComponentSpec& c : system.components) {
        const auto o = owner.find(c.name);
        if (o != owner.end() && o->second == coordinator) provided += c.provided.size();
      }
      add(coordinator + " -> supervisor", provided, *supervisor_ticks, true, false, State::Error);
    }
    for (const std::string& coordinator : names) {
      add("supervisor -> " + coordinator, 0, *coordinator_ticks, false, true, State::Warning);
    }
  }
  return patterns;
}

std::string bus_promela(const BusPattern& pattern, const BusFaultClass& faults, const BusOptions& options,
                        const std::string& mutant) {
  std::ostringstream h;
  const int streams = faults.two_streams ? 2 : static_cast<int>(std::min<std::size_t>(pattern.streams, 1));
  h << "/* " << pattern.name() << "; fault class '" << faults.name << "' */\n";
  const auto def = [&](const char* name, long value) { h << "#define " << name << " " << value << "\n"; };
  def("S", streams);
  def("HB", kTicksPerPeriod);
  def("B", pattern.bound_ticks);
  def("D", 1);
  def("RS", long{kResyncPeriods} * kTicksPerPeriod);
  def("RESUB", kBusResubscribeTicks);
  def("QT", proof_ticks(options.period));
  def("CAPS", kStreamCap);
  def("K", calm_periods(pattern));
  def("PS", kBusSettleTicks);
  def("SL", kBusSettleLimitTicks);
  def("WATCH_START", pattern.watch_start ? 1 : 0);
  def("FORGET", pattern.forget ? 1 : 0);
  def("LOSS_LEVEL", static_cast<int>(pattern.loss_level));
  def("B_CRASH", faults.crash);
  def("B_CUT", faults.cut);
  def("B_UNSUB", faults.unsubscribe);
  def("B_BROKER", faults.broker);
  def("B_FLIP", faults.flip);
  def("B_REPLAY", faults.replay);
  def("B_FORGE", faults.forge);
  def("B_WILD", faults.wild);
  def("B_RRESTART", faults.receiver_restart);
  def("B_DROP", faults.drop);
  def("B_SETTLE", faults.settle);
  if (!mutant.empty()) h << "#define " << mutant << "\n";
  return h.str() + kBusModel;
}

[[nodiscard]] Expected<BusReport> verify_bus(const spec::SystemSpec& system, const BusOptions& options) {
  const auto start = Clock::now();
  std::string mutant;
  if (!options.mutant.empty()) {
    const auto& all = bus_mutants();
    const auto it = std::find_if(all.begin(), all.end(), [&](const BusMutant& m) { return m.name == options.mutant; });
    if (it == all.end()) {
      std::string names;
      for (const BusMutant& m : all) names += (names.empty() ? "" : ", ") + m.name;
      return fail(ErrorCode::NotFound, "no mutant '" + options.mutant + "' (there are: " + names + ")");
    }
    mutant = it->macro;
  }
  std::vector<const BusFaultClass*> classes;
  for (const BusFaultClass& c : bus_fault_classes()) {
    if (options.fault_class.empty() || c.name == options.fault_class) classes.push_back(&c);
  }
  if (classes.empty()) return fail(ErrorCode::NotFound, "no fault class '" + options.fault_class + "'");
  if (auto v = spin_version(options.spin); !v) return tl::unexpected(v.error());
  if (auto c = compiler_check(options.cc); !c) return tl::unexpected(c.error());
  auto patterns = bus_patterns(system, options);
  if (!patterns) return tl::unexpected(patterns.error());
  auto dir = WorkDir::create(options.work_dir);
  if (!dir) return tl::unexpected(dir.error());

  BusReport report;
  report.system = system.name;
  report.patterns = *patterns;
  report.properties = property_list(report.patterns, options);
  const auto tick = options.period / kTicksPerPeriod;
  report.bounds = "tick " + ms_text(tick) + " (half a heartbeat period of " + ms_text(options.period) +
                  "); network delay up to one tick; proof timeout " + ms_text(kProofTimeout) + "; resync spacing " +
                  std::to_string(kResyncPeriods) + " periods; subscription round every " +
                  std::to_string(kResubscribePeriods) + " periods; at most 2 messages in flight per topic";
  PanOptions pan_base;
  pan_base.memory_mb = options.memory_mb;
  // Depth-first finds the verdict fastest; a violation is searched again for its shortest trail.
  pan_base.shortest = false;
  pan_base.spin = options.spin;
  pan_base.cc = options.cc;
  struct Job {
    std::size_t pattern;
    BusFaultClass faults;
    std::size_t same_as = SIZE_MAX;  ///< an earlier job with the same model: its result is this one's
  };
  std::vector<Job> jobs;
  std::map<std::string, std::size_t> models;  // a model's text without its title -> its first job
  for (std::size_t pi = 0; pi < report.patterns.size(); ++pi) {
    const BusPattern& pattern = report.patterns[pi];
    for (const BusFaultClass* faults : classes) {
      if (faults->two_streams && pattern.streams < 2) continue;
      const std::string model = bus_promela(pattern, *faults, options, mutant);
      const auto [it, fresh] = models.emplace(model.substr(model.find('\n')), jobs.size());
      jobs.push_back({pi, *faults, fresh ? SIZE_MAX : it->second});
    }
  }
  // Two searches at a time, each in a directory of its own (SPIN writes pan.c where it runs).
  const auto run = [&](const Job& job, std::size_t index) -> Expected<BusSearch> {
    const auto t0 = Clock::now();
    BusSearch search;
    search.pattern = job.pattern;
    search.fault_class = job.faults.name;
    const std::string sub = dir->path() + "/search" + std::to_string(index);
    std::error_code ec;
    std::filesystem::create_directory(sub, ec);
    if (ec) return fail(ErrorCode::Io, "cannot create '" + sub + "': " + ec.message());
    const std::string model = bus_promela(report.patterns[job.pattern], job.faults, options, mutant);
    // A pattern that holds no stream is searched in about 0.3 s: its verifier is not worth
    // optimising (1 s more of compilation), and its states (at most a few hundred thousand) fit a
    // table of 2^20 slots, where clearing one of 2^24 took longer than the search (0.63 s against
    // 0.22 s for robodoc's ui -> supervisor). A pattern with streams runs seconds over millions of
    // states: -O1 repays its compilation, and 2^24 slots searched fastest of 2^22, 2^24 and 2^26.
    const bool streams = report.patterns[job.pattern].streams > 0;
    PanOptions pan = pan_base;
    pan.optimise = streams;
    pan.hash_bits = streams ? 24 : 20;
    auto binary = compile(sub, "bus", model, pan);
    if (!binary) return tl::unexpected(binary.error());
    auto r = check_claim(sub, "bus", *binary, {}, pan);
    if (!r) return tl::unexpected(r.error());
    search.states = r->states;
    search.memory_mb = r->memory_mb;
    switch (r->outcome) {
      case PanResult::Outcome::Holds: search.verdict = BusVerdict::Holds; break;
      case PanResult::Outcome::Violated: {
        search.verdict = BusVerdict::Violated;
        if (auto told = tell_violation(search, *r, sub, model, pan, options); !told)
          return tl::unexpected(told.error());
        break;
      }
      case PanResult::Outcome::MemoryLimit:
        search.verdict = BusVerdict::Undecided;
        search.detail = "the search reached its bounds (" + std::to_string(options.memory_mb) + " MB of memory)";
        break;
      case PanResult::Outcome::Failed:
        search.verdict = BusVerdict::Undecided;
        search.detail = "SPIN's verifier failed:\n" + r->output;
        break;
    }
    search.seconds = since(t0);
    return search;
  };
  std::vector<std::optional<Expected<BusSearch>>> done(jobs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  const auto worker = [&] {
    for (std::size_t i = next++; i < jobs.size() && !stop; i = next++) {
      if (jobs[i].same_as != SIZE_MAX) continue;  // searched already, as another pattern's
      done[i] = run(jobs[i], i);
      if (options.first_violation && *done[i] && (*done[i])->verdict == BusVerdict::Violated) stop = true;
    }
  };
  {
    std::thread second(worker);
    worker();
    second.join();
  }
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const bool shared = jobs[i].same_as != SIZE_MAX;
    const auto& result = done[shared ? jobs[i].same_as : i];
    if (!result) continue;  // not searched: an earlier one found a violation (first_violation)
    if (!*result) return tl::unexpected(result->error());
    BusSearch search = **result;
    search.pattern = jobs[i].pattern;
    if (shared) {
      search.detail = "the same model as pattern " + std::to_string(done[jobs[i].same_as].value()->pattern + 1) +
                      "'s: searched once";
      report.searches.push_back(std::move(search));
      continue;
    }
    for (BusProperty& p : report.properties) {
      p.states += search.states;
      p.memory_mb = std::max(p.memory_mb, search.memory_mb);
      p.seconds += search.seconds;
      if (search.verdict == BusVerdict::Violated && search.property == p.name) {
        p.verdict = BusVerdict::Violated;
      } else if (search.verdict != BusVerdict::Holds && p.verdict == BusVerdict::Holds) {
        // A search stopped by another property's violation, or by its bounds, did not check this one.
        p.verdict = BusVerdict::Undecided;
      }
    }
    report.searches.push_back(std::move(search));
  }
  report.seconds = since(start);
  return report;
}

[[nodiscard]] Expected<void> simulate_bus(const BusPattern& pattern, const BusFaultClass& faults, unsigned runs,
                                          std::size_t steps, const BusOptions& options, const SimulationRun& each) {
  if (auto v = spin_version(options.spin); !v) return tl::unexpected(v.error());
  auto dir = WorkDir::create(options.work_dir);
  if (!dir) return tl::unexpected(dir.error());
  // Numbers counted far enough that a run never reaches the caps: the conformance test reads every
  // message's number exactly.
  std::string model = bus_promela(pattern, faults, options);
  const std::string caps = "#define CAPS " + std::to_string(kStreamCap) + "\n";
  model.replace(model.find(caps), caps.size(), "#define CAPS 250\n#define CAPH 250\n");
  return simulate_model(dir->path(), model, 1, runs, steps, options.spin, options.cc, each);
}

}  // namespace safecass::verify
