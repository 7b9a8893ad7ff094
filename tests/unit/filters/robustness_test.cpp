// Robustness of the built-in filters: non-finite samples (every type) and bad parameters at
// creation (DESIGN §3, filter.hpp, monitor.hpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "builtin_fixture.hpp"

namespace safecass::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Non-finite samples, for every built-in type ----------------------------------------------

/// One built-in filter, configured on component C, with the values of its scenario.
struct Case {
  std::string type;
  Params params;
  std::vector<std::pair<std::string, std::size_t>> inputs;  ///< C.<name>, size; the first gets the bad samples
  std::string output;                                       ///< C.<name> written, or empty
  std::vector<double> warm_up;                              ///< at 1.0, 1.1, 1.2 on every input
  double after = 0;                                         ///< finite value at 1.7 (first input) and 1.8 (all)
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.type; }

/// A coordinator with component C (events EVT_X, /EVT_X), a monitor and a log of what happened.
struct Rig {
  SimulatedClock clock;
  Coordinator co{"rig", &clock};
  FilterRegistry registry;
  Monitor monitor{co, registry};
  ComponentId c{0};
  struct Entry {
    std::string machine, event;
    Time time{};
    double value = 0;
    std::string signal;
    bool operator==(const Entry& o) const {
      // NaN values compare equal to each other: both rigs must agree, not the IEEE rule.
      const bool same_value = value == o.value || (std::isnan(value) && std::isnan(o.value));
      return machine == o.machine && event == o.event && time == o.time && same_value && signal == o.signal;
    }
  };
  friend std::ostream& operator<<(std::ostream& os, const Entry& e) {
    return os << e.machine << ' ' << e.event << " at " << to_seconds(e.time) << " value " << e.value << " signal '"
              << e.signal << "'";
  }
  std::vector<Entry> log;
  Filter* filter = nullptr;

  Rig() {
    register_builtin_filters(registry);
    c = *co.add_component("C");
    EXPECT_TRUE(co.add_event(EventDef{"EVT_X", 50, {Transition::N2E, Transition::W2E}, "", false, "", ""}));
    EXPECT_TRUE(co.add_event(EventDef{"/EVT_X", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""}));
    co.subscribe([this](const Record& r) {
      if (r.kind != RecordKind::Event || r.outcome == Outcome::Ignored) return;
      log.push_back(
          Entry{co.structure().address_of(r.machine), co.structure().event(r.event).name, r.time, r.root.sample.value,
                r.root.sample.signal == kNoName ? "" : std::string(co.structure().name_of(r.root.sample.signal))});
    });
  }
  void create(const Case& k) {
    for (const auto& [name, size] : k.inputs) ASSERT_TRUE(monitor.add_signal("C." + name, size));
    FilterConfig config;
    config.name = "probe";
    config.type = k.type;
    config.target.component = "C";
    config.params = k.params;
    auto f = monitor.add_filter(config);
    ASSERT_TRUE(f) << f.error().message;
    filter = *f;
  }
  void push(const std::string& name, double t, double value) {
    Signal* s = monitor.signals().find("C." + name);
    std::vector<double> v(s->size(), 1.0);
    v.back() = value;  // a non-finite value in one element is enough
    s->push(seconds_to_time(t), v.data());
  }
  void run(double t) {
    clock.set(seconds_to_time(t));
    monitor.run_active(c, seconds_to_time(t));
  }
  std::vector<Entry> on(const std::string& machine) const {
    std::vector<Entry> out;
    for (const Entry& e : log) {
      if (e.machine == machine) out.push_back(e);
    }
    return out;
  }
  /// Every sample of C.<name>: time, then values.
  std::vector<std::vector<double>> samples(const std::string& name) const {
    std::vector<std::vector<double>> out;
    const Signal* s = monitor.signals().find("C." + name);
    if (s == nullptr) return out;
    SignalCursor cursor(s);
    SampleView sample;
    while (cursor.next(sample)) {
      std::vector<double> v{to_seconds(sample.time)};
      v.insert(v.end(), sample.data, sample.data + sample.size);
      out.push_back(std::move(v));
    }
    EXPECT_EQ(cursor.missed(), 0u) << name << ": the history buffer overflowed";
    return out;
  }
};

class EveryBuiltinFilter : public ::testing::TestWithParam<Case> {
protected:
  /// The same scenario on both rigs, except that `faulty` also gets NaN, +inf and −inf samples.
  void play() {
    const Case& k = GetParam();
    faulty_.create(k);
    clean_.create(k);
    for (Rig* r : {&faulty_, &clean_}) {
      for (std::size_t i = 0; i < k.warm_up.size(); ++i) {
        const double t = 1.0 + 0.1 * static_cast<double>(i);
        for (const auto& in : k.inputs) r->push(in.first, t, k.warm_up[i]);
        r->run(t);
      }
    }
    const std::string first = k.inputs.front().first;
    const double bad[] = {kNaN, kInf, -kInf};
    for (int i = 0; i < 3; ++i) {
      const double t = 1.3 + 0.1 * i;
      faulty_.push(first, t, bad[i]);
      faulty_.run(t);
      clean_.run(t);
      states_during_.push_back(faulty_.co.state(faulty_.co.structure().framework_machine(faulty_.c)));
    }
    for (Rig* r : {&faulty_, &clean_}) {
      r->run(1.6);
      r->push(first, 1.7, k.after);
      r->run(1.7);
      for (const auto& in : k.inputs) r->push(in.first, 1.8, k.after);
      r->run(1.8);
      r->run(2.5);
    }
  }
  Rig faulty_;
  Rig clean_;
  std::vector<State> states_during_;
};

TEST_P(EveryBuiltinFilter, NonFiniteSamplesNeverReachTheFilterAndRaiseInvalidSampleOnTheTargetsFramework) {
  play();
  const Case& k = GetParam();
  // s_F: one onset for the three bad samples, one completion at the next finite sample.
  const std::vector<Rig::Entry> sf = faulty_.on("C.s_F");
  ASSERT_EQ(sf.size(), 2u);
  EXPECT_EQ(sf[0].event, "EVT_INVALID_SAMPLE");
  EXPECT_EQ(sf[0].time, seconds_to_time(1.3));
  EXPECT_EQ(sf[0].signal, "C." + k.inputs.front().first);
  EXPECT_TRUE(std::isnan(sf[0].value));
  EXPECT_EQ(sf[1].event, "/EVT_INVALID_SAMPLE");
  EXPECT_EQ(sf[1].time, seconds_to_time(1.7));
  EXPECT_EQ(states_during_, (std::vector<State>{State::Error, State::Error, State::Error}));
  EXPECT_EQ(faulty_.co.state(faulty_.co.structure().framework_machine(faulty_.c)), State::Normal);
  EXPECT_TRUE(clean_.on("C.s_F").empty());
  // The filter behaved exactly as if the bad samples had never been written: same events on its
  // target, same output samples (so nothing was written for a bad sample).
  EXPECT_EQ(faulty_.on("C.s_A"), clean_.on("C.s_A"));
  if (!k.output.empty()) {
    const auto clean_out = clean_.samples(k.output);
    EXPECT_FALSE(clean_out.empty()) << "the scenario must exercise the output";
    EXPECT_EQ(faulty_.samples(k.output), clean_out);
  }
  EXPECT_EQ(faulty_.filter->detected(), clean_.filter->detected());
}

Params with_events(Params p, const char* onset_param = "event_onset") {
  p[onset_param] = std::string("EVT_X");
  return p;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"Threshold",
       with_events({{"input_signal", std::string("x")}, {"threshold", 10.0}, {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {5, 11, 12},
       3},
      {"Range",
       with_events(
           {{"input_signal", std::string("x")}, {"min", 0.0}, {"max", 10.0}, {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {5, 11, 12},
       5},
      {"OnOff",
       with_events({{"input_signal", std::string("x")}, {"output_signal", std::string("out")}}, "event_on"),
       {{"x", 1}},
       "out",
       {0, 1, 0},
       1},
      {"ChangeDetection",
       with_events({{"input_signal", std::string("v")}, {"tolerance", 0.5}, {"output_signal", std::string("out")}}),
       {{"v", 3}},
       "out",
       {1, 2, 2},
       5},
      {"Debounce",
       with_events({{"input_signal", std::string("x")}, {"persistence", 2.0}, {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {1, 1, 1},
       0},
      {"Derivative",
       {{"input_signal", std::string("v")}, {"output_signal", std::string("out")}},
       {{"v", 3}},
       "out",
       {1, 2, 4},
       0},
      {"MovingAverage",
       {{"input_signal", std::string("v")}, {"window", 3.0}, {"output_signal", std::string("out")}},
       {{"v", 3}},
       "out",
       {1, 2, 4},
       8},
      {"Norm",
       {{"input_signal", std::string("v")}, {"output_signal", std::string("out")}},
       {{"v", 3}},
       "out",
       {1, 2, 3},
       4},
      {"Arithmetic",
       {{"input_signals", std::vector<std::string>{"a", "b"}},
        {"operation", std::string("multiply")},
        {"output_signal", std::string("out")}},
       {{"a", 2}, {"b", 2}},
       "out",
       {1, 2, 3},
       4},
      {"Vectorize",
       {{"input_signals", std::vector<std::string>{"x", "y", "z"}}, {"output_signal", std::string("out")}},
       {{"x", 1}, {"y", 1}, {"z", 1}},
       "out",
       {1, 2, 3},
       4},
      {"Bypass",
       {{"input_signal", std::string("v")}, {"output_signal", std::string("out")}},
       {{"v", 3}},
       "out",
       {1, 2, 3},
       4},
      {"NOP", {{"input_signal", std::string("v")}}, {{"v", 3}}, "", {1, 2, 3}, 4},
      {"Occurrence",
       with_events({{"input_signal", std::string("x")},
                    {"count", 2.0},
                    {"window", 10.0},
                    {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {1, 0, 0},
       1},
      {"Watchdog",
       {{"input_signal", std::string("x")}, {"timeout", 0.35}, {"output_signal", std::string("out")}},
       {{"x", 1}},
       "out",
       {1, 1, 1},
       1},
      {"Frequency",
       with_events({{"input_signal", std::string("x")},
                    {"max_rate", 5.0},
                    {"window", 2.0},
                    {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {1, 1, 1},
       1},
      {"DutyCycle",
       with_events({{"input_signal", std::string("x")}, {"period", 1.0}, {"output_signal", std::string("out")}}),
       {{"x", 1}},
       "out",
       {0.5, 0.9, 0.95},
       0.1},
      {"Deadline",
       with_events({{"input_signals", std::vector<std::string>{"start", "end"}},
                    {"deadline", 0.05},
                    {"output_signal", std::string("out")}}),
       {{"start", 1}, {"end", 1}},
       "out",
       {1, 1, 1},
       1},
  };
  return all;
}

INSTANTIATE_TEST_SUITE_P(Robustness, EveryBuiltinFilter, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& p) { return p.param.type; });

TEST(EveryBuiltinFilterTable, CoversEveryRegisteredBuiltinType) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  std::set<std::string> registered;
  for (const FilterManifest* m : registry.manifests()) registered.insert(m->type);
  std::set<std::string> tested;
  for (const Case& c : cases()) tested.insert(c.type);
  EXPECT_EQ(tested, registered);
  EXPECT_EQ(registered.size(), 17u);
}

// ---- Non-finite samples: where the event goes and how it is marked ----------------------------

using NonFiniteSample = BuiltinFixture;

TEST_F(NonFiniteSample, RaisesOnTheFrameworkMachineOfTheTargetComponentNotTheSignalOwner) {
  ASSERT_TRUE(co_.add_component("D"));
  Signal* x = signal("x");
  FilterConfig c;
  c.type = "Threshold";
  c.target.component = "D";
  c.params = {{"input_signal", std::string("C.x")}, {"threshold", 1.0}, {"event_onset", std::string("EVT_X")}};
  auto f = monitor_.add_filter(c);
  ASSERT_TRUE(f) << f.error().message;
  feed(x, *f, 1.0, kNaN);
  feed(x, *f, 1.1, 5);
  EXPECT_EQ(events_, (Events{"EVT_INVALID_SAMPLE", "/EVT_INVALID_SAMPLE", "EVT_X"}));
  EXPECT_EQ(machines_, (Events{"D.s_F", "D.s_F", "D.s_A"}));
  EXPECT_TRUE(co_.conditions(framework()).empty());
}

TEST_F(NonFiniteSample, LevelModeStillRaisesInvalidSampleOnlyOnce) {
  Signal* x = signal("x");
  Filter* f =
      make("Threshold", {{"input_signal", std::string("x")}, {"threshold", 1.0}, {"event_onset", std::string("EVT_X")}},
           DetectionMode::Level);
  feed(x, f, 1.0, 5);
  for (double v : {kNaN, kInf, kNaN, -kInf}) feed(x, f, 1.1, v);
  feed(x, f, 1.2, 6);
  EXPECT_EQ(events_, (Events{"EVT_X", "EVT_INVALID_SAMPLE", "/EVT_INVALID_SAMPLE"}));
  const std::vector<Condition> conditions = co_.conditions(app());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].count, 2u);  // the bad samples did not refresh the detection
}

TEST_F(NonFiniteSample, StuckNonFiniteInputStaysRaisedWhileAnotherInputIsFine) {
  Signal* a = signal("a");
  Signal* b = signal("b");
  make("Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b"}}, {"output_signal", std::string("r")}});
  push(a, 1.0, 1);
  push(b, 1.0, 2);
  run_all(1.0);
  for (int k = 1; k <= 3; ++k) {  // a is stuck at NaN, b keeps arriving
    push(a, 1.0 + k, kNaN);
    push(b, 1.0 + k, 2.0 + k);
    run_all(1.0 + k);
    EXPECT_EQ(co_.state(framework()), State::Error) << k;
  }
  EXPECT_EQ(events_, Events{"EVT_INVALID_SAMPLE"});
  push(b, 5.0, kInf);  // a second bad input joins the same condition
  run_all(5.0);
  push(a, 6.0, 10);  // a recovers, b is still bad
  run_all(6.0);
  EXPECT_EQ(events_, Events{"EVT_INVALID_SAMPLE"});
  push(b, 7.0, 20);
  run_all(7.0);
  EXPECT_EQ(events_, (Events{"EVT_INVALID_SAMPLE", "/EVT_INVALID_SAMPLE"}));
  EXPECT_EQ(times_, at({2.0, 7.0}));
  // Zero-order hold: while a was bad, b's samples were combined with a's last finite value.
  EXPECT_EQ(values_of("r"), (Values{3, 4, 5, 6, 15, 30}));
}

TEST_F(NonFiniteSample, VectorsWithANonFiniteElementLeaveTheLastFiniteVectorHeld) {
  Signal* a = signal("a", 2);
  Signal* b = signal("b", 2);
  make("Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b"}},
                      {"output_signal", std::string("r")},
                      {"operation", std::string("subtract")}});
  push(a, 1.0, Values{10, 20});
  push(b, 1.0, Values{1, 2});
  run_all(1.0);
  // Several bad vectors in a row, each read where the one before it was: the held vector survives.
  push(a, 2.0, Values{kNaN, 0});
  push(a, 2.5, Values{0, kInf});
  push(a, 2.75, Values{-kInf, kNaN});
  push(b, 3.0, Values{3, 4});
  run_all(3.0);
  EXPECT_EQ(latest_vector("r"), (Values{7, 16}));
  push(a, 4.0, Values{30, 40});
  run_all(4.0);
  EXPECT_EQ(latest_vector("r"), (Values{27, 36}));
  EXPECT_EQ(events_, (Events{"EVT_INVALID_SAMPLE", "/EVT_INVALID_SAMPLE"}));
}

TEST_F(NonFiniteSample, AnInfiniteSampleIsReportedAsInfiniteNotAsNaN) {
  Signal* x = signal("x");
  Signal* v = signal("v", 3);
  Filter* f = make("Threshold",
                   {{"input_signal", std::string("x")}, {"threshold", 1.0}, {"event_onset", std::string("EVT_X")}});
  Filter* n = make("Norm", {{"input_signal", std::string("v")}, {"output_signal", std::string("vn")}});
  feed(x, f, 1.0, kInf);
  std::vector<Condition> conditions = co_.conditions(framework());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].root.sample.value, kInf);
  feed(x, f, 1.1, 0);
  feed(x, f, 1.2, -kInf);
  conditions = co_.conditions(framework());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].root.sample.value, -kInf);
  feed(x, f, 1.3, 0);
  // A vector: the first value that is not finite.
  const double bad[] = {1.0, -kInf, kNaN};
  v->push(seconds_to_time(1.4), bad);
  n->run(seconds_to_time(1.4));
  conditions = co_.conditions(framework());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_EQ(conditions[0].root.sample.value, -kInf);
}

TEST_F(NonFiniteSample, TheMonitorRefusesToInjectANonFiniteValueAndChangesNothing) {
  Signal* x = signal("x");
  signal("v", 2);
  Filter* f = make("Threshold",
                   {{"input_signal", std::string("x")}, {"threshold", 1.0}, {"event_onset", std::string("EVT_X")}});
  std::size_t injections = 0;
  co_.subscribe([&injections](const Record& r) { injections += r.kind == RecordKind::Injection ? 1 : 0; });
  const struct {
    double value;
    const char* text;
  } cases[] = {{kNaN, "nan"}, {kInf, "inf"}, {-kInf, "-inf"}};
  for (const auto& c : cases) {
    auto shallow = monitor_.inject_shallow(f->name(), {{5.0}, {c.value}});
    ASSERT_FALSE(shallow) << c.text;
    EXPECT_EQ(shallow.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(shallow.error().message, "shallow injection into filter " + f->name() + ": sample 2 is " + c.text +
                                           ", not a finite number: injected values must be finite");
    auto deep = monitor_.inject_deep("C.v", {{1.0, c.value}}, seconds_to_time(1.0));
    ASSERT_FALSE(deep) << c.text;
    EXPECT_EQ(deep.error().message, std::string("deep injection into signal C.v: sample 1 value 2 is ") + c.text +
                                        ", not a finite number: injected values must be finite");
  }
  EXPECT_EQ(injections, 0u) << "a refused injection is not recorded";
  EXPECT_TRUE(written("v").empty()) << "nothing was written";
  feed(x, f, 1.0, 0);
  EXPECT_TRUE(events_.empty()) << "nothing was queued into the filter";
}

TEST_F(NonFiniteSample, ShallowInjectedNaNIsMarkedAsInjected) {
  // Below the monitor's rule (injected values are finite), the filter's own mechanism still marks
  // an invalid sample that came from an injection.
  Signal* x = signal("x");
  Filter* f = make("Threshold", {{"input_signal", std::string("x")},
                                 {"threshold", 1.0},
                                 {"event_onset", std::string("EVT_X")},
                                 {"output_signal", std::string("out")}});
  feed(x, f, 1.0, 0);
  ASSERT_TRUE(f->inject({{kNaN}}));
  tick(f, 1.1);
  EXPECT_EQ(events_, Events{"EVT_INVALID_SAMPLE"});
  const std::vector<Condition> conditions = co_.conditions(framework());
  ASSERT_EQ(conditions.size(), 1u);
  EXPECT_TRUE(conditions[0].root.sample.injected);
  EXPECT_EQ(values_of("out"), Values{0});
  feed(x, f, 1.2, 0);
  EXPECT_EQ(events_, (Events{"EVT_INVALID_SAMPLE", "/EVT_INVALID_SAMPLE"}));
}

// ---- Bad parameters: an error naming the culprit, and nothing created -------------------------

class CreationError : public BuiltinFixture {
protected:
  CreationError() {
    signal("x");
    signal("v", 3);
    signal("a", 2);
    signal("b", 3);
    signal("s");
  }
  /// Creating `type` named "bad" with `params` fails with a message naming the filter and every
  /// string of `culprits`, and leaves no filter and no signal behind.
  void expect_rejected(const std::string& type, Params params, const std::vector<std::string>& culprits) {
    const std::size_t filters = monitor_.filters().size();
    const std::size_t signals = monitor_.signals().all().size();
    FilterConfig c;
    c.name = "bad";
    c.type = type;
    c.target.component = "C";
    c.params = std::move(params);
    auto f = monitor_.add_filter(c);
    ASSERT_FALSE(f) << type << " was created";
    const std::string& m = f.error().message;
    EXPECT_NE(m.find("'bad'"), std::string::npos) << m;
    for (const std::string& s : culprits) EXPECT_NE(m.find(s), std::string::npos) << "'" << s << "' not in: " << m;
    EXPECT_EQ(monitor_.filters().size(), filters);
    EXPECT_EQ(monitor_.signals().all().size(), signals);
    EXPECT_EQ(monitor_.signals().find("C.new_out"), nullptr);
    EXPECT_EQ(monitor_.find_filter("bad"), nullptr);
  }
  static Params threshold(Params extra = {}) {
    Params p{{"input_signal", std::string("x")},
             {"threshold", 10.0},
             {"event_onset", std::string("EVT_X")},
             {"output_signal", std::string("new_out")}};
    for (auto& [k, v] : extra) p[k] = v;
    return p;
  }
};

TEST_F(CreationError, StringWhereANumberIsExpected) {
  expect_rejected("Threshold", threshold({{"threshold", std::string("ten")}}), {"'threshold'", "a string"});
}

TEST_F(CreationError, NumberWhereAChoiceIsExpected) {
  expect_rejected("Threshold", threshold({{"direction", 1.0}}), {"'direction'"});
}

TEST_F(CreationError, MissingRequiredParameter) {
  Params p = threshold();
  p.erase("threshold");
  expect_rejected("Threshold", p, {"missing", "'threshold'"});
  p = threshold();
  p.erase("input_signal");
  expect_rejected("Threshold", p, {"'input_signal'"});
}

TEST_F(CreationError, UnknownParameter) {
  expect_rejected("Threshold", threshold({{"treshold", 3.0}}), {"unknown parameter", "'treshold'"});
}

TEST_F(CreationError, OutOfRangeValues) {
  expect_rejected("MovingAverage",
                  {{"input_signal", std::string("x")}, {"window", 0.0}, {"output_signal", std::string("new_out")}},
                  {"'window'"});
  expect_rejected("MovingAverage",
                  {{"input_signal", std::string("x")}, {"window", 2.5}, {"output_signal", std::string("new_out")}},
                  {"'window'", "whole number"});
  expect_rejected("Threshold", threshold({{"hysteresis", -1.0}}), {"'hysteresis'"});
  expect_rejected("Threshold", threshold({{"persistence_unit", std::string("minutes")}}), {"'persistence_unit'"});
  expect_rejected("Watchdog",
                  {{"input_signal", std::string("x")}, {"timeout", 0.0}, {"output_signal", std::string("new_out")}},
                  {"'timeout'"});
}

TEST_F(CreationError, NonFiniteNumber) {
  expect_rejected("Threshold", threshold({{"threshold", kNaN}}), {"'threshold'", "finite"});
  expect_rejected("Threshold", threshold({{"threshold", kInf}}), {"'threshold'", "finite"});
}

TEST_F(CreationError, UnknownFilterType) {
  expect_rejected("Treshold", threshold(), {"unknown filter type", "'Treshold'"});
}

TEST_F(CreationError, UnknownEvent) {
  expect_rejected("Threshold", threshold({{"event_onset", std::string("EVT_NOPE")}}), {"'event_onset'", "'EVT_NOPE'"});
  expect_rejected("Threshold", threshold({{"event_completion", std::string("/EVT_NOPE")}}),
                  {"'event_completion'", "'/EVT_NOPE'"});
  expect_rejected("OnOff", {{"input_signal", std::string("x")}, {"event_on", std::string("EVT_NOPE")}},
                  {"'event_on'", "'EVT_NOPE'"});
}

TEST_F(CreationError, CompletionGivenAsOnsetOrOnsetAsCompletion) {
  expect_rejected("Threshold", threshold({{"event_onset", std::string("/EVT_X")}}), {"'event_onset'", "'/EVT_X'"});
  expect_rejected("Threshold", threshold({{"event_completion", std::string("EVT_X")}}),
                  {"'event_completion'", "'EVT_X'"});
}

TEST_F(CreationError, InputSignalThatDoesNotExist) {
  expect_rejected("Threshold", threshold({{"input_signal", std::string("nope")}}), {"'input_signal'", "'C.nope'"});
  expect_rejected("Vectorize",
                  {{"input_signals", std::vector<std::string>{"x", "nope"}}, {"output_signal", std::string("new_out")}},
                  {"'input_signals'", "'C.nope'"});
}

TEST_F(CreationError, VectorWhereAScalarIsNeeded) {
  expect_rejected("Threshold", threshold({{"input_signal", std::string("v")}}), {"'C.v'", "size 3"});
  expect_rejected(
      "FilterRange",
      {{"input_signal", std::string("v")}, {"min", 0.0}, {"max", 1.0}, {"event_onset", std::string("EVT_X")}},
      {"'C.v'", "size 3"});
}

TEST_F(CreationError, MismatchedSizes) {
  expect_rejected("Arithmetic",
                  {{"input_signals", std::vector<std::string>{"a", "b"}}, {"output_signal", std::string("new_out")}},
                  {"'C.a'", "'C.b'"});
  expect_rejected("Bypass", {{"input_signal", std::string("v")}, {"output_signal", std::string("s")}},
                  {"'output_signal'", "'C.s'"});
}

TEST_F(CreationError, OutputThatIsAlsoAnInput) {
  // Writing into its own input would give the filter a new sample for every sample it writes.
  expect_rejected("Bypass", {{"input_signal", std::string("v")}, {"output_signal", std::string("v")}},
                  {"'output_signal'", "'C.v'"});
  expect_rejected("Threshold", threshold({{"output_signal", std::string("C.x")}}), {"'output_signal'", "'C.x'"});
  expect_rejected("Arithmetic",
                  {{"input_signals", std::vector<std::string>{"x", "s"}}, {"output_signal", std::string("s")}},
                  {"'output_signal'", "'C.s'"});
}

TEST_F(CreationError, TargetThatDoesNotExist) {
  FilterConfig c;
  c.name = "bad";
  c.type = "Threshold";
  c.target.component = "NOPE";
  c.params = threshold();
  const std::size_t signals = monitor_.signals().all().size();
  auto f = monitor_.add_filter(c);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'NOPE'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.filters().size(), 0u);
  EXPECT_EQ(monitor_.signals().all().size(), signals);
}

TEST_F(CreationError, AGoodFilterAfterBadOnesIsCreatedNormally) {
  expect_rejected("Threshold", threshold({{"threshold", std::string("ten")}}), {"'threshold'"});
  Filter* f = make("Threshold", threshold());
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(monitor_.filters().size(), 1u);
  ASSERT_NE(monitor_.signals().find("C.new_out"), nullptr);
  feed(monitor_.signals().find("C.x"), f, 1.0, 11);
  EXPECT_EQ(events_, Events{"EVT_X"});
  EXPECT_EQ(values_of("new_out"), Values{1});
}

}  // namespace
}  // namespace safecass::test
