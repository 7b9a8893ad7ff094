// Multi-process SAFECASS through a real IceStorm (DESIGN §2.6 across processes, §4, §7): the
// robodoc example split into its two coordinators (robot, ui), each a `safecass run` process,
// driven and observed through the remote operations (RemoteClient).
//
// Environment (set by tests/integration/middleware/CMakeLists.txt):
//   SAFECASS_BIN             the safecass command
//   SAFECASS_SOURCE_DIR      the repository (examples, scripts)
//   SAFECASS_ICESTORM_ENV    file written by the fixture's scripts/start-icestorm --env
//   SAFECASS_SCRATCH         a directory for logs and token files
// Every process a test starts is stopped by PID when the test ends, whatever its outcome.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fixture.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/spec/load.hpp"

namespace safecass {
namespace {

using namespace std::chrono_literals;
namespace in = introspect;

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? v : "";
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string env_file_value(const std::string& file, const std::string& key) {
  std::istringstream lines(slurp(file));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
  }
  return "";
}

/// A child process with its output in a log file; killed by PID when it goes out of scope.
class Process {
public:
  Process(std::vector<std::string> argv, std::string log) : log_(std::move(log)) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      std::vector<char*> args;
      for (std::string& a : argv) args.push_back(a.data());
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      std::_Exit(127);
    }
  }
  ~Process() { stop(SIGTERM); }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  /// Sends `sig` and waits for the process (SIGKILL after 3 s).
  void stop(int sig) {
    if (pid_ <= 0) return;
    ::kill(pid_, sig);
    for (int i = 0; i < 300; ++i) {
      if (::waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(10ms);
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  std::string output() const { return slurp(log_); }
  pid_t pid() const { return pid_; }

private:
  pid_t pid_ = -1;
  std::string log_;
};

/// Polls `ok` every 20 ms until it holds or `timeout` passes.
bool eventually(const std::function<bool()>& ok, std::chrono::milliseconds timeout = 5000ms) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (ok()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return ok();
}

struct Paths {
  std::string bin = env("SAFECASS_BIN");
  std::string source = env("SAFECASS_SOURCE_DIR");
  std::string scratch = env("SAFECASS_SCRATCH");
  std::string system = source + "/examples/robodoc/robodoc.json";
  std::string feed = source + "/tests/integration/middleware/robot_feed.json";
};

/// The robodoc system as two processes on one IceStorm.
struct TwoProcesses {
  Paths p;
  std::string ice;
  std::string tag;
  std::unique_ptr<Process> robot, ui;

  TwoProcesses(std::string ice_endpoint, std::string test_tag)
      : ice(std::move(ice_endpoint)), tag(std::move(test_tag)) {}

  std::string token_file() const { return p.scratch + "/" + tag + "-robot.token"; }
  /// The robot's write token, once it has started and written its token file: up to 15 s (a
  /// process starting beside a loaded machine took over 5); none when it did not.
  std::optional<std::string> await_token() const {
    std::optional<std::string> token;
    (void)eventually(
        [&] {
          if (auto t = middleware::read_token_file(token_file())) token = std::move(*t);
          return token.has_value();
        },
        15000ms);
    return token;
  }
  void start_robot() {
    // A token file left by an earlier run (a process killed before it could remove it) must not be
    // read as this robot's.
    std::remove(token_file().c_str());
    robot = std::make_unique<Process>(
        std::vector<std::string>{p.bin, "run", p.system, "--coordinator", "robot", "--scenario", p.feed, "--ice", ice,
                                 "--allow-write", "--token-file", token_file(), "--duration", "40"},
        p.scratch + "/" + tag + "-robot.log");
  }
  void start_ui(std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{p.bin, "run", p.system, "--coordinator", "ui", "--ice", ice, "--duration", "40"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    ui = std::make_unique<Process>(std::move(argv), p.scratch + "/" + tag + "-ui.log");
  }
  std::unique_ptr<middleware::RemoteClient> client(const std::string& coordinator, const std::string& token = {}) {
    middleware::ClientOptions o;
    o.ice = *middleware::parse_ice_endpoint(ice);
    o.coordinator = coordinator;
    o.token = token;
    o.timeout = 3000ms;
    std::unique_ptr<middleware::RemoteClient> c;
    eventually(
        [&] {
          auto r = middleware::RemoteClient::connect(o);
          if (r) c = std::move(*r);
          return c != nullptr;
        },
        10000ms);
    return c;
  }
  std::string logs() const {
    return "--- robot ---\n" + (robot ? robot->output() : "") + "--- ui ---\n" + (ui ? ui->output() : "");
  }
};

/// The state of `address` as `c` reads it; nothing when the read fails or has no such row (never
/// taken for Normal).
std::optional<State> state_of(middleware::RemoteClient& c, const std::string& address) {
  const auto component = address.substr(0, address.find('.'));
  auto rows = c.state_list(component);
  if (!rows) return std::nullopt;
  for (const auto& r : *rows) {
    if (r.address == address) return r.state;
  }
  return std::nullopt;
}

std::string causes(const std::vector<Explanation>& why) {
  std::string out;
  for (const Explanation& e : why) {
    out += e.machine + " " + std::string(to_string(e.level)) + " " + e.event + " <- " + e.root.origin + ":" +
           e.root.event + " path";
    for (const std::string& hop : e.path) out += " " + hop;
    out += "\n";
  }
  return out;
}

/// explain(address) in one process running the whole system, after `setup`.
std::string in_process(const std::function<void(Coordinator&)>& setup, const std::string& address) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system(Paths{}.system, registry);
  EXPECT_TRUE(load.ok());
  SimulatedClock clock;
  Coordinator co("robodoc", &clock);
  Monitor monitor(co, registry);
  EXPECT_TRUE(spec::instantiate(*load.system, co, monitor));
  setup(co);
  return causes(*explain(co, address));
}

std::string ice_of_fixture() {
  const std::string file = env("SAFECASS_ICESTORM_ENV");
  return "127.0.0.1:" + env_file_value(file, "ICESTORM_PORT");
}

TEST(MultiProcess, RobodocSplitInTwoProcessesHasTheSameStatesAndRootCausesAsInProcess) {
  TwoProcesses sys(ice_of_fixture(), "propagation");
  sys.start_robot();
  sys.start_ui();
  const auto token = sys.await_token();
  ASSERT_TRUE(token.has_value()) << sys.logs();
  auto robot = sys.client("robot", *token);
  auto ui = sys.client("ui");
  ASSERT_TRUE(robot && ui) << sys.logs();
  ASSERT_TRUE(eventually([&] {
    return state_of(*ui, "PENDANT") == State::Normal && state_of(*robot, "CONTROL") == State::Normal;
  })) << sys.logs();

  ASSERT_TRUE(robot->apply(in::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"})) << sys.logs();
  ASSERT_TRUE(eventually([&] { return state_of(*ui, "PENDANT") == State::Error; })) << sys.logs();
  EXPECT_EQ(state_of(*ui, "PENDANT.s_R.Status"), State::Error);
  EXPECT_EQ(state_of(*robot, "SERVO"), State::Error);

  const std::string expected =
      in_process([](Coordinator& co) { ASSERT_TRUE(generate(co, "EVT_FORCE_ERROR", "JR3.s_A")); }, "PENDANT");
  auto remote = ui->explain("PENDANT");
  ASSERT_TRUE(remote) << remote.error().message;
  EXPECT_EQ(causes(remote->conditions), expected);
  EXPECT_NE(expected.find("JR3.s_A:EVT_FORCE_ERROR path JR3.s_A JR3.s_S.ForceData CONTROL.s_R.ForceData "
                          "CONTROL.s_S.Status PENDANT.s_R.Status"),
            std::string::npos)
      << expected;

  ASSERT_TRUE(robot->apply(in::GenerateEvent{"/EVT_FORCE_ERROR", "JR3.s_A"}));
  EXPECT_TRUE(eventually([&] { return state_of(*ui, "PENDANT") == State::Normal; })) << sys.logs();
  const auto after = ui->explain("PENDANT");
  ASSERT_TRUE(after) << after.error().message;
  EXPECT_TRUE(after->conditions.empty());
}

/// One history record as a line both sides can produce: what happened and its root cause.
std::string history_line(const std::string& kind, const std::string& outcome, const std::string& event, State from,
                         State to, const std::string& root_origin, const std::string& root_event) {
  return kind + " " + outcome + " " + event + " " + std::string(to_string(from)) + "->" + std::string(to_string(to)) +
         " <- " + root_origin + ":" + root_event;
}

TEST(MultiProcess, TheClientsAndTheSupervisorsHistoriesNameTheSameRootCausesAsAnInProcessRunCauseByCause) {
  // A true audit trail (issue finding: after a fault was cleared, the ui's history named the root
  // of the next fault). A seeded random sequence of faults on the robot; after each, the ui is
  // given time to hold the same roots; then PENDANT.s_R.Status's history in the ui, and the
  // supervisor's printed transitions of it, must equal an in-process run's, record by record.
  TwoProcesses sys(ice_of_fixture(), "audit");
  sys.start_robot();
  sys.start_ui({"--lost-after", "3000"});  // this test is about causes: no loss under CI load
  Process supervisor(
      {sys.p.bin, "supervisor", sys.p.system, "--ice", sys.ice, "--lost-after", "3000", "--duration", "40"},
      sys.p.scratch + "/audit-supervisor.log");
  const auto token = sys.await_token();
  ASSERT_TRUE(token.has_value()) << sys.logs();
  auto robot = sys.client("robot", *token);
  auto ui = sys.client("ui");
  ASSERT_TRUE(robot && ui) << sys.logs();
  ASSERT_TRUE(eventually([&] { return state_of(*ui, "PENDANT") == State::Normal; })) << sys.logs();
  ASSERT_TRUE(eventually([&] { return supervisor.output().find("coordinator 'ui' is up") != std::string::npos; }))
      << supervisor.output();

  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system(sys.p.system, registry);
  ASSERT_TRUE(load.ok());
  SimulatedClock clock;
  Coordinator reference("robodoc", &clock);
  Monitor monitor(reference, registry);
  ASSERT_TRUE(spec::instantiate(*load.system, reference, monitor));
  const MachineId pendant = *reference.structure().find_machine("PENDANT.s_R.Status");
  const auto history_before = reference.history(pendant).size();

  struct Op {
    const char* event;
    const char* target;
  };
  const std::vector<Op> ops{{"EVT_FORCE_ERROR", "JR3.s_A"},
                            {"/EVT_FORCE_ERROR", "JR3.s_A"},
                            {"EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"},
                            {"/EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"},
                            {"EVT_BONE_MOTION", "BMM.s_A"},
                            {"reset", "BMM"}};
  auto roots = [](const std::vector<Explanation>& why) {
    std::vector<std::string> out;
    for (const Explanation& e : why) out.push_back(e.root.name());
    std::sort(out.begin(), out.end());
    return out;
  };
  std::mt19937 random(20261123);
  for (int step = 0; step < 40; ++step) {
    const Op op = ops[random() % ops.size()];
    if (std::string(op.event) == "reset") {
      ASSERT_TRUE(robot->apply(in::ResetState{op.target, "audit test", "step " + std::to_string(step)})) << sys.logs();
      ASSERT_TRUE(reset(reference, op.target, "audit test", "step " + std::to_string(step)));
    } else {
      ASSERT_TRUE(robot->apply(in::GenerateEvent{op.event, op.target})) << sys.logs();
      ASSERT_TRUE(generate(reference, op.event, op.target));
    }
    clock.advance(std::chrono::milliseconds(10));
    const auto want = roots(*explain(reference, "PENDANT.s_R.Status"));
    ASSERT_TRUE(eventually([&] {
      auto got = ui->explain("PENDANT.s_R.Status");
      return got && roots(got->conditions) == want;
    })) << "step "
        << step << " " << op.event << " " << op.target << "\n"
        << sys.logs();
  }

  std::vector<std::string> expected, expected_transitions;
  const auto records = reference.history(pendant);
  for (std::size_t i = history_before; i < records.size(); ++i) {
    const Record& r = records[i];
    const std::string root_event = r.root.event == kNoEvent ? "" : reference.structure().event(r.root.event).name;
    const std::string root_origin = r.root.event == kNoEvent ? "" : reference.resolve_root(r.root).origin;
    const std::string outcome = r.outcome == Outcome::None ? "" : std::string(to_string(r.outcome));
    const std::string event = r.event == kNoEvent ? "" : reference.structure().event(r.event).name;
    expected.push_back(
        history_line(std::string(to_string(r.kind)), outcome, event, r.from, r.to, root_origin, root_event));
    if (r.kind == RecordKind::Transition) {
      expected_transitions.push_back("[ui] PENDANT.s_R.Status " + std::string(to_string(r.from)) + " -> " +
                                     std::string(to_string(r.to)) + " " + event + " (root " + root_origin + ":" +
                                     root_event + ")");
    }
  }
  ASSERT_GT(expected_transitions.size(), 4u) << "the sequence exercises the interface";
  auto rows = ui->history("PENDANT.s_R.Status", 1000);
  ASSERT_TRUE(rows) << rows.error().message;
  std::vector<std::string> got;
  for (const auto& r : *rows) {
    got.push_back(history_line(std::string(to_string(r.kind)),
                               r.outcome == Outcome::None ? "" : std::string(to_string(r.outcome)), r.event, r.from,
                               r.to, r.root ? r.root->origin : "", r.root ? r.root->event : ""));
  }
  ASSERT_GE(got.size(), expected.size());
  got.erase(got.begin(), got.end() - static_cast<std::ptrdiff_t>(expected.size()));  // the start-up records
  EXPECT_EQ(got, expected);

  // The supervisor prints as the records arrive: wait until its last lines are the transitions
  // (it may print start-up lines before them, so a count alone says nothing).
  std::vector<std::string> printed;
  const auto ends_with_transitions = [&] {
    printed.clear();
    std::istringstream out(supervisor.output());
    for (std::string line; std::getline(out, line);) {
      // Taken while the ui was lost to the supervisor (shown lost meanwhile): the same record.
      if (const auto at = line.find(" (while '"); at != std::string::npos) line.erase(at);
      if (line.rfind("[ui] PENDANT.s_R.Status ", 0) == 0) printed.push_back(line);
    }
    return printed.size() >= expected_transitions.size() &&
           std::equal(expected_transitions.begin(), expected_transitions.end(),
                      printed.end() - static_cast<std::ptrdiff_t>(expected_transitions.size()));
  };
  EXPECT_TRUE(eventually(ends_with_transitions)) << supervisor.output();
  // The start-up lines first: the ui holds PENDANT.s_R.Status at Error until the robot is proven
  // alive and its state received (a newcomer starts toward safe).
  const auto extra =
      static_cast<std::ptrdiff_t>(printed.size() - std::min(printed.size(), expected_transitions.size()));
  for (auto it = printed.begin(); it != printed.begin() + extra; ++it) {
    EXPECT_NE(it->find("EVT_COORDINATOR_LOST"), std::string::npos) << *it << "\n" << supervisor.output();
  }
  printed.erase(printed.begin(), printed.begin() + extra);
  EXPECT_EQ(printed, expected_transitions) << supervisor.output();
}

TEST(MultiProcess, ReadsAreRefusedWithoutTheReadCredentialWhenTheCoordinatorHasOne) {
  TwoProcesses sys(ice_of_fixture(), "read");
  const std::string credential_file = sys.p.scratch + "/read-ui.token";
  ::unlink(credential_file.c_str());
  sys.start_ui({"--read-token-file", credential_file});
  std::optional<std::string> credential;
  ASSERT_TRUE(eventually([&] {
    return (credential = middleware::read_token_file(credential_file).value_or("")) && !credential->empty();
  })) << sys.logs();
  struct stat st {};
  ASSERT_EQ(::stat(credential_file.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);

  middleware::ClientOptions o;
  o.ice = *middleware::parse_ice_endpoint(sys.ice);
  o.coordinator = "ui";
  o.timeout = 3000ms;
  std::unique_ptr<middleware::RemoteClient> anonymous;
  ASSERT_TRUE(eventually(
      [&] {
        auto r = middleware::RemoteClient::connect(o);
        if (r) anonymous = std::move(*r);
        return anonymous != nullptr;
      },
      10000ms))
      << sys.logs();
  for (auto refused : {anonymous->state_list("PENDANT").has_value(), anonymous->explain("PENDANT").has_value(),
                       anonymous->history("SYSTEM", 5, introspect::HistoryFilter::Events).has_value(),
                       anonymous->history("PENDANT", 5).has_value()}) {
    EXPECT_FALSE(refused);
  }
  auto why = anonymous->state_list("PENDANT");
  ASSERT_FALSE(why);
  EXPECT_EQ(why.error().code, ErrorCode::Denied);
  EXPECT_NE(why.error().message.find("read credential"), std::string::npos) << why.error().message;

  o.read_token = *credential;
  auto reader = middleware::RemoteClient::connect(o);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_TRUE((*reader)->state_list("PENDANT"));
  EXPECT_TRUE((*reader)->explain("PENDANT"));
  o.read_token = std::string(64, '0');
  auto wrong = middleware::RemoteClient::connect(o);
  ASSERT_TRUE(wrong);
  EXPECT_FALSE((*wrong)->state_list("PENDANT")) << "a wrong credential is no credential";
}

TEST(MultiProcess, AWriteIsRefusedWithoutTheTokenAndAcceptedWithIt) {
  TwoProcesses sys(ice_of_fixture(), "token");
  sys.start_robot();
  sys.start_ui();
  const auto token = sys.await_token();
  ASSERT_TRUE(token.has_value()) << sys.logs();
  struct stat st {};
  ASSERT_EQ(::stat(sys.token_file().c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u) << "the token file is readable by its owner only";

  auto anonymous = sys.client("robot");
  auto wrong = sys.client("robot", std::string(64, '0'));
  auto ui = sys.client("ui", *token);
  auto robot = sys.client("robot", *token);
  ASSERT_TRUE(anonymous && wrong && ui && robot) << sys.logs();

  for (auto* c : {anonymous.get(), wrong.get()}) {
    auto r = c->apply(in::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::Denied) << r.error().message;
    EXPECT_FALSE(c->apply(in::ResetState{"SYSTEM", "test", "no token"}));
    EXPECT_FALSE(c->apply(in::InjectShallow{"force_limit", {{50.0}}}));
  }
  auto read_only = ui->apply(in::GenerateEvent{"EVT_TRACKING_ERROR", "PENDANT.s_R.Status"});
  ASSERT_FALSE(read_only);
  EXPECT_NE(read_only.error().message.find("read-only"), std::string::npos) << read_only.error().message;
  EXPECT_EQ(state_of(*robot, "JR3"), State::Normal) << "refused writes changed nothing";

  auto bad = robot->apply(in::GenerateEvent{"EVT_NO_SUCH_EVENT", "JR3.s_A"});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::NotFound);
  ASSERT_TRUE(robot->apply(in::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"}));
  EXPECT_EQ(state_of(*robot, "JR3.s_A"), State::Error);
  ASSERT_TRUE(robot->apply(in::ResetState{"JR3", "test", "operator reset"}));
  EXPECT_EQ(state_of(*robot, "JR3.s_A"), State::Normal);
  // Reads work for everyone.
  EXPECT_TRUE(anonymous->state_list());
  EXPECT_TRUE(anonymous->filter_info("force_limit"));
  EXPECT_TRUE(anonymous->connection_list());
  EXPECT_TRUE(anonymous->service_list());
  EXPECT_TRUE(anonymous->event_list());
  EXPECT_TRUE(anonymous->history("SYSTEM", 10, introspect::HistoryFilter::Events));
}

TEST(MultiProcess, TheSupervisorDetectsAKilledCoordinatorAndItsRecovery) {
  TwoProcesses sys(ice_of_fixture(), "supervisor");
  sys.start_robot();
  sys.start_ui();
  Process supervisor(
      {sys.p.bin, "supervisor", sys.p.system, "--ice", sys.ice, "--lost-after", "500", "--duration", "40"},
      sys.p.scratch + "/supervisor-supervisor.log");
  auto robot = sys.client("robot");
  auto ui = sys.client("ui");
  ASSERT_TRUE(robot && ui) << sys.logs();
  ASSERT_TRUE(eventually([&] {
    const std::string out = supervisor.output();
    // Up, and back from the loss it starts in once its state is received (the republish it asks
    // for at the proof): a kill before that leaves it lost, with no loss of its own to report.
    return out.find("coordinator 'robot' recovered") != std::string::npos &&
           out.find("coordinator 'ui' recovered") != std::string::npos;
  })) << supervisor.output();

  sys.robot->stop(SIGKILL);
  ASSERT_TRUE(eventually([&] { return supervisor.output().find("coordinator 'robot' lost") != std::string::npos; }))
      << supervisor.output();
  EXPECT_TRUE(eventually([&] {
    const std::string out = supervisor.output();
    const auto at = out.find("supervisor: PENDANT.s_R.Status Normal -> Error EVT_SERVICE_FAILURE (root ");
    return at != std::string::npos && out.find(".s_F:EVT_COORDINATOR_LOST)", at) == out.find('\n', at) - 26;
  })) << supervisor.output();
  EXPECT_NE(supervisor.output().find("supervisor: JR3.s_F Normal -> Error EVT_COORDINATOR_LOST"), std::string::npos);
  EXPECT_EQ(supervisor.output().find("coordinator 'ui' lost"), std::string::npos) << supervisor.output();

  sys.start_robot();
  EXPECT_TRUE(eventually([&] { return supervisor.output().find("coordinator 'robot' recovered") != std::string::npos; },
                         10000ms))
      << supervisor.output();
  EXPECT_TRUE(eventually([&] {
    return supervisor.output().find("supervisor: PENDANT.s_R.Status Error -> Normal") != std::string::npos;
  })) << supervisor.output();
}

TEST(MultiProcess, AClientSeesErrorWhileItsProviderProcessIsKilledAndClearsWhenItIsBack) {
  // DESIGN §4, fail toward safe on loss: the ui must not keep showing the robot's last state.
  TwoProcesses sys(ice_of_fixture(), "lost");
  sys.start_robot();
  sys.start_ui();
  auto robot = sys.client("robot");
  auto ui = sys.client("ui");
  ASSERT_TRUE(robot && ui) << sys.logs();
  ASSERT_TRUE(eventually([&] { return state_of(*ui, "PENDANT.s_R.Status") == State::Normal; }, 5000ms)) << sys.logs();

  sys.robot->stop(SIGKILL);
  const auto killed = std::chrono::steady_clock::now();
  ASSERT_TRUE(eventually([&] { return state_of(*ui, "PENDANT.s_R.Status") == State::Error; }, 3000ms)) << sys.logs();
  const auto seen = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - killed);
  EXPECT_LT(seen.count(), 1500) << "the default bound is 3 heartbeats (300 ms)";
  auto why = ui->explain("PENDANT");
  ASSERT_TRUE(why);
  EXPECT_NE(causes(why->conditions).find("EVT_COORDINATOR_LOST"), std::string::npos) << causes(why->conditions);
  EXPECT_NE(sys.ui->output().find("coordinator 'robot' lost"), std::string::npos) << sys.logs();

  sys.start_robot();
  EXPECT_TRUE(eventually([&] { return state_of(*ui, "PENDANT.s_R.Status") == State::Normal; }, 10000ms)) << sys.logs();
  EXPECT_NE(sys.ui->output().find("coordinator 'robot' is back and resynchronised"), std::string::npos) << sys.logs();
}

TEST(MultiProcess, NothingIsLostWhenIceStormIsKilledAndRestartedMidRun) {
  Paths p;
  const std::string dir = p.scratch + "/restart-icestorm";
  const std::string env_file = p.scratch + "/restart-icestorm.env";
  const std::string start = p.source + "/scripts/start-icestorm";
  ASSERT_EQ(std::system((start + " --port 0 --replace --dir " + dir + " --env " + env_file + " >/dev/null").c_str()),
            0);
  const std::string port = env_file_value(env_file, "ICESTORM_PORT");
  pid_t icestorm = static_cast<pid_t>(std::stol(env_file_value(env_file, "ICESTORM_PID")));
  struct Kill {
    pid_t* pid;
    ~Kill() {
      if (*pid > 0) ::kill(*pid, SIGKILL);
    }
  } kill_icestorm{&icestorm};

  TwoProcesses sys("127.0.0.1:" + port, "restart");
  sys.start_robot();
  sys.start_ui();
  const auto token = sys.await_token();
  ASSERT_TRUE(token.has_value());
  auto robot = sys.client("robot", *token);
  auto ui = sys.client("ui");
  ASSERT_TRUE(robot && ui) << sys.logs();
  ASSERT_TRUE(robot->apply(in::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"}));
  ASSERT_TRUE(eventually([&] { return state_of(*ui, "PENDANT") == State::Error; })) << sys.logs();

  ::kill(icestorm, SIGKILL);
  ::waitpid(icestorm, nullptr, 0);
  icestorm = -1;
  // IceStorm is down: each process keeps detecting and propagating locally.
  ASSERT_TRUE(robot->apply(in::GenerateEvent{"/EVT_FORCE_ERROR", "JR3.s_A"}))
      << "remote operations do not go through IceStorm";
  ASSERT_TRUE(robot->apply(in::GenerateEvent{"EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"}));
  EXPECT_EQ(state_of(*robot, "JR3"), State::Normal);
  EXPECT_EQ(state_of(*robot, "SERVO"), State::Error) << "local propagation does not wait for the network";
  // A process started while IceStorm is down tries again until it is back (its first connection
  // failed before any topic was reached).
  Process supervisor({sys.p.bin, "supervisor", sys.p.system, "--ice", sys.ice, "--duration", "40"},
                     sys.p.scratch + "/restart-supervisor.log");
  std::this_thread::sleep_for(300ms);

  ASSERT_EQ(std::system((start + " --port " + port + " --dir " + dir + " --env " + env_file + " >/dev/null").c_str()),
            0);
  icestorm = static_cast<pid_t>(std::stol(env_file_value(env_file, "ICESTORM_PID")));
  const std::string expected = in_process(
      [](Coordinator& co) { ASSERT_TRUE(generate(co, "EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A")); }, "PENDANT");
  EXPECT_TRUE(eventually(
      [&] {
        auto why = ui->explain("PENDANT");
        return why && causes(why->conditions) == expected;
      },
      10000ms))
      << "after resync the ui holds exactly the robot's current roots\n"
      <<
      [&] {
        const auto why = ui->explain("PENDANT");
        return why ? causes(why->conditions) : "(explain failed: " + why.error().message + ")";
      }()
      << sys.logs();
  EXPECT_NE(sys.ui->output().find("connected to IceStorm"), std::string::npos);

  ASSERT_TRUE(robot->apply(in::GenerateEvent{"/EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"}));
  EXPECT_TRUE(eventually([&] { return state_of(*ui, "PENDANT") == State::Normal; })) << "propagation works again\n"
                                                                                     << sys.logs();
  EXPECT_TRUE(eventually([&] {
    const std::string out = supervisor.output();
    return out.find("coordinator 'robot' is up") != std::string::npos &&
           out.find("coordinator 'ui' is up") != std::string::npos;
  })) << supervisor.output();
  // A tool that connects now finds the robot through the tools' broker: the links the members made
  // before the restart still forward (the tools' broker listens where it did).
  EXPECT_NE(sys.client("robot"), nullptr) << sys.logs();
}

/// One coordinator of a system on the fixture's IceStorm, in this process.
struct Node {
  FilterRegistry registry;
  spec::SystemSpec system;
  middleware::HostClock clock;
  std::unique_ptr<Coordinator> co;
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<middleware::CoordinatorNode> node;

  Node(const std::string& text, const std::string& name, const std::string& keys) {
    register_builtin_filters(registry);
    auto load = spec::load_system_from_text(text, "burst.json", registry);
    EXPECT_TRUE(load.ok());
    if (!load.ok()) return;
    system = *load.system;
    co = std::make_unique<Coordinator>(name, &clock);
    monitor = std::make_unique<Monitor>(*co, registry);
    EXPECT_TRUE(spec::instantiate(system, *co, *monitor, name));
    EXPECT_TRUE(middleware::connect_remote_providers(system, name, *co));
    middleware::NodeOptions options;
    options.ice = *middleware::parse_ice_endpoint(ice_of_fixture());
    options.keys_dir = keys;
    options.log = [](const std::string&) {};
    auto n = middleware::CoordinatorNode::create(*co, *monitor, registry, system, name, options);
    EXPECT_TRUE(n);
    if (!n) return;
    node = std::move(*n);
    EXPECT_TRUE(node->start());
  }
  ~Node() {
    if (node) node->stop();
  }
};

TEST(MultiProcess, ABurstOverManyInterfacesIsBatchedAndEndsInTheProvidersExactState) {
  // S (coordinator "burst-s") provides D0..D23; A (coordinator "burst-a") requires each of them.
  constexpr int kInterfaces = 24;
  std::string provided, required, connections;
  for (int i = 0; i < kInterfaces; ++i) {
    const std::string d = "D" + std::to_string(i);
    provided += std::string(i ? ", " : "") + "\"" + d + "\"";
    required += std::string(i ? ", " : "") + "\"" + d + "\"";
    connections += std::string(i ? ", " : "") + R"({ "required": "A.)" + d + R"(", "provided": "S.)" + d + "\" }";
  }
  const std::string text = R"({ "safecass": 1, "system": "burst",
    "components": [
      { "component": "S", "interfaces": { "provided": [)" +
                           provided + R"(], "required": [] },
        "event": [ { "name": "EVT_E", "severity": 50, "state_transition": ["N2E", "W2E"] },
                   { "name": "/EVT_E", "severity": 50, "state_transition": ["E2N", "E2W"] },
                   { "name": "EVT_F", "severity": 60, "state_transition": ["N2E", "W2E"] },
                   { "name": "/EVT_F", "severity": 60, "state_transition": ["E2N", "E2W"] } ] },
      { "component": "A", "interfaces": { "provided": [], "required": [)" +
                           required + R"(] } } ],
    "connections": [ )" + connections +
                           R"( ],
    "coordinators": { "burst-s": ["S"], "burst-a": ["A"] } })";
  const std::string keys = Paths{}.scratch + "/burst-keys";
  {
    FilterRegistry registry;
    register_builtin_filters(registry);
    auto load = spec::load_system_from_text(text, "burst.json", registry);
    ASSERT_TRUE(load.ok());
    ASSERT_TRUE(fixture::make_keys(*load.system, keys));
  }
  Node provider(text, "burst-s", keys), client(text, "burst-a", keys);
  ASSERT_TRUE(provider.node && client.node);
  ASSERT_TRUE(eventually([&] { return provider.node->stats().connected && client.node->stats().connected; }, 10000ms));
  std::this_thread::sleep_for(300ms);  // subscriptions settle, initial resync done

  std::vector<MachineId> targets;
  for (int i = 0; i < kInterfaces; ++i)
    targets.push_back(*provider.co->structure().find_machine("S.s_P.D" + std::to_string(i)));
  const std::vector<EventId> events{
      *provider.co->structure().find_event("EVT_E"), *provider.co->structure().find_event("/EVT_E"),
      *provider.co->structure().find_event("EVT_F"), *provider.co->structure().find_event("/EVT_F")};
  const auto before = provider.node->stats();
  const auto applied_before = client.node->stats().updates_applied;
  std::mt19937 random(7);
  for (int round = 0; round < 400; ++round) {
    for (int k = 0; k < kInterfaces; ++k)
      provider.co->generate(events[random() % 4], targets[random() % targets.size()]);
    if (round % 20 == 0) std::this_thread::sleep_for(1ms);
  }
  // Every interface ends in the provider's exact final state: the same roots (origin, event, onset
  // time) at the client's stand-in S.s_P.Di as at the provider's service S.s_S.Di.
  const ComponentId s = *provider.co->structure().find_component("S");
  std::string mismatch;
  auto same_everywhere = [&] {
    for (int i = 0; i < kInterfaces; ++i) {
      std::vector<std::string> want, got;
      for (const RemoteRoot& r : provider.co->service_roots(s, static_cast<std::uint32_t>(i))) {
        want.push_back(r.root.origin + ":" + r.root.event + "@" + std::to_string(r.root.time.count()));
      }
      auto why = explain(*client.co, "S.s_P.D" + std::to_string(i));
      if (!why) return false;
      for (const Explanation& e : *why) got.push_back(e.root.name() + "@" + std::to_string(e.root.time.count()));
      std::sort(want.begin(), want.end());
      std::sort(got.begin(), got.end());
      const State client_state = client.co->state(*client.co->structure().find_machine("A.s_R.D" + std::to_string(i)));
      const State provider_state = provider.co->service_state(s, static_cast<std::uint32_t>(i));
      if (want != got || client_state != provider_state) {
        mismatch = "D" + std::to_string(i) + ": provider " + std::string(to_string(provider_state)) + " " +
                   std::to_string(want.size()) + " root(s), client " + std::string(to_string(client_state)) + " " +
                   std::to_string(got.size()) + " root(s)";
        return false;
      }
    }
    return true;
  };
  EXPECT_TRUE(eventually(same_everywhere, 10000ms)) << mismatch;
  const auto after = provider.node->stats();
  const std::uint64_t updates = after.updates_published - before.updates_published;
  const std::uint64_t messages = after.state_messages_published - before.state_messages_published;
  EXPECT_GT(updates, static_cast<std::uint64_t>(kInterfaces));
  EXPECT_LT(messages, updates) << "several interfaces' updates share one message";
  EXPECT_TRUE(eventually([&] { return client.node->stats().updates_applied - applied_before == updates; }))
      << "every update sent was applied, in order";
  const auto received = client.node->stats();
  EXPECT_EQ(received.updates_rejected, 0u);
  EXPECT_EQ(received.updates_missed, 0u) << "batched updates keep consecutive sequence numbers";
}

}  // namespace
}  // namespace safecass
