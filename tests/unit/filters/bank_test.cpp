// Filter banks (DESIGN §3, docs/filters.md "Filter banks"): a bank is an implementation of the
// same filters, not new semantics. The differential test runs one random system twice, its
// filters run as objects (Monitor(..., banks = false)) and in banks, and requires byte-equal
// observer streams, outputs, detections and missed-sample counts after every cycle. The systems
// mix every banked type (Threshold, Watchdog, MovingAverage of scalars and of vectors, Debounce,
// Frequency, Norm, Deadline on two signals, sometimes one signal twice, sometimes several
// Deadlines of one pair in a row) with an object filter (Range) in between, ACTIVE and PASSIVE, scalar and vector
// signals, pipelines (a filter on an earlier filter's output), EDGE and LEVEL, persistence in samples and seconds; the
// signals mix noise around the limits, steps, ramps, zeros, NaN and ±inf; the runs mix several
// samples per cycle, none, bursts that overflow the history, deep and shallow injection, enabling and disabling
// filters, and a pipeline that fails half-built and is undone.
//
// SAFECASS_BANK_SEEDS=N runs N seeds (the long run in docs/filters.md); `make test` runs 2,000, the
// CI's ASan subset 400 (Makefile, ASAN_CI_ENV).

#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"

namespace safecass {
namespace {

constexpr int kEvents = 3;

/// One system, as the program below builds it: objects or banks.
class World {
public:
  explicit World(bool banks) : monitor_(co_, registry_, 32, banks) {
    register_builtin_filters(registry_);
    (void)co_.add_component("C");
    for (int e = 0; e < kEvents; ++e) {
      const std::string name = "EVT_" + std::to_string(e);
      (void)co_.add_event(
          EventDef{name, 10 + e, {Transition::N2W, Transition::N2E, Transition::W2E}, "", false, "", ""});
      (void)co_.add_event(
          EventDef{"/" + name, 10 + e, {Transition::W2N, Transition::E2N, Transition::E2W}, "", false, "", ""});
    }
    co_.subscribe([this](const Record& r) { log_ += line(r); });
  }
  Monitor& monitor() { return monitor_; }
  Coordinator& coordinator() { return co_; }
  SimulatedClock& clock() { return clock_; }
  const std::string& log() const { return log_; }

  /// Everything a user can see after a cycle: outputs, detections, missed samples.
  std::string view() const {
    std::string v;
    for (const auto& s : monitor_.signals().all()) {
      Time t{};
      std::vector<double> x(s->size());
      bool injected = false;
      v += s->name() + "=";
      if (!s->latest(t, x.data(), &injected)) {
        v += "-;";
        continue;
      }
      v += std::to_string(t.count()) + (injected ? "i" : "");
      for (const double e : x) v += ":" + bits(e);
      v += ";";
    }
    for (const auto& f : monitor_.filters()) {
      // The run-time facts too (Filter::facts(): what `analyze now` reads), kept by either path.
      const FilterFacts facts = f->facts();
      v += f->name() + (f->detected() ? "!" : ".") + std::to_string(f->missed_samples()) +
           (facts.enabled ? " on" : " off") + (facts.injected ? " injected" : "") +
           " last=" + (facts.last_sample ? std::to_string(facts.last_sample->count()) : "-") +
           " runs=" + std::to_string(facts.evaluations) + ";";
    }
    return v;
  }

private:
  static std::string bits(double x) { return std::to_string(std::bit_cast<std::uint64_t>(x)); }
  std::string line(const Record& r) const {
    std::string s = std::string(to_string(r.kind)) + " " + std::string(to_string(r.outcome)) +
                    " t=" + std::to_string(r.time.count()) + " m=" + std::to_string(static_cast<int>(r.machine)) + " ";
    if (r.event != kNoEvent) s += co_.structure().event(r.event).name;
    s += " " + std::string(to_string(r.from)) + ">" + std::string(to_string(r.to));
    const SampleCause& c = r.root.sample;
    if (c.present()) {
      s += " by " + std::string(co_.structure().name_of(c.filter)) + " on " +
           std::string(co_.structure().name_of(c.signal)) + " v=" + bits(c.value) + " at " +
           std::to_string(c.sample_time.count()) + (c.injected ? " injected" : "");
    }
    return s + "\n";
  }

  SimulatedClock clock_;
  Coordinator co_{"bank", &clock_};
  FilterRegistry registry_;
  Monitor monitor_;
  std::string log_;
};

/// A seeded random system and run, applied identically to both worlds.
class Program {
public:
  explicit Program(unsigned seed) : rng_(seed) {}

  void build(World& a, World& b) {
    const int signals = pick(1, 3);
    for (int i = 0; i < signals; ++i) inputs_.emplace_back("s" + std::to_string(i), 1);
    if (pick(0, 1) == 0) inputs_.emplace_back("v", 3);  // a vector (a force)
    signals_ = inputs_;
    for (const Named& s : signals_) {
      both(a, b, [&](World& w) { (void)w.monitor().add_signal("C." + s.first, s.second); });
    }
    const int filters = pick(1, 8);
    for (int i = 0; i < filters; ++i) {
      FilterConfig c = next_filter(i);
      both(a, b, [&](World& w) {
        auto f = w.monitor().add_filter(c);
        ASSERT_TRUE(f) << f.error().message;
      });
      filters_.emplace_back(c.name, width_of(first_input(c)));
    }
  }

  /// One cycle: samples, faults and changes, then the run at the cycle's time.
  void cycle(World& a, World& b, int k) {
    const std::int64_t now = std::int64_t{k + 1} * 1'000'000;  // 1 ms
    for (std::size_t s = 0; s < signals_.size(); ++s) {
      // Now and then a burst of more samples than the history holds (32): the oldest are missed.
      const bool burst = pick(0, 49) == 0;
      const int samples = burst ? 40 : pick(0, 6) < 4 ? 1 : pick(0, 3);
      for (int j = 0; j < samples; ++j) {
        std::vector<double> x(signals_[s].second);
        for (double& e : x) e = value(s, k);
        const Time t{now - std::int64_t{samples - j} * (burst ? 20'000 : 100'000)};
        both(a, b, [&](World& w) { w.monitor().signals().find("C." + signals_[s].first)->push(t, x.data()); });
      }
    }
    if (pick(0, 19) == 0) {  // deep injection
      const Named& s = signals_[index(signals_.size())];
      const std::vector<std::vector<double>> v{injected(s.second), injected(s.second)};
      both(a, b, [&](World& w) { ASSERT_TRUE(w.monitor().inject_deep("C." + s.first, v, Time{now - 50'000})); });
    }
    if (pick(0, 19) == 0) {  // shallow injection
      const Named& f = filters_[index(filters_.size())];
      std::vector<std::vector<double>> v(static_cast<std::size_t>(pick(1, 3)));
      for (auto& x : v) x = injected(f.second);
      both(a, b, [&](World& w) { ASSERT_TRUE(w.monitor().inject_shallow(f.first, v)); });
    }
    if (k == 30 && pick(0, 1) == 0) {  // a pipeline that fails at its second stage: undone whole
      FilterConfig first;
      first.type = "MovingAverage";
      first.target.component = "C";
      first.params = {{"input_signal", signals_[0].first}};
      FilterConfig second = first;
      second.type = "NoSuchType";
      both(a, b, [&](World& w) { ASSERT_FALSE(w.monitor().add_pipeline("undone", {first, second})); });
    }
    if (pick(0, 14) == 0) {  // enable or disable a filter
      const std::string& f = filters_[index(filters_.size())].first;
      const bool on = pick(0, 1) == 0;
      both(a, b, [&](World& w) { w.monitor().find_filter(f)->set_enabled(on); });
    }
    both(a, b, [&](World& w) {
      w.clock().set(Time{now});
      w.monitor().run_active(ComponentId{0}, Time{now});
      w.monitor().tick(Time{now});
    });
  }

private:
  using Named = std::pair<std::string, std::size_t>;  // a name and a width

  template <class F>
  static void both(World& a, World& b, F&& f) {
    f(a);
    f(b);
  }
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::size_t index(std::size_t n) { return static_cast<std::size_t>(pick(0, static_cast<int>(n) - 1)); }
  double real(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  std::size_t width_of(const std::string& signal) const {
    for (const auto& [name, size] : signals_) {
      if (name == signal) return size;
    }
    return 1;
  }

  /// Values around 10 (every threshold is near it): noise, steps, ramps, and now and then NaN or ±inf.
  double value(std::size_t signal, int k) {
    switch (pick(0, 24)) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return std::numeric_limits<double>::infinity();
      case 2: return -std::numeric_limits<double>::infinity();
      case 3:
      case 4: return pick(0, 1) == 0 ? 0.0 : 20.0;  // a step
      case 5:
      case 6: return 5.0 + 0.25 * ((k + static_cast<int>(signal) * 7) % 40);  // a ramp
      default: return 10.0 + real(-2.0, 2.0);                                 // noise around the limits
    }
  }
  /// An injected sample: finite (injection refuses others), on either side of the limits.
  std::vector<double> injected(std::size_t size) {
    std::vector<double> v(size);
    for (double& x : v) x = pick(0, 2) == 0 ? 20.0 : pick(0, 3) == 0 ? 0.0 : 10.0 + real(-2.0, 2.0);
    return v;
  }

  /// A scalar input: a signal, or sometimes the output of an earlier filter (a pipeline).
  std::string scalar_input() {
    std::vector<std::string> scalars;
    for (const auto& [name, size] : inputs_) {
      if (size == 1) scalars.push_back(name);
    }
    if (!outputs_.empty() && pick(0, 2) == 0) return outputs_[index(outputs_.size())];
    return scalars[index(scalars.size())];
  }
  std::string any_input() { return pick(0, 2) == 0 ? inputs_[index(inputs_.size())].first : scalar_input(); }
  static std::string first_input(const FilterConfig& c) {
    if (const auto it = c.params.find("input_signal"); it != c.params.end()) return std::get<std::string>(it->second);
    return std::get<std::vector<std::string>>(c.params.at("input_signals"))[0];
  }
  /// Names an output `name`, readable by the filters after this one.
  void output(FilterConfig& c, const std::string& name) {
    c.params["output_signal"] = name;
    outputs_.push_back(name);
    signals_.emplace_back(name, 1);
  }

  FilterConfig next_filter(int i) {
    FilterConfig c;
    c.name = "f" + std::to_string(i);
    c.target.component = "C";
    c.execution = pick(0, 3) == 0 ? ExecutionMode::Passive : ExecutionMode::Active;
    c.detection = pick(0, 2) == 0 ? DetectionMode::Level : DetectionMode::Edge;
    c.enabled = pick(0, 9) != 0;
    const std::string event = "EVT_" + std::to_string(pick(0, kEvents - 1));
    auto events = [&] {
      c.params["event_onset"] = event;
      c.params["event_completion"] = "/" + event;
    };
    auto persistence = [&](const char* unit_param) {
      const bool seconds = pick(0, 1) == 0;
      c.params["persistence"] = seconds ? real(0.0, 0.004) : static_cast<double>(pick(0, 3));
      if (unit_param != nullptr) c.params[unit_param] = std::string(seconds ? "seconds" : "samples");
    };
    // After a Deadline, often another of the same two signals: they share one merged read.
    const bool again = !pair_.empty() && pick(0, 1) == 0;
    if (!again) pair_.clear();
    const int type = again ? 6 : pick(0, 7);
    switch (type) {
      case 0:
        c.type = "Threshold";
        c.params = {{"input_signal", scalar_input()},
                    {"threshold", 10.0 + real(-1.0, 1.0)},
                    {"tolerance", pick(0, 1) == 0 ? 0.0 : real(0.0, 0.5)},
                    {"hysteresis", pick(0, 1) == 0 ? 0.0 : real(0.0, 1.5)},
                    {"direction", std::string(pick(0, 2) == 0 ? "below" : "above")}};
        events();
        if (pick(0, 1) == 0) persistence("persistence_unit");
        if (pick(0, 1) == 0) output(c, "out" + std::to_string(i));
        break;
      case 1:
        c.type = "Watchdog";
        c.params = {{"input_signal", any_input()}, {"timeout", pick(5, 40) * 1e-4}};
        events();
        if (pick(0, 1) == 0) output(c, "age" + std::to_string(i));
        break;
      case 2: {
        c.type = "MovingAverage";
        const std::string input = any_input();
        c.params = {{"input_signal", input}, {"window", static_cast<double>(pick(1, 5))}};
        const std::string name = "mean" + std::to_string(i);
        if (width_of(input) == 1) {
          output(c, name);
        } else {  // a vector's means: a vector signal, which the scalar filters after it do not read
          c.params["output_signal"] = name;
          signals_.emplace_back(name, width_of(input));
        }
        break;
      }
      case 3:
        c.type = "Debounce";
        c.params = {{"input_signal", scalar_input()}, {"release", static_cast<double>(pick(1, 3))}};
        events();
        if (pick(0, 1) == 0) persistence("persistence_unit");
        if (pick(0, 1) == 0) output(c, "debounced" + std::to_string(i));
        break;
      case 4:
        c.type = "Frequency";
        c.params = {{"input_signal", any_input()},
                    {"min_rate", pick(0, 1) == 0 ? 0.0 : real(500.0, 1500.0)},
                    {"max_rate", pick(0, 1) == 0 ? 0.0 : real(1000.0, 5000.0)},
                    {"max_jitter", pick(0, 1) == 0 ? 0.0 : real(0.0, 0.0005)},
                    {"window", static_cast<double>(pick(1, 4))}};
        events();
        if (pick(0, 1) == 0) output(c, "rate" + std::to_string(i));
        break;
      case 5: {
        c.type = "Norm";
        std::vector<std::string> all;
        for (const auto& [name, size] : inputs_) all.push_back(name);
        const char* norms[] = {"L2", "L1", "Linf"};
        c.params = {{"input_signal", all[index(all.size())]}, {"norm", std::string(norms[pick(0, 2)])}};
        output(c, "norm" + std::to_string(i));
        break;
      }
      case 6: {
        c.type = "Deadline";
        if (pair_.empty()) {
          const std::string start = any_input();
          pair_ = {start, pick(0, 4) == 0 ? start : any_input()};  // sometimes one signal for both
        }
        c.params = {{"input_signals", pair_}, {"deadline", pick(1, 30) * 1e-4}};
        events();
        if (pick(0, 1) == 0) output(c, "elapsed" + std::to_string(i));
        break;
      }
      default:
        c.type = "Range";  // not banked: runs as an object between banked filters
        c.params = {{"input_signal", scalar_input()}, {"min", 9.0}, {"max", 11.0}};
        events();
        break;
    }
    return c;
  }

  std::mt19937 rng_;
  std::vector<Named> inputs_;         ///< the signals the cycle writes
  std::vector<Named> signals_;        ///< every signal: the inputs, then the filters' outputs
  std::vector<std::string> outputs_;  ///< the scalar outputs, in the order made
  std::vector<Named> filters_;        ///< each filter and its (first) input's width
  std::vector<std::string> pair_;     ///< the last filter's two signals, when it is a Deadline
};

/// The first line where `a` and `b` differ, with the line before it.
std::string first_difference(const std::string& a, const std::string& b) {
  std::size_t line = 0, start = 0, previous = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size() && a[i] == b[i]; ++i) {
    if (a[i] == '\n') {
      ++line;
      previous = start;
      start = i + 1;
    }
  }
  auto tail = [&](const std::string& s) { return s.substr(previous, s.find('\n', start) - previous); };
  return "line " + std::to_string(line + 1) + "\n--- objects\n" + tail(a) + "\n--- banks\n" + tail(b);
}

/// Runs seed `seed` in both worlds; the first difference, or "".
std::string difference(unsigned seed, std::size_t* banked = nullptr) {
  World objects(false);
  World banks(true);
  Program program(seed);
  program.build(objects, banks);
  if (banked != nullptr) *banked += banks.monitor().banked_count();
  EXPECT_EQ(objects.monitor().banked_count(), 0U);
  for (int k = 0; k < 60; ++k) {
    program.cycle(objects, banks, k);
    if (objects.log() != banks.log()) {
      return "cycle " + std::to_string(k) + ", observer stream, " + first_difference(objects.log(), banks.log());
    }
    if (objects.view() != banks.view()) {
      return "cycle " + std::to_string(k) + ", view, " + first_difference(objects.view(), banks.view());
    }
  }
  return "";
}

TEST(FilterBank, ABankRaisesTheSameEventsValuesTimesAndOrderAsTheFiltersRunOneByOne) {
  const char* env = std::getenv("SAFECASS_BANK_SEEDS");
  const unsigned seeds = env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : 2000U;
  std::size_t banked = 0;
  for (unsigned seed = 1; seed <= seeds; ++seed) {
    const std::string d = difference(seed, &banked);
    ASSERT_EQ(d, "") << "seed " << seed << ": " << d;
  }
  EXPECT_GT(banked, seeds) << "the random systems must put filters in banks";
}

TEST(FilterBank, BuiltInFiltersOfOneSignalShareOneBankReaderAndCustomTypesStayObjects) {
  World w(true);
  ASSERT_TRUE(w.monitor().add_signal("C.x"));
  auto add = [&](const std::string& type, Params p) {
    FilterConfig c;
    c.type = type;
    c.target.component = "C";
    c.params = std::move(p);
    ASSERT_TRUE(w.monitor().add_filter(c));
  };
  add("Threshold", {{"input_signal", std::string("x")}, {"threshold", 1.0}, {"event_onset", std::string("EVT_0")}});
  add("Watchdog", {{"input_signal", std::string("x")}, {"timeout", 1.0}});
  add("MovingAverage", {{"input_signal", std::string("x")}});
  add("Range", {{"input_signal", std::string("x")}, {"min", 0.0}, {"max", 1.0}, {"event_onset", std::string("EVT_1")}});
  EXPECT_EQ(w.monitor().banked_count(), 3U);
  EXPECT_EQ(w.monitor().filters().size(), 4U);  // the console and the read model list all four
}

TEST(FilterBank, DeadlinesOfOnePairAreBankedAndTakeAStartAndAnEndOfTheSameTimeStartFirst) {
  // A Deadline merges its two signals in time order, a tie going to the start (input order), in
  // a bank as as an object: a start and an end at the same time close a zero-length interval.
  for (const bool banking : {false, true}) {
    World w(banking);
    Signal* start = *w.monitor().add_signal("C.start");
    Signal* end = *w.monitor().add_signal("C.end");
    for (const char* name : {"d1", "d2"}) {
      FilterConfig c;
      c.name = name;
      c.type = "Deadline";
      c.target.component = "C";
      c.params = {{"input_signals", std::vector<std::string>{"start", "end"}},
                  {"deadline", 1e-6},
                  {"event_onset", std::string("EVT_0")},
                  {"output_signal", std::string(name) + "_elapsed"}};
      ASSERT_TRUE(w.monitor().add_filter(c));
    }
    EXPECT_EQ(w.monitor().banked_count(), banking ? 2U : 0U);
    end->push(Time{1'000}, 1.0);  // written first, but the start of the same time is taken first
    start->push(Time{1'000}, 1.0);
    w.clock().set(Time{1'500});
    w.monitor().run_active(ComponentId{0}, Time{1'500});
    for (const char* name : {"d1", "d2"}) {
      EXPECT_FALSE(w.monitor().find_filter(name)->detected()) << name << (banking ? " in a bank" : " as an object");
      Time t{};
      double elapsed = -1.0;
      ASSERT_TRUE(w.monitor().signals().find("C." + std::string(name) + "_elapsed")->latest(t, &elapsed));
      EXPECT_EQ(elapsed, 0.0);
    }
    start->push(Time{2'000}, 1.0);  // open at the run 2 µs later: overdue
    w.clock().set(Time{4'000});
    w.monitor().run_active(ComponentId{0}, Time{4'000});
    EXPECT_TRUE(w.monitor().find_filter("d1")->detected());
    EXPECT_TRUE(w.monitor().find_filter("d2")->detected());
  }
}

TEST(FilterBank, AVectorsMovingAverageIsBankedAndWritesTheElementWiseMeans) {
  World w(true);
  Signal* v = *w.monitor().add_signal("C.v", 3);
  FilterConfig c;
  c.type = "MovingAverage";
  c.target.component = "C";
  c.params = {{"input_signal", std::string("v")}, {"window", 2.0}, {"output_signal", std::string("mean")}};
  ASSERT_TRUE(w.monitor().add_filter(c));
  EXPECT_EQ(w.monitor().banked_count(), 1U);
  const double first[] = {1.0, 2.0, 3.0};
  const double second[] = {3.0, 6.0, -3.0};
  v->push(Time{1}, first);
  v->push(Time{2}, second);
  w.monitor().run_active(ComponentId{0}, Time{2});
  const Signal* mean = w.monitor().signals().find("C.mean");
  ASSERT_NE(mean, nullptr);
  Time t{};
  double out[3] = {};
  ASSERT_TRUE(mean->latest(t, out));
  EXPECT_EQ(t, Time{2});
  EXPECT_EQ(out[0], 2.0);
  EXPECT_EQ(out[1], 4.0);
  EXPECT_EQ(out[2], 0.0);
}

TEST(FilterBank, ASampleAnObserverWritesDuringTheRunIsJudgedInThatRunAsByTheFiltersOneByOne) {
  // The signals no filter writes are read ahead of the run; one that something else writes during
  // the run (here an observer of the first filter's event) must still be read at its step. The
  // first filter is banked (Threshold) or an object (Range): either's event runs the observer.
  for (const std::string first : {"Threshold", "Range"}) {
    auto build = [&first](World& w) {
      Signal* x = *w.monitor().add_signal("C.x");
      Signal* y = *w.monitor().add_signal("C.y");
      for (const char* input : {"x", "y"}) {
        FilterConfig c;
        c.name = std::string("limit_") + input;
        c.type = input[0] == 'x' ? first : "Threshold";
        c.target.component = "C";
        c.params = {{"input_signal", std::string(input)},
                    {"event_onset", std::string(input[0] == 'x' ? "EVT_0" : "EVT_1")}};
        if (c.type == "Range") {
          c.params["min"] = 0.0;
          c.params["max"] = 10.0;
        } else {
          c.params["threshold"] = 10.0;
        }
        ASSERT_TRUE(w.monitor().add_filter(c));
      }
      const EventId onset = *w.coordinator().structure().find_event("EVT_0");
      w.coordinator().subscribe([y, onset](const Record& r) {
        if (r.kind == RecordKind::Event && r.event == onset && r.outcome != Outcome::Ignored) y->push(r.time, 20.0);
      });
      x->push(Time{1}, 1.0);
      y->push(Time{1}, 1.0);
      x->push(Time{2}, 20.0);  // limit_x's onset: the observer writes y = 20 during the run
    };
    World objects(false);
    World banks(true);
    build(objects);
    build(banks);
    ASSERT_EQ(banks.monitor().banked_count(), first == "Range" ? 1U : 2U);
    for (World* w : {&objects, &banks}) {
      w->clock().set(Time{3});
      w->monitor().run_active(ComponentId{0}, Time{3});
    }
    EXPECT_EQ(objects.log(), banks.log()) << first;
    EXPECT_TRUE(objects.monitor().find_filter("limit_y")->detected()) << first;
    EXPECT_TRUE(banks.monitor().find_filter("limit_y")->detected()) << first;
  }
}

TEST(FilterBank, AFilterDisabledAndInjectedFromAnotherThreadWhileItsBankRunsStaysExactAfterward) {
  // set_enabled() and inject() come from tool threads while the component's loop runs the bank;
  // a change is seen at the bank's next run. Afterwards the filter judges as before.
  World w(true);
  Signal* x = *w.monitor().add_signal("C.x");
  FilterConfig c;
  c.name = "limit";
  c.type = "Threshold";
  c.target.component = "C";
  c.params = {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_0")}};
  Filter* limit = *w.monitor().add_filter(c);
  c.name = "other";
  Filter* other = *w.monitor().add_filter(c);
  ASSERT_EQ(w.monitor().banked_count(), 2U);
  std::atomic<bool> done{false};
  std::atomic<int> injected{0};
  std::thread tool([&] {
    for (int i = 0; !done.load(); ++i) {
      limit->set_enabled(i % 2 == 0);
      if (i % 5 == 0 && w.monitor().inject_shallow("limit", {{1.0}})) injected.fetch_add(1);
      std::this_thread::yield();
    }
  });
  std::int64_t t = 0;
  for (int i = 0; i < 20000; ++i) {
    x->push(Time{++t}, 1.0);
    w.monitor().run_active(ComponentId{0}, Time{t});
  }
  done = true;
  tool.join();
  limit->set_enabled(true);
  // The detour ends: an enabled run takes one queued injection (a disabled one takes none, so as
  // many may still be queued as were made), the next restores reality; then it is back in the bank.
  for (int i = 0; i < injected.load() + 2; ++i) {
    x->push(Time{++t}, 1.0);
    w.monitor().run_active(ComponentId{0}, Time{t});
  }
  EXPECT_FALSE(limit->detected());
  x->push(Time{++t}, 20.0);
  w.monitor().run_active(ComponentId{0}, Time{t});
  EXPECT_TRUE(limit->detected());
  EXPECT_TRUE(other->detected());
  EXPECT_EQ(limit->missed_samples(), 0U);
}

}  // namespace
}  // namespace safecass
