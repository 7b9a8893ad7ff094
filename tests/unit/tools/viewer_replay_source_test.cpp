// `safecass viewer --replay` (safecass/viewer/replay_source.hpp): a recording of the robodoc story fed
// through robodoc by the replay module; the states shown at any time the page seeks to are the
// recorded run's states at that time (from its history file), forwards and backwards; bad logs are
// refused with file:line; a replay is read-only; the protocol's replay controls.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "safecass/filters/registry.hpp"
#include "safecass/json/read.hpp"
#include "safecass/record/input_recorder.hpp"
#include "safecass/replay/replay.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/viewer/protocol.hpp"
#include "safecass/viewer/replay_source.hpp"
#include "viewer_test_support.hpp"

namespace safecass::viewer {
namespace {

using test::kStory;
using test::kSystem;

using ::testing::HasSubstr;

const std::string kSource = SAFECASS_SOURCE_DIR;

/// The robodoc story run once, recorded: its history and its inputs, in a fresh directory.
class RecordedStory : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / "safecass-viewer-replay-XXXXXX").string();
    ASSERT_NE(::mkdtemp(dir_.data()), nullptr);
    history_ = dir_ + "/story.jsonl";
    FilterRegistry registry;
    register_builtin_filters(registry);
    auto r = runner::ScenarioRunner::open(runner::ScenarioSource{kStory, {}}, registry);
    ASSERT_TRUE(r.has_value());
    runner::RunOptions o;
    o.quiet = true;
    o.record_path = history_;
    const runner::RunResult result = (*r)->run(o);
    ASSERT_TRUE(result.history_complete());
    inputs_ = InputRecorder::path_for_history(history_);
    ASSERT_TRUE(std::filesystem::exists(inputs_));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::unique_ptr<ReplaySource> open_replay() {
    ReplaySourceOptions o;
    o.system = kSystem;
    o.input = inputs_;
    auto source = ReplaySource::open(o);
    EXPECT_TRUE(source.has_value()) << (source ? "" : source.error().message);
    return source ? std::move(*source) : nullptr;
  }

  /// The state of every machine and component at time `t` by the history file: Normal, then the
  /// "to" of each transition record at or before t.
  std::map<std::string, std::string> history_states(double t) const {
    std::map<std::string, std::string> states;
    std::ifstream in(history_);
    std::string line;
    while (std::getline(in, line)) {
      const json::JsonParse p = json::parse_json(line, 16);
      if (!p.value) continue;
      const json::JsonValue& r = *p.value;
      const json::JsonValue* kind = r.find("kind");
      const json::JsonValue* time = r.find("t");
      const json::JsonValue* to = r.find("to");
      if (kind == nullptr || time == nullptr || to == nullptr || time->number > t + 1e-9) continue;
      if (kind->string == "transition") states[r.find("machine")->string] = to->string;
      if (kind->string == "component-transition") states[r.find("component")->string] = to->string;
    }
    return states;
  }

  /// The transition times of the history file, in order.
  std::vector<double> transition_times() const {
    std::vector<double> out;
    std::ifstream in(history_);
    std::string line;
    while (std::getline(in, line)) {
      const json::JsonParse p = json::parse_json(line, 16);
      if (!p.value) continue;
      const json::JsonValue* kind = p.value->find("kind");
      if (kind != nullptr && (kind->string == "transition" || kind->string == "component-transition")) {
        const double t = p.value->find("t")->number;
        if (out.empty() || out.back() != t) out.push_back(t);
      }
    }
    return out;
  }

  std::string dir_, history_, inputs_;
};

/// What the source shows of every machine and component.
std::map<std::string, std::string> shown_states(const ViewSource& s) {
  std::map<std::string, std::string> out;
  for (const CoordinatorView& co : s.view().coordinators) {
    for (const ComponentView& c : co.components) {
      out[c.name] = std::string(to_string(c.state));
      for (const MachineView& m : c.machines) {
        if (m.kind != NodeKind::Service) out[m.address] = std::string(to_string(m.state));
      }
    }
  }
  return out;
}

/// `shown` agrees with `history`: every address the history names has its state, and every
/// other address is Normal.
void expect_same(const std::map<std::string, std::string>& shown, const std::map<std::string, std::string>& history,
                 double t) {
  for (const auto& [address, state] : shown) {
    const auto it = history.find(address);
    EXPECT_EQ(state, it == history.end() ? "Normal" : it->second) << address << " at t=" << t;
  }
  for (const auto& [address, state] : history) EXPECT_TRUE(shown.count(address) != 0) << address << " not shown";
}

void seek(ReplaySource& s, double t) {
  ReplayControl c;
  c.op = ReplayControl::Op::Seek;
  c.t = t;
  auto done = s.control(c);
  ASSERT_TRUE(done.has_value()) << done.error().message;
  s.settle();
}

TEST_F(RecordedStory, StatesAtEveryTimeSoughtEqualTheRecordedRunsStatesAtThatTimeForwardsAndBackwards) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  const std::vector<double> times = transition_times();
  ASSERT_GE(times.size(), 4u);
  // At, between and after transitions, forwards, then backwards (the replay starts over), then
  // forwards again.
  std::vector<double> targets;
  for (const double t : times) targets.insert(targets.end(), {t, t + 0.0005});
  targets.insert(targets.end(), {times[times.size() / 2], times[1], 0.0, times.back(), times[2] + 0.0004});
  for (const double t : targets) {
    if (t > source->replay()->end) continue;
    seek(*source, t);
    EXPECT_LE(source->now(), t + 1e-9);
    EXPECT_GT(source->now() + source->replay()->period, t - 1e-9) << "the last tick at or before " << t;
    expect_same(shown_states(*source), history_states(source->now()), t);
  }
}

TEST_F(RecordedStory, ReplayRunsFromTheRecordingsFirstToItsLastTickAndAtTheEndMatchesTheHistory) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  const ReplayView r = *source->replay();
  EXPECT_EQ(r.start, 0.0);
  EXPECT_NEAR(r.end, 2.0, 1e-9);  // the story's duration
  EXPECT_FALSE(r.playing);
  EXPECT_EQ(source->now(), 0.0);  // paused at the first tick
  seek(*source, r.end);
  EXPECT_FALSE(source->running());
  expect_same(shown_states(*source), history_states(r.end), r.end);
}

TEST_F(RecordedStory, NextRunsOnToTheNextTransitionOfTheHistoryAndPausesThere) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  const std::vector<double> times = transition_times();
  double now = source->now();
  for (const double expected : times) {
    if (expected <= now) continue;
    ReplayControl next;
    next.op = ReplayControl::Op::Next;
    ASSERT_TRUE(source->control(next).has_value());
    source->settle();
    EXPECT_NEAR(source->now(), expected, 1e-9);
    EXPECT_FALSE(source->replay()->playing);
    now = source->now();
  }
}

TEST_F(RecordedStory, ControlsRefuseWhatCannotBeDoneAndChangeNothing) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  seek(*source, 0.5);
  ReplayControl c;
  c.op = ReplayControl::Op::Seek;
  c.t = 9.0;
  auto r = source->control(c);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("t=9 is outside the replay (0.000000 s to 2.000000 s)"));
  c.op = ReplayControl::Op::Speed;
  c.speed = 0.0;
  r = source->control(c);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("above 0"));
  EXPECT_EQ(source->replay()->speed, 1.0);
  EXPECT_DOUBLE_EQ(source->now(), 0.5);
  // Read-only: the recording is what happened.
  auto w = source->apply(introspect::GenerateEvent{"EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"});
  ASSERT_FALSE(w.has_value());
  EXPECT_THAT(w.error().message, HasSubstr("read-only"));
  EXPECT_FALSE(source->apply(introspect::ResetState{"SYSTEM", "viewer", "x"}).has_value());
  EXPECT_FALSE(source->apply(introspect::InjectShallow{"force_limit", {{50.0}}}).has_value());
  seek(*source, 2.0);
  c.op = ReplayControl::Op::Next;
  r = source->control(c);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("at the end of the replay"));
}

TEST_F(RecordedStory, PlayAdvancesWithTheWallClockTimesTheSpeedAndStopsAtTheEnd) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  ReplayControl c;
  c.op = ReplayControl::Op::Speed;
  c.speed = 1000.0;
  ASSERT_TRUE(source->control(c).has_value());
  c.op = ReplayControl::Op::Play;
  ASSERT_TRUE(source->control(c).has_value());
  EXPECT_TRUE(source->replay()->playing);
  for (int i = 0; i < 400 && source->replay()->playing; ++i) {
    source->poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_FALSE(source->replay()->playing);
  EXPECT_NEAR(source->now(), 2.0, 1e-9);
}

TEST(ViewerReplaySource, ACsvLogShowsAtEveryTickTheStatesSafecassReplayPrintsForIt) {
  const std::string system = kSource + "/tests/data/replay/arm.json";
  const std::string log = kSource + "/tests/data/replay/arm_ok.csv";
  // What `safecass replay --json` prints for the same log: the transitions.
  replay::ReplayOptions o;
  o.system = system;
  o.input = log;
  o.json = true;
  std::FILE* out = std::tmpfile();
  std::FILE* err = std::tmpfile();
  ASSERT_NE(out, nullptr);
  o.out = out;
  o.err = err;
  FilterRegistry registry;
  register_builtin_filters(registry);
  ASSERT_EQ(replay::run_replay(o, registry), 0);
  std::rewind(out);
  std::vector<std::pair<double, std::string>> transitions;  // ARM.s_A's
  char line[4096];
  while (std::fgets(line, sizeof line, out) != nullptr) {
    const json::JsonParse p = json::parse_json(line, 16);
    if (!p.value || !p.value->is_object()) continue;
    const json::JsonValue* kind = p.value->find("kind");
    const json::JsonValue* machine = p.value->find("machine");
    if (kind != nullptr && kind->string == "transition" && machine != nullptr && machine->string == "ARM.s_A")
      transitions.emplace_back(p.value->find("t")->number, p.value->find("to")->string);
  }
  std::fclose(out);
  std::fclose(err);
  ASSERT_EQ(transitions.size(), 2u);  // the spike: Error at 0.003 s, Normal at 0.005 s

  ReplaySourceOptions ro;
  ro.system = system;
  ro.input = log;
  auto source = ReplaySource::open(ro);
  ASSERT_TRUE(source.has_value()) << source.error().message;
  const ReplayView r = *(*source)->replay();
  EXPECT_NEAR(r.end, 0.006, 1e-9);
  for (double t = r.end; t >= r.start - 1e-9; t -= r.period) {  // backwards: each seek starts over
    seek(**source, t);
    std::string expected = "Normal";
    for (const auto& [when, to] : transitions) {
      if (when <= t + 1e-9) expected = to;
    }
    EXPECT_EQ(shown_states(**source)["ARM.s_A"], expected) << "t=" << t;
  }
}

TEST(ViewerReplaySource, ABadLogIsRefusedWithFileLineAndTheReason) {
  ReplaySourceOptions o;
  o.system = kSource + "/tests/data/replay/arm.json";
  o.input = kSource + "/tests/data/replay/non_monotonic.csv";
  auto source = ReplaySource::open(o);
  ASSERT_FALSE(source.has_value());
  EXPECT_THAT(source.error().message,
              HasSubstr("non_monotonic.csv:4: time 0.001 s is before the previous row's 0.002 s"));
  o.input = kSource + "/tests/data/replay/unknown_signal.csv";
  source = ReplaySource::open(o);
  ASSERT_FALSE(source.has_value());
  EXPECT_THAT(source.error().message, HasSubstr("unknown_signal.csv:1"));
  o.input = "no/such.log";
  source = ReplaySource::open(o);
  ASSERT_FALSE(source.has_value());
  EXPECT_THAT(source.error().message, HasSubstr("no/such.log"));
  o.input = kSource + "/tests/data/replay/arm_ok.csv";
  o.system.clear();
  source = ReplaySource::open(o);
  ASSERT_FALSE(source.has_value());
  EXPECT_THAT(source.error().message, HasSubstr("--system"));
}

TEST_F(RecordedStory, ProtocolCarriesTheReplayAndItsControlsAndGreetsPagesAgainWhenItGoesBack) {
  auto source = open_replay();
  ASSERT_NE(source, nullptr);
  Protocol protocol(*source, ProtocolOptions{});
  EXPECT_THAT(protocol.hello(), HasSubstr(R"("replay":{"start":0.000000,"end":2.000000,"period":0.001000,)"));
  EXPECT_THAT(protocol.hello(), HasSubstr(R"("clock":{"base":"simulated"})"));
  EXPECT_THAT(protocol.hello(), HasSubstr(R"({"required":"CONTROL.ForceData","provided":"JR3.ForceData"})"));
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"seek","t":1.2})"), HasSubstr("seeking to t=1.200000"));
  long long ms = 0;
  std::string pushed;
  for (int i = 0; i < 100 && !source->replay()->busy.empty(); ++i) pushed += protocol.update(ms += 10);
  pushed += protocol.update(ms += 10);
  EXPECT_THAT(pushed, HasSubstr(R"("type":"update")"));
  EXPECT_THAT(pushed, HasSubstr(R"("kind":"component-transition")"));
  EXPECT_THAT(pushed, HasSubstr(R"("busy":"")"));
  // Back in time: the replay starts over, and every page is greeted again.
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"seek","t":0.1})"), HasSubstr("seeking to t=0.100000"));
  std::string again = protocol.update(ms += 10);
  EXPECT_THAT(again, HasSubstr(R"("type":"hello")"));
  // Bad controls get an error saying what is wrong.
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"rewind"})"), HasSubstr("unknown action 'rewind'"));
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"seek"})"), HasSubstr("needs 't'"));
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"speed","speed":-1})"), HasSubstr("above 0"));
  EXPECT_THAT(protocol.handle(R"({"op":"replay","action":"play","t":1})"), HasSubstr("takes neither"));
  // Writes are refused (the protocol of a replay is never write-enabled).
  EXPECT_THAT(protocol.handle(R"({"op":"reset","target":"SYSTEM"})"), HasSubstr("read-only"));
}

}  // namespace
}  // namespace safecass::viewer
