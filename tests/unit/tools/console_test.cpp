// `safecass console`: the command executor on the ROBODOC example, without a terminal.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "console.hpp"

namespace safecass::tools {
namespace {

const std::string kSource = SAFECASS_SOURCE_DIR;
const std::string kRobodoc = kSource + "/examples/robodoc/robodoc.json";
const std::string kStory = kSource + "/examples/robodoc/story.json";

std::unique_ptr<Console> open_console(bool allow_write, bool json = false, const std::string& scenario = {},
                                      const std::string& system = kRobodoc) {
  auto console = Console::open(system, scenario, ConsoleOptions{json, allow_write});
  EXPECT_TRUE(console.has_value()) << (console ? "" : console.error().message);
  return console ? std::move(*console) : nullptr;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::size_t count_lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

/// Everything a command could change, as the console shows it.
std::string observable(Console& console) {
  std::string all;
  for (const char* command : {"state list", "state history 100000", "event history 100000", "service list",
                              "connection list", "filter list", "time"}) {
    all += console.execute(command).out;
  }
  return all;
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

class ConsoleTest : public ::testing::Test {
protected:
  void SetUp() override {
    console = open_console(true);
    ASSERT_NE(console, nullptr);
  }
  ConsoleReply run(const std::string& line) {
    ConsoleReply r = console->execute(line);
    EXPECT_TRUE(r.ok) << line << ": " << r.err;
    EXPECT_TRUE(r.err.empty()) << line;
    return r;
  }
  std::unique_ptr<Console> console;
};

// ---- every command's happy path ----------------------------------------------------------------

TEST_F(ConsoleTest, StateListShowsEveryComponentAndMachineWithItsStateAndOutstandingEvent) {
  const std::string out = run("state list").out;
  for (const char* address : {"SYSTEM", "JR3", "JR3.s_F", "JR3.s_A", "JR3.s_P.ForceData", "BMM.s_P.BoneMotion",
                              "CONTROL.s_P.Command", "CONTROL.s_P.Status", "CONTROL.s_R.ForceData",
                              "CONTROL.s_R.BoneMotion", "SERVO.s_R.Command", "PENDANT.s_R.Status"}) {
    EXPECT_TRUE(contains(out, std::string(address) + " ")) << address << "\n" << out;
  }
  EXPECT_FALSE(contains(out, "Error"));
  run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  const std::string after = run("state list CONTROL").out;
  EXPECT_TRUE(contains(after, "CONTROL                   Error   EVT_CONTROL_FORCE_FREEZE")) << after;
  EXPECT_TRUE(contains(after, "  CONTROL.s_A             Error   EVT_CONTROL_FORCE_FREEZE")) << after;
  EXPECT_FALSE(contains(after, "JR3"));
}

TEST_F(ConsoleTest, StateSummaryCountsTheComponentsByStateAndListsThoseNotNormalAsStateListShowsThem) {
  EXPECT_EQ(run("state summary").out, "SYSTEM Normal: 5 components, 5 Normal, 0 Warning, 0 Error\n");
  run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  const std::string out = run("state summary").out;
  EXPECT_TRUE(contains(out, "SYSTEM Error: 5 components, ")) << out;
  EXPECT_TRUE(contains(out, "\n  CONTROL  Error")) << out;
  EXPECT_TRUE(contains(out, "EVT_CONTROL_FORCE_FREEZE\n")) << out;
  // Every component the summary lists is one that state list shows not Normal, and no other.
  const std::string states = run("state list").out;
  for (const char* component : {"JR3", "BMM", "CONTROL", "SERVO", "PENDANT"}) {
    const bool listed = contains(out, "\n  " + std::string(component) + " ");
    const bool normal =
        contains(states, "\n" + std::string(component) + " ") &&
        contains(states.substr(states.find("\n" + std::string(component) + " ")).substr(0, 40), "Normal");
    EXPECT_NE(listed, normal) << component << "\n" << out << states;
  }
  auto json = open_console(true, true);
  ASSERT_NE(json, nullptr);
  EXPECT_EQ(json->execute("state summary").out,
            R"({"system":"Normal","normal":5,"warning":0,"error":0,"not_normal":[]})"
            "\n");
  const ConsoleReply extra = console->execute("state summary JR3");
  EXPECT_FALSE(extra.ok) << "state summary takes no argument";
}

TEST_F(ConsoleTest, AnalyzeNowSaysEveryHazardIsUncoveredWhileNoFilterHasJudgedASample) {
  // The console's system has not run: no filter has a sample to judge, so nothing can be detected.
  const std::string out = run("analyze now").out;
  EXPECT_TRUE(contains(out, "hazard H-3: UNCOVERED\n  EVT_FORCE_ERROR: filter force_limit has judged no sample yet\n"))
      << out << "(EVT_CONTROL_FORCE_FREEZE, raised by CONTROL's code, is no gap)";
  EXPECT_TRUE(contains(out, " hazards, ")) << out;
  auto json = open_console(true, true);
  ASSERT_NE(json, nullptr);
  const std::string answer = json->execute("analyze now").out;
  EXPECT_TRUE(contains(answer, R"("hazard":"H-3","covered":false)")) << answer;
  EXPECT_FALSE(console->execute("analyze now H-3").ok) << "analyze now takes no argument";
}

TEST_F(ConsoleTest, StateHistoryShowsTheRecordsOfAnAddressOrOfTheSystem) {
  run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  const std::string machine = run("state history CONTROL.s_A").out;
  EXPECT_TRUE(contains(machine, "CONTROL.s_A  raised EVT_CONTROL_FORCE_FREEZE")) << machine;
  EXPECT_TRUE(contains(machine, "CONTROL.s_A  Normal -> Error  EVT_CONTROL_FORCE_FREEZE")) << machine;
  EXPECT_FALSE(contains(machine, "SERVO"));
  const std::string system = run("state history").out;
  EXPECT_TRUE(contains(system, "SERVO.s_R.Command  Normal -> Error  EVT_SERVICE_FAILURE")) << system;
  EXPECT_EQ(count_lines(run("state history 2").out), 2u);
  EXPECT_EQ(count_lines(run("state history CONTROL.s_A 1").out), 1u);
  EXPECT_TRUE(contains(run("state history BMM").out, "no records"));
}

TEST_F(ConsoleTest, FilterListNamesEveryFilterWithItsTypeTargetAndSignals) {
  const std::string out = run("filter list").out;
  for (const char* name : {"force_vector", "force_norm", "force_limit", "force_warning", "force_stale", "bone_motion",
                           "tracking", "servo_duty"}) {
    EXPECT_TRUE(contains(out, name)) << name;
  }
  EXPECT_TRUE(contains(out, "force_stale    Watchdog   JR3.s_F      PASSIVE  EDGE  enabled  -  JR3.Force")) << out;
  EXPECT_TRUE(contains(out, "JR3.Fx,JR3.Fy,JR3.Fz -> JR3.Force")) << out;
}

TEST_F(ConsoleTest, FilterInfoShowsTheManifestAndTheFiltersCurrentState) {
  const std::string out = run("filter info force_limit").out;
  EXPECT_TRUE(contains(out, "filter force_limit: Threshold")) << out;
  EXPECT_TRUE(contains(out, "target JR3.s_A, ACTIVE, EDGE")) << out;
  EXPECT_TRUE(contains(out, "enabled, not detected")) << out;
  EXPECT_TRUE(contains(out, "inputs:  JR3.ForceNorm (size 1)")) << out;
  // Each parameter: name, type, value, default, range, doc.
  EXPECT_TRUE(contains(out, "threshold")) << out;
  EXPECT_TRUE(contains(out, "hysteresis")) << out;
  EXPECT_TRUE(contains(out, "number")) << out;
  EXPECT_TRUE(contains(out, "above|below")) << out;
  EXPECT_TRUE(contains(out, "(required)")) << out;
  EXPECT_TRUE(contains(out, "[0, +inf]")) << out;
  run("filter inject force_limit 50");
  run("watch 0.002");
  EXPECT_TRUE(contains(run("filter info force_limit").out, "enabled, injected, detected"));

  const std::string type = run("filter info Watchdog").out;
  EXPECT_TRUE(contains(type, "filter type Watchdog")) << type;
  EXPECT_TRUE(contains(type, "timeout")) << type;
}

TEST_F(ConsoleTest, ShallowInjectionIsSeenByThatFilterAlone) {
  const std::string out = run("filter inject force_limit 50 50").out;
  EXPECT_TRUE(contains(out, "queued 2 samples into filter force_limit")) << out;
  EXPECT_TRUE(contains(out, "injection")) << out;  // the record on the observer stream
  const std::string watched = run("watch 0.003").out;
  EXPECT_TRUE(contains(watched, "JR3.s_A  Normal -> Error  EVT_FORCE_ERROR")) << watched;
  EXPECT_TRUE(contains(watched, "injected")) << watched;
  // force_warning reads the same signal and saw nothing.
  EXPECT_FALSE(contains(run("explain JR3.s_A").out, "EVT_FORCE_HIGH"));
}

TEST(ConsoleInjection, TheEndOfAShallowInjectionFromTheConsoleRestoresTheRealValueOfAnOnChangeSensor) {
  // A door sensor that publishes once (closed) and then only on change (DESIGN §3).
  const std::string system = write_file("door_system.json", R"({ "component": "CELL",
    "signals": [ { "name": "DoorOpen" } ],
    "event": [ { "name": "EVT_DOOR", "severity": 40, "state_transition": ["N2E"] },
               { "name": "/EVT_DOOR", "severity": 40, "state_transition": ["E2N"] } ],
    "filter": [ { "name": "door", "class_name": "OnOff",
                  "argument": { "input_signal": "DoorOpen", "event_on": "EVT_DOOR" } } ] })");
  const std::string scenario = write_file("door_scenario.json", R"({ "system": "door_system.json", "duration": 1.0,
    "steps": [ { "at": 0.0, "sample": { "CELL.DoorOpen": 0 } } ] })");
  auto console = open_console(true, false, scenario, system);
  ASSERT_NE(console, nullptr);
  ASSERT_TRUE(console->execute("watch 0.01").ok);
  ASSERT_TRUE(console->execute("filter inject door 1").ok);
  const std::string watched = console->execute("watch 0.01").out;
  EXPECT_TRUE(contains(watched, "CELL.s_A  Normal -> Error  EVT_DOOR")) << watched;
  EXPECT_TRUE(contains(watched, "CELL.s_A  Error -> Normal  /EVT_DOOR"))
      << "the real value, closed, is judged again: " << watched;
  EXPECT_TRUE(contains(console->execute("state list CELL").out, "Normal"));
}

TEST_F(ConsoleTest, DeepInjectionIsSeenByEveryConsumerOfTheSignal) {
  const std::string out = run("filter dinject JR3.Force [0, 0, 50]").out;
  EXPECT_TRUE(contains(out, "wrote 1 sample into signal JR3.Force")) << out;
  EXPECT_TRUE(contains(out, "injection  (deep injection into signal JR3.Force: [0, 0, 50])")) << out;
  run("watch 0.003");
  const std::string why = run("explain JR3.s_A").out;
  // Both thresholds read the norm of the injected force.
  EXPECT_TRUE(contains(why, "EVT_FORCE_ERROR (severity 50)")) << why;
  EXPECT_TRUE(contains(why, "EVT_FORCE_HIGH (severity 30)")) << why;
  EXPECT_TRUE(contains(why, "JR3.ForceNorm = 50")) << why;
}

TEST_F(ConsoleTest, ADeepInjectionIsRecordedOnceOnEachMachineWhoseFiltersReadTheSignal) {
  // JR3.ForceNorm is read by two filters of JR3.s_A (force_limit, force_warning): one record.
  run("filter dinject JR3.ForceNorm 40");
  const std::string norm = run("state history JR3 100").out;
  EXPECT_EQ(count_lines(norm), 1u) << norm;
  EXPECT_TRUE(contains(norm, "JR3.s_A  injection  (deep injection into signal JR3.ForceNorm: 40)")) << norm;
  // JR3.Force is read by force_norm (s_A) and force_stale (s_F): one record on each.
  run("filter dinject JR3.Force [0, 0, 10]");
  const std::string force = run("state history JR3 100").out;
  EXPECT_EQ(count_lines(force), 3u) << force;
  EXPECT_TRUE(contains(force, "JR3.s_A  injection  (deep injection into signal JR3.Force: [0, 0, 10])")) << force;
  EXPECT_TRUE(contains(force, "JR3.s_F  injection  (deep injection into signal JR3.Force: [0, 0, 10])")) << force;
}

TEST_F(ConsoleTest, DinloadInjectsEverySampleOfAFile) {
  const std::string file = write_file("console_dinload.txt", "# Fx Fy Fz\n0, 0, 10\n\n0 0 45  # too much\n0,0,46\n");
  const std::string out = run("filter dinload JR3.Force " + file).out;
  EXPECT_TRUE(contains(out, "wrote 3 samples into signal JR3.Force")) << out;
  run("watch 0.003");
  const std::string states = run("state list JR3").out;
  EXPECT_TRUE(contains(states, "  JR3.s_A            Error   EVT_FORCE_ERROR")) << states;
}

TEST_F(ConsoleTest, EventListShowsEveryEventWithItsDefinition) {
  const std::string out = run("event list").out;
  EXPECT_TRUE(contains(out, "EVT_FORCE_ERROR")) << out;
  EXPECT_TRUE(contains(out, "50   onset       N2E,W2E  cleared by /EVT_FORCE_ERROR, hazard H-3")) << out;
  EXPECT_TRUE(contains(out, "/EVT_FORCE_ERROR")) << out;
  EXPECT_TRUE(contains(out, "latched")) << out;              // EVT_BONE_MOTION
  EXPECT_TRUE(contains(out, "EVT_SERVICE_FAILURE")) << out;  // framework events too
}

TEST_F(ConsoleTest, EventHistoryShowsTheEventsProcessedIgnoredOrMasked) {
  EXPECT_TRUE(contains(run("event history").out, "no events yet"));
  run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  run("event generate /EVT_BONE_MOTION BMM.s_A");  // ignored: not active
  const std::string out = run("event history").out;
  EXPECT_TRUE(contains(out, "CONTROL.s_A  raised EVT_CONTROL_FORCE_FREEZE")) << out;
  EXPECT_TRUE(contains(out, "BMM.s_A  ignored /EVT_BONE_MOTION  (not active)")) << out;
  EXPECT_FALSE(contains(out, "->")) << out;  // events only, no transitions
  EXPECT_EQ(count_lines(run("event history 1").out), 1u);
}

TEST_F(ConsoleTest, EventGenerateProcessesTheEventAndPrintsWhatItChanged) {
  const std::string out = run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A").out;
  EXPECT_TRUE(contains(out, "generated EVT_CONTROL_FORCE_FREEZE on CONTROL.s_A at t=0.000000")) << out;
  EXPECT_TRUE(contains(out, "CONTROL.s_A  Normal -> Error  EVT_CONTROL_FORCE_FREEZE")) << out;
  EXPECT_TRUE(
      contains(out, "SERVO.s_R.Command  Normal -> Error  EVT_SERVICE_FAILURE  <- CONTROL.s_A:EVT_CONTROL_FORCE_FREEZE"))
      << out;
  const std::string states = run("state list").out;
  EXPECT_TRUE(contains(states, "SYSTEM                    Error   -")) << states;
  run("event generate /EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  EXPECT_FALSE(contains(run("state list").out, "Error"));
}

TEST(ConsoleBroadcast, EventBroadcastReachesTheApplicationMachineOfEveryComponent) {
  const std::string system = write_file("console_broadcast.json", R"({
    "safecass": 1, "system": "cell",
    "components": [
      { "component": "ARM", "event": [
          { "name": "EVT_ESTOP", "severity": 255, "state_transition": ["N2E"] },
          { "name": "/EVT_ESTOP", "severity": 255, "state_transition": ["E2N"] } ] },
      { "component": "TOOL" } ] })");
  auto console = open_console(true, false, {}, system);
  ASSERT_NE(console, nullptr);
  const ConsoleReply r = console->execute("event broadcast EVT_ESTOP");
  ASSERT_TRUE(r.ok) << r.err;
  EXPECT_TRUE(contains(r.out, "broadcast EVT_ESTOP")) << r.out;
  EXPECT_TRUE(contains(r.out, "ARM.s_A  Normal -> Error  EVT_ESTOP")) << r.out;
  EXPECT_TRUE(contains(r.out, "TOOL.s_A  Normal -> Error  EVT_ESTOP")) << r.out;
  EXPECT_TRUE(contains(console->execute("event list").out, "255  broadcast")) << console->execute("event list").out;
}

TEST_F(ConsoleTest, ConnectionListShowsEveryConnectionWithBothEndsStates) {
  const std::string out = run("connection list").out;
  EXPECT_TRUE(contains(out, "CONTROL.ForceData   ->  JR3.ForceData    s_R Normal  s_S Normal  propagates Error"))
      << out;
  EXPECT_TRUE(
      contains(out, "PENDANT.Status      ->  CONTROL.Status   s_R Normal  s_S Normal  propagates Warning and Error"))
      << out;
  EXPECT_EQ(count_lines(out), 4u);
}

TEST_F(ConsoleTest, ServiceListShowsEveryServiceStateAndItsDependencyFormula) {
  const std::string out = run("service list").out;
  EXPECT_TRUE(contains(out, "CONTROL.s_S.Command  Normal  = s_P.Command * s_F * s_A * s_R.ForceData * s_R.BoneMotion"))
      << out;
  EXPECT_TRUE(contains(out, "JR3.s_S.ForceData    Normal  = s_P.ForceData * s_F * s_A")) << out;
  EXPECT_TRUE(contains(out, "(propagates Warning and Error)")) << out;
  run("event generate EVT_FORCE_ERROR JR3.s_A");
  EXPECT_TRUE(contains(run("service list").out, "CONTROL.s_S.Command  Error"));
}

TEST_F(ConsoleTest, ExplainGivesEachConditionWithItsRootCauseAndPath) {
  EXPECT_TRUE(contains(run("explain SERVO").out, "SERVO is Normal: no active condition"));
  run("event generate EVT_FORCE_ERROR JR3.s_A");
  const std::string out = run("explain SERVO").out;
  EXPECT_TRUE(contains(out, "SERVO.s_R.Command: Error EVT_SERVICE_FAILURE (severity 220) <- JR3.s_A:EVT_FORCE_ERROR"))
      << out;
  EXPECT_TRUE(contains(out, "[hazard H-3]")) << out;
  EXPECT_TRUE(contains(out, "path JR3.s_A -> ")) << out;
}

TEST_F(ConsoleTest, WatchAdvancesSimulatedTimeAndPrintsEachTransition) {
  EXPECT_TRUE(contains(run("time").out, "t=0.000000 s"));
  // No samples at all: the force sensor's watchdog (50 ms) fires.
  const std::string out = run("watch 0.1").out;
  EXPECT_TRUE(contains(out, "JR3.s_F  Normal -> Error  EVT_FORCE_STALE")) << out;
  EXPECT_TRUE(contains(out, "t=0.100000  watched 0.1 s:")) << out;
  EXPECT_TRUE(contains(run("time").out, "t=0.100000 s"));
  run("watch");
  EXPECT_TRUE(contains(run("time").out, "t=1.100000 s"));
}

TEST(ConsoleScenario, WatchAppliesTheScenarioStepsAsTimeAdvances) {
  auto console = open_console(false, false, kStory, "");
  ASSERT_NE(console, nullptr);
  EXPECT_TRUE(contains(console->banner(), "scenario")) << console->banner();
  const ConsoleReply first = console->execute("watch 0.5");
  ASSERT_TRUE(first.ok) << first.err;
  EXPECT_TRUE(contains(first.out, "JR3.s_A  Normal -> Warning  EVT_FORCE_HIGH")) << first.out;
  EXPECT_TRUE(contains(first.out, "JR3.s_A  Warning -> Error  EVT_FORCE_ERROR")) << first.out;
  const std::string states = console->execute("state list CONTROL").out;
  EXPECT_TRUE(contains(states, "CONTROL                   Error   EVT_SERVICE_FAILURE")) << states;
  // The rest of the story: its expectations hold when time advances in pieces, as in `safecass run`.
  const ConsoleReply rest = console->execute("watch 1.5");
  EXPECT_FALSE(contains(rest.out, "expectation")) << rest.out;
  EXPECT_TRUE(contains(rest.out, "BMM.s_A  reset  (scenario: surgeon re-registered the bone)")) << rest.out;
  EXPECT_TRUE(contains(console->execute("time").out, "t=2.000000 s (simulated; tick 0.001 s; scenario"));
}

TEST_F(ConsoleTest, ResetClearsEveryConditionOfTheTargetAndRecordsTheReason) {
  run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A");
  const std::string out = run("reset CONTROL motion checked by the operator").out;
  EXPECT_TRUE(contains(out, "reset CONTROL at t=0.000000 (motion checked by the operator)")) << out;
  EXPECT_TRUE(contains(out, "CONTROL.s_A  Error -> Normal")) << out;
  EXPECT_FALSE(contains(run("state list").out, "Error"));
  EXPECT_TRUE(contains(run("state history CONTROL.s_A").out, "console: motion checked by the operator"));
}

TEST_F(ConsoleTest, HelpListsEveryCommandAndShowsOneCommandsUsage) {
  const std::string all = run("help").out;
  for (const char* usage : {"state list",
                            "state history [ADDRESS] [N]",
                            "filter list",
                            "filter info NAME",
                            "filter inject NAME SAMPLE...",
                            "filter dinject SIGNAL SAMPLE...",
                            "filter dinload SIGNAL FILE",
                            "event list",
                            "event history [N]",
                            "event generate EVENT TARGET",
                            "event broadcast EVENT",
                            "connection list",
                            "service list",
                            "explain ADDRESS",
                            "watch [SECONDS]",
                            "reset TARGET [REASON]",
                            "time",
                            "help [COMMAND]",
                            "quit",
                            "state summary"}) {
    EXPECT_TRUE(contains(all, usage)) << usage;
  }
  const std::string one = run("help filter dinload").out;
  EXPECT_TRUE(contains(one, "usage: filter dinload SIGNAL FILE")) << one;
  EXPECT_TRUE(contains(one, "needs --allow-write")) << one;
  EXPECT_EQ(count_lines(run("help state").out), 3u);  // state list, state summary, state history
  EXPECT_TRUE(contains(run("help exit").out, "usage: quit"));
}

TEST_F(ConsoleTest, QuitAndExitEndTheConsole) {
  EXPECT_TRUE(run("quit").quit);
  EXPECT_TRUE(run("exit").quit);
  EXPECT_FALSE(run("time").quit);
}

TEST_F(ConsoleTest, EmptyLinesAndCommentsDoNothing) {
  EXPECT_TRUE(run("").out.empty());
  EXPECT_TRUE(run("   ").out.empty());
  EXPECT_TRUE(run("# a comment").out.empty());
}

// ---- writes need --allow-write -----------------------------------------------------------------

TEST(ConsoleReadOnly, EveryWriteIsRefusedAndChangesNothing) {
  auto console = open_console(false);
  ASSERT_NE(console, nullptr);
  const std::string file = write_file("console_refused.txt", "0 0 50\n");
  const std::string before = observable(*console);
  for (const std::string& line : std::vector<std::string>{
           "filter inject force_limit 50", "filter dinject JR3.Force [0,0,50]", "filter dinload JR3.Force " + file,
           "event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A", "event broadcast EVT_CONTROL_FORCE_FREEZE",
           "reset SYSTEM"}) {
    const ConsoleReply r = console->execute(line);
    EXPECT_FALSE(r.ok) << line;
    EXPECT_TRUE(r.out.empty()) << line;
    EXPECT_TRUE(contains(r.err, "refused")) << r.err;
    EXPECT_TRUE(contains(r.err, "--allow-write")) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  }
  EXPECT_EQ(observable(*console), before);
  // Injections would show after time advances: nothing was queued or written.
  EXPECT_FALSE(contains(console->execute("watch 0.01").out, "Error"));
  // Reading stays allowed.
  EXPECT_TRUE(console->execute("state list").ok);
  EXPECT_TRUE(console->execute("explain SYSTEM").ok);
}

// ---- bad commands: one usage line, nothing changes ---------------------------------------------

TEST_F(ConsoleTest, BadCommandsGiveOneUsageLineAndChangeNothing) {
  const std::string before = observable(*console);
  const std::vector<std::string> bad = {"frobnicate",
                                        "state",
                                        "state frob",
                                        "state list NOPE",
                                        "state list JR3 BMM",
                                        "state history JR3 0",
                                        "state history NOPE.s_A",
                                        "state history JR3 5 6",
                                        "filter",
                                        "filter info",
                                        "filter info nope",
                                        "filter info force_limit extra",
                                        "filter inject force_limit",
                                        "filter inject force_limit abc",
                                        "filter inject force_limit [1,2",
                                        "filter inject nope 1",
                                        "filter inject force_limit [1,2,3]",
                                        "filter inject force_limit 1 x",
                                        "filter dinject JR3.Force 1",
                                        "filter dinject JR3.Nope 1",
                                        "filter dinject JR3.Force []",
                                        "filter dinload JR3.Force /nonexistent/samples.txt",
                                        "filter dinload JR3.Force",
                                        "event",
                                        "event generate EVT_NOPE CONTROL.s_A",
                                        "event generate EVT_CONTROL_FORCE_FREEZE NOPE.s_A",
                                        "event generate EVT_CONTROL_FORCE_FREEZE CONTROL",
                                        "event generate EVT_CONTROL_FORCE_FREEZE",
                                        "event broadcast EVT_FORCE_ERROR",
                                        "event broadcast",
                                        "event history x",
                                        "connection",
                                        "connection list x",
                                        "service list x",
                                        "explain",
                                        "explain NOPE",
                                        "explain JR3.s_X",
                                        "watch -1",
                                        "watch 0",
                                        "watch abc",
                                        "watch 1 2",
                                        "watch 100000",
                                        "watch nan",
                                        "reset",
                                        "reset NOPE",
                                        "time now",
                                        "help nope",
                                        "quit now",
                                        "state list 'unterminated",
                                        "reset [1,2"};
  for (const std::string& line : bad) {
    const ConsoleReply r = console->execute(line);
    EXPECT_FALSE(r.ok) << line;
    EXPECT_FALSE(r.quit) << line;
    EXPECT_TRUE(r.out.empty()) << line << " printed " << r.out;
    EXPECT_EQ(count_lines(r.err), 1u) << line << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "(usage: ")) << line << ": " << r.err;
  }
  EXPECT_EQ(observable(*console), before);
  // The console goes on.
  EXPECT_TRUE(run("event generate EVT_CONTROL_FORCE_FREEZE CONTROL.s_A").ok);
}

TEST_F(ConsoleTest, ABadDinloadFileNamesTheLineAndInjectsNothing) {
  const std::string file = write_file("console_bad_dinload.txt", "0 0 50\n0 0 fifty\n");
  const std::string before = observable(*console);
  const ConsoleReply r = console->execute("filter dinload JR3.Force " + file);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(contains(r.err, "console_bad_dinload.txt:2: 'fifty' is not a number")) << r.err;
  EXPECT_EQ(observable(*console), before);
  const std::string sizes = write_file("console_bad_sizes.txt", "0 0 50\n1\n");
  EXPECT_FALSE(console->execute("filter dinload JR3.Force " + sizes).ok);
  EXPECT_FALSE(contains(console->execute("watch 0.01").out, "EVT_FORCE_ERROR"));
}

TEST_F(ConsoleTest, DinloadReadsRegularFilesOnlyAndRefusesDevicesFifosDirectoriesAndHugeFilesAtOnce) {
  std::string pattern = ::testing::TempDir() + "/console-dinload-XXXXXX";
  ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
  const std::string dir = pattern;
  const std::string fifo = dir + "/samples.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string big = dir + "/big.txt";
  std::ofstream(big).close();
  ASSERT_EQ(::truncate(big.c_str(), (off_t{64} << 20) + 1), 0);  // sparse: nothing on the disk
  const std::string before = observable(*console);
  const auto started = std::chrono::steady_clock::now();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/dev/zero", "cannot read file '/dev/zero': not a regular file (a character device)"},
      {fifo, "cannot read file '" + fifo + "': not a regular file (a FIFO)"},
      {dir, "cannot read file '" + dir + "': not a regular file (a directory)"},
      {big, "cannot read file '" + big + "': larger than 64 MiB (67108865 bytes)"},
  };
  for (const auto& [file, message] : cases) {
    const ConsoleReply r = console->execute("filter dinload JR3.Force " + file);
    EXPECT_FALSE(r.ok) << file;
    EXPECT_TRUE(contains(r.err, message)) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  }
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(5)) << "nothing hung";
  EXPECT_EQ(observable(*console), before);
  std::filesystem::remove_all(dir);
}

TEST_F(ConsoleTest, InjectingANonFiniteValueIsRefusedOnEveryPathAndChangesNothing) {
  const std::string before = observable(*console);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"filter inject force_limit inf", "'inf' is not a finite number: injected values must be finite"},
      {"filter inject force_limit 10 -inf", "'-inf' is not a finite number: injected values must be finite"},
      {"filter inject force_limit nan", "'nan' is not a finite number: injected values must be finite"},
      {"filter dinject JR3.Force [0,0,inf]", "'inf' is not a finite number: injected values must be finite"},
      {"filter dinject JR3.Force [NaN 0 0]", "'NaN' is not a finite number: injected values must be finite"},
      {"filter dinject JR3.Force [0,0,1e999]", "'1e999' is not a number"},
  };
  for (const auto& [line, message] : cases) {
    const ConsoleReply r = console->execute(line);
    EXPECT_FALSE(r.ok) << line;
    EXPECT_TRUE(contains(r.err, message)) << line << ": " << r.err;
  }
  const std::string file = write_file("console_infinite_dinload.txt", "0 0 10\n0, 0, -inf\n");
  const ConsoleReply r = console->execute("filter dinload JR3.Force " + file);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(
      contains(r.err, "console_infinite_dinload.txt:2: '-inf' is not a finite number: injected values must be finite"))
      << r.err;
  EXPECT_EQ(observable(*console), before);
  EXPECT_FALSE(contains(console->execute("watch 0.05").out, "EVT_INVALID_SAMPLE"));
}

TEST_F(ConsoleTest, UsageNamesTheCommandThatWasMistyped) {
  EXPECT_EQ(console->execute("filter info").err, "filter info: missing arguments (usage: filter info NAME)\n");
  EXPECT_EQ(console->execute("frob").err, "unknown command 'frob' (usage: help [COMMAND])\n");
  EXPECT_EQ(
      console->execute("state").err,
      "state: needs a subcommand (usage: state list [COMPONENT] | state summary | state history [ADDRESS] [N])\n");
}

TEST(ConsoleOpen, ABadSystemOrScenarioIsAnErrorWithItsDiagnostics) {
  EXPECT_FALSE(Console::open(kSource + "/no/such/system.json", {}, {}).has_value());
  EXPECT_FALSE(Console::open({}, {}, {}).has_value());
  const std::string bad =
      write_file("console_bad_system.json", "{ \"safecass\": 1, \"components\": [ { \"component\": 5 } ] }");
  auto r = Console::open(bad, {}, {});
  ASSERT_FALSE(r.has_value());
  EXPECT_TRUE(contains(r.error().message, "console_bad_system.json:1:")) << r.error().message;
}

// ---- JSON output ---------------------------------------------------------------------------------

TEST(ConsoleJson, EveryResultLineIsOneJsonObject) {
  auto console = open_console(true, true);
  ASSERT_NE(console, nullptr);
  for (const char* line :
       {"state list", "filter list", "filter info force_limit", "filter info Threshold", "event list",
        "event generate EVT_FORCE_ERROR JR3.s_A", "state history", "event history", "connection list", "service list",
        "explain CONTROL", "watch 0.06", "time", "help", "reset SYSTEM operator", "filter inject force_limit 1",
        "filter dinject JR3.Force [1,2,3]"}) {
    const ConsoleReply r = console->execute(line);
    ASSERT_TRUE(r.ok) << line << ": " << r.err;
    ASSERT_FALSE(r.out.empty()) << line;
    std::size_t start = 0;
    while (start < r.out.size()) {
      const std::size_t end = r.out.find('\n', start);
      const std::string object = r.out.substr(start, end - start);
      EXPECT_TRUE(object.size() >= 2 && object.front() == '{' && object.back() == '}') << line << ": " << object;
      start = end + 1;
    }
  }
  EXPECT_TRUE(contains(console->execute("state list JR3").out,
                       R"({"address":"JR3.s_F","kind":"framework","state":"Normal","outstanding":null})"));
  const ConsoleReply bad = console->execute("filter info nope");
  EXPECT_FALSE(bad.ok);
  EXPECT_TRUE(contains(bad.err, R"({"ok":false,"command":"filter info","error":)")) << bad.err;
  EXPECT_TRUE(contains(bad.err, R"("usage":"filter info NAME"})")) << bad.err;
}

// ---- completion ----------------------------------------------------------------------------------

TEST_F(ConsoleTest, CompletionOffersCommandWordsThenTheNamesEachCommandTakes) {
  using V = std::vector<std::string>;
  EXPECT_EQ(console->complete("", "st"), V{"state"});
  EXPECT_EQ(console->complete("", "e"), (V{"event", "exit", "explain"}));
  EXPECT_EQ(console->complete("state ", "li"), V{"list"});
  EXPECT_EQ(console->complete("filter ", "d"), (V{"dinject", "dinload"}));
  EXPECT_EQ(console->complete("event generate ", "EVT_CONTROL_F"), V{"EVT_CONTROL_FORCE_FREEZE"});
  EXPECT_EQ(console->complete("event generate EVT_CONTROL_FORCE_FREEZE ", "CONTROL.s_"),
            (V{"CONTROL.s_A", "CONTROL.s_F", "CONTROL.s_P.Command", "CONTROL.s_P.Status", "CONTROL.s_R.BoneMotion",
               "CONTROL.s_R.ForceData"}));
  EXPECT_EQ(console->complete("explain ", "JR3.s_S"), V{"JR3.s_S.ForceData"});
  EXPECT_EQ(console->complete("state list ", "P"), V{"PENDANT"});
  EXPECT_EQ(console->complete("filter info ", "force_l"), V{"force_limit"});
  EXPECT_EQ(console->complete("filter info ", "Thr"), V{"Threshold"});
  EXPECT_EQ(console->complete("filter inject ", "servo"), V{"servo_duty"});
  EXPECT_EQ(console->complete("filter dinject ", "JR3.Force"), (V{"JR3.Force", "JR3.ForceNorm"}));
  EXPECT_EQ(console->complete("reset ", "SYS"), V{"SYSTEM"});
  EXPECT_EQ(console->complete("help ", "con"), V{"connection"});
  EXPECT_EQ(console->complete("help event ", "g"), V{"generate"});
  EXPECT_TRUE(console->complete("time ", "").empty());
  EXPECT_TRUE(console->complete("filter inject force_limit ", "").empty());
  EXPECT_TRUE(console->completes_file("filter dinload JR3.Force "));
  EXPECT_FALSE(console->completes_file("filter dinject JR3.Force "));
}

TEST(ConsoleBatch, DashCTextIsCutAtEverySemicolonAndLineEndAndKeepsEmptyCommands) {
  EXPECT_EQ(split_commands("state list; filter list\nevent list"),
            (std::vector<std::string>{"state list", " filter list", "event list"}));
  EXPECT_EQ(split_commands(";;"), (std::vector<std::string>{"", "", ""}))
      << "each an empty command, which does nothing";
  EXPECT_EQ(split_commands("time"), (std::vector<std::string>{"time"}));
}

}  // namespace
}  // namespace safecass::tools
