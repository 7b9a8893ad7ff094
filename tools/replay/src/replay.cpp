// `safecass replay`: a log fed through a system in simulated time, and --diff of two systems.

#include "safecass/replay/replay.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <unordered_map>

#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/json/write.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/replay/source.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/instance.hpp"

#include "safecass/replay/rosbag1_source.hpp"
#ifdef SAFECASS_REPLAY_WITH_ROSBAG2
#include "safecass/replay/rosbag2_source.hpp"
#endif

namespace safecass::replay {

namespace {

using runner::ScenarioRunner;

std::string secs(Time t) { return seconds_text(t); }

/// The format of a log from its first bytes: a recording's header, a bag's "#ROSBAG", SQLite's
/// header or a directory (a ROS 2 bag), else CSV.
std::string sniff(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return "rosbag2";
  char head[16] = {};
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";  // open_input() says why it cannot be read
  const ssize_t n = ::read(fd, head, sizeof head);
  ::close(fd);
  const std::string_view h(head, n > 0 ? static_cast<std::size_t>(n) : 0);
  if (h.substr(0, input_log::kMagic.size()) == input_log::kMagic) return "recording";
  if (h.substr(0, 7) == "#ROSBAG") return "bag";
  if (h.substr(0, 16) == std::string_view("SQLite format 3\0", 16)) return "rosbag2";
  return "csv";
}

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_input(const ReplayOptions& o, const std::string& format) {
  if (format.empty()) {
    const int fd = ::open(o.input.c_str(), O_RDONLY | O_CLOEXEC);
    const int error = errno;
    if (fd >= 0) ::close(fd);
    return fail(ErrorCode::Io, "cannot read log '" + o.input + "': " + std::strerror(fd >= 0 ? EIO : error));
  }
  if (format == "recording") {
    auto reader = InputLogReader::open(o.input);
    if (!reader) return tl::unexpected(reader.error());
    return open_recording(std::move(*reader));
  }
  if (format == "csv") return open_csv(o.input);
  if (format == "bag") {
    if (o.mapping.empty()) {
      return fail(ErrorCode::InvalidArgument,
                  o.input + ": a ROS bag needs the ROS extension's mapping file (--mapping FILE)");
    }
    return open_rosbag1(o.input, o.mapping);
  }
  if (format == "rosbag2") {
#ifdef SAFECASS_REPLAY_WITH_ROSBAG2
    if (o.mapping.empty()) {
      return fail(ErrorCode::InvalidArgument,
                  o.input + ": a ROS 2 bag needs the ROS extensions' mapping file (--mapping FILE)");
    }
    return open_rosbag2(o.input, o.mapping);
#else
    return fail(ErrorCode::InvalidArgument,
                o.input + ": a ROS 2 bag needs SQLite, and this safecass was built without it (libsqlite3-dev)");
#endif
  }
  return fail(ErrorCode::InvalidArgument, "unknown log format '" + format + "' (recording, csv, bag or rosbag2)");
}

/// The system, composed as `safecass run` composes it, with no scenario steps.
std::unique_ptr<ScenarioRunner> open_system(const std::string& path, std::optional<Time> period,
                                            const std::string& input, const FilterRegistry& registry, std::FILE* err) {
  auto system = spec::load_valid_system(path, registry);
  if (!system) {
    spec::print(system.error(), err);
    return nullptr;
  }
  spec::Scenario sc;
  sc.path = input;
  sc.system = path;
  if (period) {
    sc.period = to_seconds(*period);
  } else {
    double smallest = 0.0;
    for (const spec::ComponentSpec& c : system->components) {
      if (c.period && (smallest == 0.0 || *c.period < smallest)) smallest = *c.period;
    }
    sc.period = smallest > 0.0 ? smallest : 0.001;
  }
  auto opened = ScenarioRunner::open(std::move(sc), std::move(*system), registry);
  if (!opened) {
    spec::print(opened.error(), err);
    return nullptr;
  }
  return std::move(*opened);
}

/// Applies `a` to the runner's system as every tool does (introspect::apply), recorded by the
/// runner's input recorder when it has one.
void apply_action(ScenarioRunner& r, const introspect::Action& a, Time now) {
  (void)introspect::apply(a, r.coordinator(), r.monitor(), now, r.input_recorder());  // checked by check_log
}

struct Window {
  Time from = Time::min();
  Time to = Time::max();
};

/// What the first pass learns of the inputs in the window: the first and the last one's time
/// (nullopt for none) and the recorded run's last tick, when the log says.
struct LogSpan {
  std::optional<Time> first;
  std::optional<Time> last;
  std::optional<Time> end;
};

/// The first pass: reads the whole log, checking what the source checks and every action.
/// Fills `span`; false on error.
bool check_log(InputSource& src, ScenarioRunner& r, const Window& w, LogSpan& span, std::FILE* err) {
  for (;;) {
    const InputItem item = src.next();
    switch (item.kind) {
      case InputItem::Kind::End: span.end = src.end(); return true;
      case InputItem::Kind::Error: std::fprintf(err, "%s\n", src.error().c_str()); return false;
      case InputItem::Kind::Action:
        if (auto ok = introspect::check(*item.action, r.coordinator(), r.monitor()); !ok) {
          std::fprintf(err, "%s: action at t=%s: %s\n", src.where().c_str(), secs(item.time).c_str(),
                       ok.error().message.c_str());
          return false;
        }
        [[fallthrough]];
      case InputItem::Kind::Sample:
        if (item.time >= w.from && item.time <= w.to) {
          if (!span.first) span.first = item.time;
          span.last = item.time;
        }
        break;
    }
  }
}

/// Opens, binds and checks the log against `r`; then opens it again, bound, for feeding.
std::unique_ptr<InputSource> prepare_log(const ReplayOptions& o, const std::string& format, ScenarioRunner& r,
                                         const Window& w, LogSpan& span) {
  auto check = open_input(o, format);
  if (!check) {
    std::fprintf(o.err, "%s\n", check.error().message.c_str());
    return nullptr;
  }
  if (auto b = (*check)->bind(r.monitor()); !b) {
    std::fprintf(o.err, "%s\n", b.error().message.c_str());
    return nullptr;
  }
  if (!check_log(**check, r, w, span, o.err)) return nullptr;
  auto feed = open_input(o, format);
  if (!feed) {
    std::fprintf(o.err, "%s\n", feed.error().message.c_str());
    return nullptr;
  }
  if (auto b = (*feed)->bind(r.monitor()); !b) {
    std::fprintf(o.err, "%s\n", b.error().message.c_str());
    return nullptr;
  }
  return std::move(*feed);
}

Window window_of(const ReplayOptions& o) {
  Window w;
  if (o.from) w.from = seconds_to_time(*o.from);
  if (o.to) w.to = seconds_to_time(*o.to);
  return w;
}

/// Feeds a log into one or two systems tick by tick.
class Feeder {
public:
  Feeder(InputSource& src, Window w) : src_(src), w_(w) { pending_ = src_.next(); }

  /// Applies every input due at `now` to `a` and, when given, to `b` (with `map` from a's signals).
  void feed(Time now, ScenarioRunner& a, ScenarioRunner* b, const std::unordered_map<const Signal*, Signal*>* map) {
    while (!done_) {
      if (pending_.kind == InputItem::Kind::End || pending_.kind == InputItem::Kind::Error) {
        done_ = true;
        failed_ = pending_.kind == InputItem::Kind::Error;
        break;
      }
      if (pending_.time > now) break;
      if (pending_.time > w_.to) {
        done_ = true;
        break;
      }
      if (pending_.time >= w_.from) {
        if (pending_.kind == InputItem::Kind::Sample) {
          pending_.signal->push(pending_.time, pending_.values);
          if (b != nullptr) map->at(pending_.signal)->push(pending_.time, pending_.values);
          ++fed_;
        } else {
          apply_action(a, *pending_.action, now);
          if (b != nullptr) {
            b->clock().set(now);
            apply_action(*b, *pending_.action, now);
          }
          ++actions_;
        }
        last_ = pending_.time;
      }
      pending_ = src_.next();
    }
  }
  bool done() const noexcept { return done_; }
  bool failed() const noexcept { return failed_; }
  std::optional<Time> last() const noexcept { return last_; }
  std::uint64_t fed() const noexcept { return fed_; }
  std::uint64_t actions() const noexcept { return actions_; }

private:
  InputSource& src_;
  Window w_;
  InputItem pending_;
  bool done_ = false;
  bool failed_ = false;
  std::optional<Time> last_;
  std::uint64_t fed_ = 0;
  std::uint64_t actions_ = 0;
};

/// The replay's first tick: the recording's start, else the first input, never before --from.
Time start_of(const InputSource& src, const std::optional<Time>& first, const Window& w) {
  Time start = src.start().value_or(first.value_or(Time{0}));
  if (first && *first < start) start = *first;
  if (w.from != Time::min() && w.from > start) start = w.from;
  return start;
}

/// The replay's last tick: the recording's end, else the last input fed; never after --to.
Time end_of(const InputSource& src, const Feeder& f, const Window& w, Time now) {
  Time end = src.end().value_or(f.last().value_or(now));
  if (end > w.to) end = w.to;
  return end;
}

void print_notes(const InputSource& src, std::FILE* err) {
  for (const std::string& n : src.notes()) std::fprintf(err, "note: %s\n", n.c_str());
}

/// A replay ready to run: the system opened, the log checked and opened again for feeding.
struct Prepared {
  std::unique_ptr<ScenarioRunner> runner;
  std::unique_ptr<InputSource> src;
  Window window;
  LogSpan span;
};

/// Opens `o.system` and checks `o.input` against it; says what is wrong on `o.err` and returns
/// nullopt on bad input.
std::optional<Prepared> prepare(const ReplayOptions& o, const FilterRegistry& registry) {
  const std::string format = o.format.empty() ? sniff(o.input) : o.format;
  // The period: asked for, else the recording's, else the system's smallest component period.
  std::optional<Time> period;
  if (o.period) period = seconds_to_time(*o.period);
  if (!period && format == "recording") {
    if (auto reader = InputLogReader::open(o.input); reader && (*reader)->header().period.count() > 0) {
      period = (*reader)->header().period;
    }
  }
  Prepared p;
  p.runner = open_system(o.system, period, o.input, registry, o.err);
  if (!p.runner) return std::nullopt;
  p.window = window_of(o);
  p.src = prepare_log(o, format, *p.runner, p.window, p.span);
  if (!p.src) return std::nullopt;
  return p;
}

}  // namespace

/// When each hazard was uncovered during a replay: `analyze now` judged after every tick, each
/// interval kept with the gaps that opened it.
class CoverageTimeline {
public:
  void observe(const introspect::CoverageNow& c) {
    for (const introspect::HazardCoverage& h : c.hazards) {
      auto open = std::find_if(intervals_.begin(), intervals_.end(),
                               [&](const Interval& i) { return i.hazard == h.hazard && !i.to; });
      if (h.covered()) {
        if (open != intervals_.end()) open->to = c.now;
        continue;
      }
      if (open != intervals_.end()) continue;
      std::vector<std::string> gaps;
      for (const introspect::CoverageGap& g : h.gaps) gaps.push_back(g.onset + ": " + g.reason);
      intervals_.push_back(Interval{h.hazard, c.now, std::nullopt, introspect::joined(gaps, "; ")});
    }
    if (!c.hazards.empty()) judged_ = true;
  }

  void print(Time end, bool json, std::FILE* out) const {
    if (!json && !judged_) std::fprintf(out, "coverage: no onset names a hazard\n");
    if (!json && judged_ && intervals_.empty()) std::fprintf(out, "coverage: every hazard covered throughout\n");
    for (const Interval& i : intervals_) {
      const std::string until = i.to ? secs(*i.to) : secs(end) + " (the end)";
      if (json) {
        std::fprintf(out, "%s\n",
                     json::JsonObject()
                         .str("kind", "uncovered")
                         .str("hazard", i.hazard)
                         .raw("from", secs(i.from))
                         .raw("to", i.to ? secs(*i.to) : "null")
                         .str("gaps", i.gaps)
                         .text()
                         .c_str());
      } else {
        std::fprintf(out, "coverage: hazard %s uncovered %s .. %s s: %s\n", i.hazard.c_str(), secs(i.from).c_str(),
                     until.c_str(), i.gaps.c_str());
      }
    }
  }

private:
  struct Interval {
    std::string hazard;
    Time from{};
    std::optional<Time> to;  ///< none: still uncovered at the end
    std::string gaps;        ///< what opened it
  };
  std::vector<Interval> intervals_;
  bool judged_ = false;  ///< some onset names a hazard
};

int run_replay(const ReplayOptions& o, const FilterRegistry& registry) {
  std::optional<Prepared> prepared = prepare(o, registry);
  if (!prepared) return 2;
  auto& r = prepared->runner;
  auto& src = prepared->src;
  const Window& w = prepared->window;
  const std::optional<Time>& first = prepared->span.first;

  runner::RunOptions ro;
  ro.json = o.json;
  ro.out = o.out;
  ro.record_path = o.record;
  ro.inputs_path = o.record_inputs;
  ro.limits = o.limits;
  runner::RunResult result;
  r->start_at(start_of(*src, first, w));
  if (!r->begin(ro, result)) {
    for (const std::string& f : result.failures) std::fprintf(o.err, "%s\n", f.c_str());
    return 2;
  }
  Feeder feeder(*src, w);
  ScenarioRunner& sys = *r;
  r->set_feed([&](Time now) { feeder.feed(now, sys, nullptr, nullptr); });
  const Time tick = seconds_to_time(r->scenario().period);
  introspect::LocalQuery query(r->coordinator(), r->monitor(), registry);
  CoverageTimeline coverage;
  auto step = [&](Time to) {
    r->advance_to(to, result);
    if (o.coverage) coverage.observe(query.coverage().value_or(introspect::CoverageNow{}));  // in-process: never fails
  };
  while (!feeder.done()) step(r->now() + tick);
  const Time end = end_of(*src, feeder, w, r->now());
  if (r->now() < end) step(end);
  r->finish(result);
  if (o.coverage) coverage.print(r->now(), o.json, o.out);
  if (feeder.failed()) {
    std::fprintf(o.err, "%s\n", src->error().c_str());  // the log changed between the two passes
    return 2;
  }
  print_notes(*src, o.err);
  std::fprintf(o.err, "%s: replayed %llu samples and %llu actions through %s, %s s to %s s\n", o.input.c_str(),
               static_cast<unsigned long long>(feeder.fed()), static_cast<unsigned long long>(feeder.actions()),
               o.system.c_str(), secs(start_of(*src, first, w)).c_str(), secs(r->now()).c_str());
  int code = 0;
  if (result.inputs) {
    for (const std::string& loss : describe_losses(*result.inputs)) std::fprintf(o.err, "%s\n", loss.c_str());
    if (o.json) std::fprintf(o.out, "%s\n", record_status_json(*result.inputs).c_str());
  }
  if (result.record) {
    for (const std::string& loss : describe_losses(*result.record)) std::fprintf(o.err, "%s\n", loss.c_str());
    if (o.json) std::fprintf(o.out, "%s\n", record_status_json(*result.record).c_str());
  }
  if (!result.history_complete()) code = 2;
  return code;
}

namespace {

/// Every address of a system worth comparing: machines, service states, components, SYSTEM.
std::vector<std::string> addresses_of(const Coordinator& co) {
  const Structure& shape = co.structure();
  std::vector<std::string> out;
  for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
    out.emplace_back(shape.component_name(c));
    out.push_back(shape.address_of(shape.framework_machine(c)));
    out.push_back(shape.address_of(shape.application_machine(c)));
    for (MachineId m : shape.provided_machines(c)) {
      out.push_back(shape.address_of(m));
      out.push_back(address::service(shape.component_name(c), shape.interface_name(m)));
    }
    for (MachineId m : shape.required_machines(c)) out.push_back(shape.address_of(m));
  }
  out.emplace_back("SYSTEM");
  return out;
}

/// The cause of `address`'s state: the outstanding condition at its level (else the first there).
ResolvedRoot cause_of(const Coordinator& co, const Address& a) {
  const State level = co.state_of(a);
  ResolvedRoot c;
  bool found = false;
  for (const Explanation& e : co.explain(a)) {
    if (e.level != level) continue;
    if (found && !e.outstanding) continue;
    c = e.root;
    found = true;
    if (e.outstanding) break;
  }
  return c;
}

std::string cause_text(const ResolvedRoot& c) {
  if (c.event.empty()) return "none";
  std::string out = c.name();
  if (!c.filter.empty() || !c.signal.empty()) {
    const std::string v = number_text(c.value);
    out += " [";
    if (!c.filter.empty()) out += "filter " + c.filter;
    if (!c.signal.empty()) out += std::string(c.filter.empty() ? "" : ", ") + c.signal + " = " + v;
    if (c.injected) out += ", injected";
    out += "]";
  }
  return out;
}

struct Interval {
  Time from{}, to{};
  bool open = true;
  State b = State::Normal, a = State::Normal;
  char side = 'B';
  ResolvedRoot cause;  ///< the first cause of the difference
};

struct Tracked {
  std::string name;
  Address in_b, in_a;
  std::vector<Interval> intervals;
};

}  // namespace

namespace {

/// One interval in which B and A differ at `address`, until `until`: a JSON line (--json) or a
/// text line with its first cause.
void print_interval(const Interval& i, const std::string& address, const std::string& until, const ReplayOptions& o) {
  if (o.json) {
    const ResolvedRoot& c = i.cause;
    json::JsonObject cause;
    cause.str("system", i.side == 'B' ? "B" : "A").str("origin", c.origin).str("event", c.event);
    if (!c.filter.empty()) cause.str("filter", c.filter);
    if (!c.signal.empty()) {
      cause.str("signal", c.signal);
      // JSON has no NaN or infinity: a non-finite value is written as its text ("nan", "inf").
      if (std::isfinite(c.value)) {
        cause.num("value", c.value);
      } else {
        cause.str("value", number_text(c.value));
      }
    }
    const std::string line = json::JsonObject()
                                 .str("kind", "difference")
                                 .str("address", address)
                                 .raw("from", secs(i.from))
                                 .raw("to", until)
                                 .boolean("until_end", i.open)
                                 .str("b", to_string(i.b))
                                 .str("a", to_string(i.a))
                                 .raw("cause", cause.text())
                                 .text();
    std::fprintf(o.out, "%s\n", line.c_str());
  } else {
    std::fprintf(o.out, "  %s .. %s s%s  B %s, A %s  first cause (%c): %s\n", secs(i.from).c_str(), until.c_str(),
                 i.open ? " (to the end)" : "", std::string(to_string(i.b)).c_str(),
                 std::string(to_string(i.a)).c_str(), i.side, cause_text(i.cause).c_str());
  }
}

/// The differences, address by address, the addresses not compared, then the summary; `end`: the
/// time the replay ended (the end of an interval still open). Returns 0 when B and A never
/// differ, 1 when they do.
int print_diff(const std::vector<Tracked>& tracked, const std::vector<std::string>& only, Time end,
               const std::string& system_b, const ReplayOptions& o) {
  std::size_t addresses = 0;
  std::size_t intervals = 0;
  for (const Tracked& t : tracked) {
    if (t.intervals.empty()) continue;
    ++addresses;
    intervals += t.intervals.size();
    if (!o.json) std::fprintf(o.out, "%s\n", t.name.c_str());
    for (const Interval& i : t.intervals) {
      print_interval(i, t.name, i.open ? secs(end) : secs(i.to), o);
    }
  }
  for (const std::string& n : only) std::fprintf(o.err, "note: address %s is not compared\n", n.c_str());
  if (o.json) {
    const std::string line = json::JsonObject()
                                 .str("kind", "diff")
                                 .str("b", system_b)
                                 .str("a", o.system)
                                 .integer("addresses", static_cast<long long>(addresses))
                                 .integer("intervals", static_cast<long long>(intervals))
                                 .boolean("differ", addresses != 0)
                                 .text();
    std::fprintf(o.out, "%s\n", line.c_str());
  } else if (addresses == 0) {
    std::fprintf(o.out, "B (%s) and A (%s) never differ on %s\n", system_b.c_str(), o.system.c_str(), o.input.c_str());
  } else {
    std::fprintf(o.out, "B (%s) and A (%s) differ at %zu address%s in %zu interval%s on %s\n", system_b.c_str(),
                 o.system.c_str(), addresses, addresses == 1 ? "" : "es", intervals, intervals == 1 ? "" : "s",
                 o.input.c_str());
  }
  return addresses == 0 ? 0 : 1;
}

}  // namespace

int run_replay_diff(const std::string& system_b, const ReplayOptions& o, const FilterRegistry& registry) {
  const std::string format = o.format.empty() ? sniff(o.input) : o.format;
  std::optional<Time> period;
  if (o.period) period = seconds_to_time(*o.period);
  if (!period && format == "recording") {
    if (auto reader = InputLogReader::open(o.input); reader && (*reader)->header().period.count() > 0) {
      period = (*reader)->header().period;
    }
  }
  auto a = open_system(o.system, period, o.input, registry, o.err);
  if (!a) return 2;
  auto b = open_system(system_b, seconds_to_time(a->scenario().period), o.input, registry, o.err);
  if (!b) return 2;
  const Window w = window_of(o);
  LogSpan span;
  {  // The log must fit SYSTEM_B too.
    LogSpan unused;
    if (!prepare_log(o, format, *b, w, unused)) return 2;
  }
  auto src = prepare_log(o, format, *a, w, span);
  if (!src) return 2;
  const std::optional<Time>& first = span.first;
  // Each input signal of A, as B's signal of the same name.
  std::unordered_map<const Signal*, Signal*> map;
  for (const std::string& name : input_signal_names(a->monitor())) {
    if (auto s = find_input_signal(b->monitor(), name); s) map.emplace(a->monitor().signals().find(name), *s);
  }
  // Addresses in both systems, in B's order.
  std::vector<Tracked> tracked;
  std::vector<std::string> only;
  for (const std::string& name : addresses_of(b->coordinator())) {
    auto ab = b->coordinator().structure().resolve(name);
    auto aa = a->coordinator().structure().resolve(name);
    if (ab && aa)
      tracked.push_back(Tracked{name, *ab, *aa, {}});
    else
      only.push_back(name + " (only in " + system_b + ")");
  }
  for (const std::string& name : addresses_of(a->coordinator())) {
    if (!b->coordinator().structure().resolve(name)) only.push_back(name + " (only in " + o.system + ")");
  }

  runner::RunOptions quiet;
  quiet.quiet = true;
  runner::RunResult ra, rb;
  const Time start = start_of(*src, first, w);
  a->start_at(start);
  b->start_at(start);
  (void)a->begin(quiet, ra);
  (void)b->begin(quiet, rb);
  bool dirty = true;
  const auto mark = [&dirty](const Record&) { dirty = true; };
  const auto sa = a->coordinator().subscribe(mark);
  const auto sb = b->coordinator().subscribe(mark);
  Feeder feeder(*src, w);
  ScenarioRunner& ra_sys = *a;
  ScenarioRunner* rb_sys = b.get();
  a->set_feed([&](Time now) { feeder.feed(now, ra_sys, rb_sys, &map); });
  const Time tick = seconds_to_time(a->scenario().period);
  const auto compare = [&](Time now) {
    if (!dirty) return;
    dirty = false;
    for (Tracked& t : tracked) {
      const State sb_state = b->coordinator().state_of(t.in_b);
      const State sa_state = a->coordinator().state_of(t.in_a);
      const bool open = !t.intervals.empty() && t.intervals.back().open;
      if (sb_state != sa_state && !open) {
        Interval i;
        i.from = now;
        i.b = sb_state;
        i.a = sa_state;
        i.side = sb_state > sa_state ? 'B' : 'A';
        i.cause = i.side == 'B' ? cause_of(b->coordinator(), t.in_b) : cause_of(a->coordinator(), t.in_a);
        t.intervals.push_back(std::move(i));
      } else if (sb_state == sa_state && open) {
        t.intervals.back().to = now;
        t.intervals.back().open = false;
      }
    }
  };
  const auto step = [&](Time t) {
    a->advance_to(t, ra);
    b->advance_to(t, rb);
    compare(a->now());
  };
  while (!feeder.done()) step(a->now() + tick);
  const Time end = end_of(*src, feeder, w, a->now());
  while (a->now() < end) step(a->now() + tick);
  a->coordinator().unsubscribe(sa);
  b->coordinator().unsubscribe(sb);
  a->finish(ra);
  b->finish(rb);
  if (feeder.failed()) {
    std::fprintf(o.err, "%s\n", src->error().c_str());
    return 2;
  }
  print_notes(*src, o.err);

  return print_diff(tracked, only, a->now(), system_b, o);
}

// ---- ReplaySession ----------------------------------------------------------------------------

struct ReplaySession::Impl {
  Prepared p;
  std::unique_ptr<Feeder> feeder;
  runner::RunResult result;
  Time start{}, end{}, period{};
};

ReplaySession::ReplaySession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ReplaySession::~ReplaySession() {
  if (impl_ && impl_->p.runner) impl_->p.runner->finish(impl_->result);
}

Expected<std::unique_ptr<ReplaySession>> ReplaySession::open(const ReplayOptions& options,
                                                             const FilterRegistry& registry) {
  // The errors run_replay() prints, collected: the same code says them.
  char* text = nullptr;
  std::size_t size = 0;
  std::FILE* err = ::open_memstream(&text, &size);
  if (err == nullptr)
    return fail(ErrorCode::Io, std::string("cannot collect the replay's errors: ") + std::strerror(errno));
  ReplayOptions o = options;
  o.err = err;
  o.json = false;
  o.record.clear();
  std::optional<Prepared> prepared = prepare(o, registry);
  std::fclose(err);
  std::string errors(text != nullptr ? text : "", size);
  std::free(text);
  if (!prepared) {
    while (!errors.empty() && errors.back() == '\n') errors.pop_back();
    if (errors.empty()) errors = "cannot replay " + options.input + " through " + options.system;
    return fail(ErrorCode::Parse, errors);
  }
  auto impl = std::make_unique<Impl>();
  impl->p = std::move(*prepared);
  ScenarioRunner& r = *impl->p.runner;
  const Window& w = impl->p.window;
  const LogSpan& span = impl->p.span;
  impl->period = seconds_to_time(r.scenario().period);
  impl->start = start_of(*impl->p.src, span.first, w);
  r.start_at(impl->start);
  // The first tick, as start_at() rounds it: the first multiple of the period at or after start.
  const auto ticks_to = [&](Time t) {
    const auto n = (t.count() + impl->period.count() - 1) / impl->period.count();
    return Time{n * impl->period.count()};
  };
  impl->start = ticks_to(impl->start);
  // run_replay() ticks until the last input is fed, then on to the recording's end (else the last
  // input), never past --to.
  Time end = span.end.value_or(span.last.value_or(impl->start));
  if (end > w.to) end = w.to;
  if (span.last && ticks_to(*span.last) > end) end = ticks_to(*span.last);
  impl->end = std::max(end, impl->start);
  runner::RunOptions quiet;
  quiet.quiet = true;
  quiet.inputs_path = "-";
  if (!r.begin(quiet, impl->result)) {
    std::string why;
    for (const std::string& f : impl->result.failures) why += (why.empty() ? "" : "\n") + f;
    return fail(ErrorCode::Io, why);
  }
  impl->feeder = std::make_unique<Feeder>(*impl->p.src, w);
  Feeder* feeder = impl->feeder.get();
  r.set_feed([feeder, &r](Time now) { feeder->feed(now, r, nullptr, nullptr); });
  return std::unique_ptr<ReplaySession>(new ReplaySession(std::move(impl)));
}

ScenarioRunner& ReplaySession::runner() noexcept { return *impl_->p.runner; }
const ScenarioRunner& ReplaySession::runner() const noexcept { return *impl_->p.runner; }
Time ReplaySession::start() const noexcept { return impl_->start; }
Time ReplaySession::end() const noexcept { return impl_->end; }
Time ReplaySession::period() const noexcept { return impl_->period; }

Time ReplaySession::now() const noexcept {
  const Time t = impl_->p.runner->now();
  return t < impl_->start ? impl_->start - impl_->period : t;
}

void ReplaySession::advance_to(Time t) {
  if (t > impl_->end) t = impl_->end;
  if (t <= impl_->p.runner->now()) return;
  impl_->p.runner->advance_to(t, impl_->result);
}

std::uint64_t ReplaySession::samples() const noexcept { return impl_->feeder->fed(); }
std::uint64_t ReplaySession::actions() const noexcept { return impl_->feeder->actions(); }
std::vector<std::string> ReplaySession::notes() const { return impl_->p.src->notes(); }

}  // namespace safecass::replay
