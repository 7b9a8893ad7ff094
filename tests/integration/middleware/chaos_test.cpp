// Chaos test of the multi-process system (DESIGN §4 "fail toward safe on loss", §7 "nothing
// lost"; docs/middleware.md "Loss of a provider", "Sequence numbers, loss and resync",
// "Supervisor"): a seeded loop of rounds against real processes — the robodoc example as its two
// coordinators (`robot`, `ui`), a `safecass supervisor` and an IceStorm of the test's own. Each
// round does one thing: kill -9 the robot (and restart it), SIGSTOP it for 0.6–1 s, kill -9 the
// ui (and restart it), kill IceStorm (and restart it on the same port and database, changing the
// robot's faults while it is down), kill -9 the supervisor (and restart it), or send a burst of
// 5–30 generate/complete/reset operations to the robot. The first six rounds are a seeded
// permutation of the six actions, so every seed exercises each of them.
//
// The reference is one in-process Coordinator of the whole system (spec::load_system +
// spec::instantiate, simulated clock) given the same operations in the same order; a restarted
// robot starts clean, so the reference resets the robot's components then. After each round the
// test polls (every 20 ms, at most 2 s after the disruption is over: the restarted process
// answers, IceStorm is ready, the supervisor is connected, the last operation returned) until
//  1. the robot's and the ui's `state list` (address, state, outstanding event) and `explain` of
//     each of their components (machine, level, event, root cause, hop path) equal the
//     reference's — so no EVT_COORDINATOR_LOST or EVT_SUPERVISOR_LOST is left either;
//  2. the supervisor's view, rebuilt from what it printed exactly as Supervisor::view() builds it
//     (last transition or state update of each address; a restarted coordinator's rows dropped),
//     equals the reference for every address in it, and it reports no coordinator lost;
//  3. no record is lost without being reported: every transition that the robot and the ui
//     print (their own observer stream, before the node queues the record) since the current
//     supervisor subscribed (or since the process started, when later) was printed by the
//     supervisor, in order as it received it or marked late (out of order: a replicated IceStorm
//     reorders a publisher's messages when it moves to another replica) — or the supervisor
//     printed "N event record(s) of 'X' missed" for at least as many records. Conversely the
//     supervisor printed no transition the process did not make.
// During the disruptions it also checks fail-toward-safe: while the robot is killed or
// unreachable (IceStorm down) the ui shows EVT_COORDINATOR_LOST, and it declares a stopped robot
// lost; while the supervisor is gone both coordinators show EVT_SUPERVISOR_LOST. At the end every
// process is stopped by PID with SIGTERM; the surviving coordinators must report "0 event records
// dropped" (their observer queues never overflowed) and the supervisor no lost coordinator. The
// run prints the seed, each round's convergence time and the total (about 12–20 s on the shared
// 2-core machine, up to about 40 s under heavy load; the budget is 3 minutes).
//
// Every round settles before the next disruption, so IceStorm is never killed while records are
// on their way through it. Doing so (a burst right before the kill) shows two bugs of the
// supervisor, which the last two tests of this file reproduce deterministically.
//
// Environment (set by tests/integration/middleware/CMakeLists.txt):
//   SAFECASS_BIN, SAFECASS_SOURCE_DIR, SAFECASS_SCRATCH, SAFECASS_KEYS (the robodoc bus keys)
//   SAFECASS_CHAOS_SEED      the seed (default 20240611; printed)
//   SAFECASS_CHAOS_ROUNDS    the number of rounds (default 20)
//   SAFECASS_CHAOS_BOUND_MS  the convergence bound (default 2000)
// Every process the test starts is stopped by PID whatever the outcome; the coordinators and the
// supervisor die with the test (PR_SET_PDEATHSIG), and a small reaper process kills the test's
// IceStorm if the test itself is killed (a ctest timeout).

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/spec/load.hpp"

namespace safecass {
namespace {

using namespace std::chrono_literals;
using Steady = std::chrono::steady_clock;
using Millis = std::chrono::milliseconds;

std::string env(const char* name, const std::string& fallback = {}) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : fallback;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The complete lines of a file another process is still writing (a partial last line is left
/// out), with runs of spaces collapsed and trailing spaces removed: the supervisor prints a
/// transition without an event (a reset's) as "A -> B  (root ...)", its coordinator as
/// "A -> B (root ...)".
std::vector<std::string> lines_of(const std::string& path) {
  const std::string text = slurp(path);
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', start)) {
    std::string line;
    for (std::size_t i = start; i < nl; ++i) {
      if (text[i] != ' ' || line.empty() || line.back() != ' ') line += text[i];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out.push_back(std::move(line));
    start = nl + 1;
  }
  return out;
}

std::string tail(const std::string& path, std::size_t n = 25) {
  const auto lines = lines_of(path);
  std::string out = "--- " + path + " (last " + std::to_string(std::min(n, lines.size())) + " lines)\n";
  for (std::size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i) out += lines[i] + "\n";
  return out;
}

std::string env_file_value(const std::string& file, const std::string& key) {
  std::istringstream lines(slurp(file));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
  }
  return "";
}

bool eventually(const std::function<bool()>& ok, Millis timeout) {
  const auto until = Steady::now() + timeout;
  while (Steady::now() < until) {
    if (ok()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return ok();
}

double seconds_since(Steady::time_point t) { return std::chrono::duration<double>(Steady::now() - t).count(); }

/// A child process with its output in a log file, stopped by PID when it goes out of scope. It
/// also dies with the test (PR_SET_PDEATHSIG), so a killed test leaves no coordinator behind.
class Process {
public:
  Process(std::vector<std::string> argv, std::string log) : log_(std::move(log)) {
    std::vector<char*> args;
    for (std::string& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    // A log of an earlier run under the same name must not be read as this process's.
    std::remove(log_.c_str());
    const pid_t parent = ::getpid();
    pid_ = ::fork();
    if (pid_ == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) std::_Exit(127);
      const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::execv(args[0], args.data());
      std::_Exit(127);
    }
  }
  ~Process() { stop(SIGTERM); }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  /// Sends `sig` and waits for the process (SIGKILL after 5 s). Returns the wait status, or -1.
  int stop(int sig) {
    if (pid_ <= 0) return -1;
    ::kill(pid_, sig);
    ::kill(pid_, SIGCONT);  // a stopped process handles SIGTERM only once it runs again
    int status = -1;
    for (int i = 0; i < 500; ++i) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return status;
      }
      std::this_thread::sleep_for(10ms);
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  /// Waits up to `timeout` for the process to exit by itself; its wait status, or -1.
  int wait_exit(std::chrono::milliseconds timeout) {
    int status = -1;
    for (auto until = std::chrono::steady_clock::now() + timeout; pid_ > 0 && std::chrono::steady_clock::now() < until;
         std::this_thread::sleep_for(20ms)) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return status;
      }
    }
    return -1;
  }
  const std::string& log() const { return log_; }
  bool running() const { return pid_ > 0; }

private:
  pid_t pid_ = -1;
  std::string log_;
};

/// The test's own IceStorm (scripts/start-icestorm), killed and restarted on the same port and
/// database directory; or, with `replicas`, its own replicated IceStorm under IceGrid (one node
/// with the registry, `replicas` IceBoxes), whose replicas are killed one at a time and restarted
/// by the node. A reaper child kills it by PID (and the replicas by their data directory) if the
/// test dies before its destructor runs (the IceStorm runs in its own session, so nothing else
/// would stop it).
class IceStorm {
public:
  IceStorm(std::string source, const std::string& scratch, int replicas = 0)
      : script_(std::move(source) + "/scripts/start-icestorm"),
        dir_(scratch + (replicas > 0 ? "/chaos-icegrid" : "/chaos-icestorm")),
        env_file_(dir_ + ".env"),
        replicas_(replicas) {
    std::remove(env_file_.c_str());
    const pid_t parent = ::getpid();
    reaper_ = ::fork();
    if (reaper_ == 0) {
      while (::getppid() == parent) ::usleep(200'000);
      char buffer[512] = {};
      const int fd = ::open(env_file_.c_str(), O_RDONLY);
      if (fd >= 0) {
        const ssize_t n = ::read(fd, buffer, sizeof buffer - 1);
        ::close(fd);
        const char* at = n > 0 ? std::strstr(buffer, "ICESTORM_PID=") : nullptr;
        if (at != nullptr) {
          const long pid = std::strtol(at + 13, nullptr, 10);
          if (pid > 1) ::kill(static_cast<pid_t>(pid), SIGKILL);
        }
      }
      if (replicas_ > 0) std::system(("pkill -KILL -f '" + dir_ + "[/]node-'").c_str());
      std::_Exit(0);
    }
  }
  ~IceStorm() {
    kill();
    if (reaper_ > 0) {
      ::kill(reaper_, SIGKILL);
      ::waitpid(reaper_, nullptr, 0);
    }
  }
  IceStorm(const IceStorm&) = delete;
  IceStorm& operator=(const IceStorm&) = delete;

  /// Starts it (on a free port the first time, on the same port afterwards); false on failure.
  /// The script gives IceBox 5 s to be ready, which a heavily loaded machine can exceed, and the
  /// port of a killed IceStorm can stay in use for a moment after it: up to five attempts, half a
  /// second apart.
  bool start() {
    const std::string command = script_ + (replicas_ > 0 ? " --replicas " + std::to_string(replicas_) : "") +
                                " --port " + (port_.empty() ? "0" : port_) + " --dir " + dir_ + " --env " + env_file_ +
                                " --replace >/dev/null";
    bool started = false;
    for (int attempt = 0; attempt < 5 && !started; ++attempt) {
      if (attempt > 0) std::this_thread::sleep_for(500ms);
      started = std::system(command.c_str()) == 0;
    }
    if (!started) return false;
    port_ = env_file_value(env_file_, "ICESTORM_PORT");
    endpoint_ = env_file_value(env_file_, "ICESTORM_ICE");
    pid_ = static_cast<pid_t>(std::stol(env_file_value(env_file_, "ICESTORM_PID")));
    return pid_ > 0;
  }
  /// SIGSTOP / SIGCONT: a frozen IceStorm keeps its connections, and the kernel still accepts
  /// what publishers send it.
  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  /// kill -9, and waits until the process is gone (its port is free again). Replicated: the
  /// node, then every replica it ran.
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    for (int i = 0; i < 300 && ::kill(pid_, 0) == 0; ++i) std::this_thread::sleep_for(10ms);
    pid_ = -1;
    if (replicas_ > 0) std::system(("pkill -KILL -f '" + dir_ + "[/]node-'").c_str());
  }
  /// What processes give to --ice: "127.0.0.1:PORT", or "locator:127.0.0.1:PORT" when replicated.
  std::string endpoint() const { return endpoint_; }
  std::string log() const { return replicas_ > 0 ? dir_ + "/node-local.log" : dir_ + "/icebox.log"; }

  // -- replicated only --

  /// The replicas' own report (`icestormadmin ... replica`): per replica "ID: coord: N" and
  /// "ID: state: S" lines, or an error.
  std::string replica_report() const {
    std::string out;
    FILE* p = ::popen(("icestormadmin --Ice.Config=" + dir_ + "/admin.config -e replica 2>&1").c_str(), "r");
    if (p == nullptr) return out;
    char line[256];
    while (std::fgets(line, sizeof line, p) != nullptr) out += line;
    ::pclose(p);
    return out;
  }
  /// The master replica's id, 0 when the replicas do not agree on one or some replica is not in
  /// the normal state (an election, or a replica restarting).
  int settled_master() const {
    const std::string report = replica_report();
    int master = 0, normal = 0;
    std::istringstream lines(report);
    std::string line;
    while (std::getline(lines, line)) {
      int id = 0, value = 0;
      char word[16] = {};
      if (std::sscanf(line.c_str(), "%d: coord: %d", &id, &value) == 2) {
        if (master != 0 && master != value) return 0;
        master = value;
      } else if (std::sscanf(line.c_str(), "%d: state: %15s", &id, word) == 2 && std::string(word) == "normal") {
        ++normal;
      }
    }
    return normal == replicas_ ? master : 0;
  }
  /// kill -9 of replica `id` (its node starts it again at once); false when it is not running.
  bool kill_replica(int id) const {
    // "[/]": the pattern does not match the shell that runs pkill with it.
    const std::string pattern = dir_ + "/node-local/data/servers/SafecassIceStorm" + std::to_string(id) + "[/]";
    return std::system(("pkill -KILL -f '" + pattern + "'").c_str()) == 0;
  }

private:
  std::string script_, dir_, env_file_, port_, endpoint_;
  int replicas_ = 0;
  pid_t pid_ = -1;
  pid_t reaper_ = -1;
};

/// The whole system in one process, in simulated time: what every process must converge to.
struct Reference {
  FilterRegistry registry;
  spec::LoadResult load;
  SimulatedClock clock;
  std::unique_ptr<Coordinator> co;
  std::unique_ptr<Monitor> monitor;

  explicit Reference(const std::string& system) {
    register_builtin_filters(registry);
    load = spec::load_system(system, registry);
    EXPECT_TRUE(load.ok());
    if (!load.ok()) return;
    co = std::make_unique<Coordinator>("robodoc", &clock);
    monitor = std::make_unique<Monitor>(*co, registry);
    EXPECT_TRUE(spec::instantiate(*load.system, *co, *monitor));
  }
};

/// `state list` of some components of a coordinator, one "address state outstanding" line per
/// row, sorted (built as the Control servant builds its reply).
std::vector<std::string> rows_of(const Coordinator& co, const std::vector<std::string>& components) {
  std::vector<std::string> out;
  auto name = [&](EventId e) { return e == kNoEvent ? std::string() : co.structure().event(e).name; };
  auto row = [&](const std::string& address, State s, const std::string& outstanding) {
    out.push_back(address + " " + std::string(to_string(s)) + (outstanding.empty() ? "" : " " + outstanding));
  };
  for (const std::string& c : components) {
    const ComponentId id = *co.structure().find_component(c);
    const StateSnapshot s = co.extended(id);
    row(c, s.state, name(s.outstanding));
    std::vector<MachineId> machines{co.structure().framework_machine(id), co.structure().application_machine(id)};
    for (MachineId m : co.structure().provided_machines(id)) machines.push_back(m);
    for (MachineId m : co.structure().required_machines(id)) machines.push_back(m);
    for (MachineId m : machines)
      row(co.structure().address_of(m), co.snapshot(m).state, name(co.snapshot(m).outstanding));
    const auto& provided = co.structure().provided_machines(id);
    for (std::uint32_t p = 0; p < provided.size(); ++p) {
      row(c + ".s_S." + std::string(co.structure().interface_name(provided[p])), co.service_state(id, p), "");
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> rows_of(const std::vector<introspect::StateRow>& rows) {
  std::vector<std::string> out;
  for (const auto& r : rows) {
    if (r.kind == introspect::RowKind::System) continue;  // the reference lists the components alone
    out.push_back(r.address + " " + std::string(to_string(r.state)) +
                  (r.outstanding.empty() ? "" : " " + r.outstanding));
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Each active condition with its root cause and hop path (times left out: the reference runs
/// in simulated time), sorted.
std::vector<std::string> causes_of(const std::vector<Explanation>& why) {
  std::vector<std::string> out;
  for (const Explanation& e : why) {
    std::string line = e.machine + " " + std::string(to_string(e.level)) + " " + e.event + " <- " + e.root.origin +
                       ":" + e.root.event + " path";
    for (const std::string& hop : e.path) line += " " + hop;
    out.push_back(std::move(line));
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool has_root(const Expected<introspect::ExplainAnswer>& why, const std::string& event) {
  return why && std::any_of(why->conditions.begin(), why->conditions.end(),
                            [&](const Explanation& e) { return e.root.event == event; });
}

/// "- wanted" / "+ got" lines of two sorted lists, empty when they are equal.
std::string diff(const std::string& what, const std::vector<std::string>& want, const std::vector<std::string>& got) {
  if (want == got) return "";
  std::string out = what + " differs from the in-process run (- in-process, + process):\n";
  std::vector<std::string> only_want, only_got;
  std::set_difference(want.begin(), want.end(), got.begin(), got.end(), std::back_inserter(only_want));
  std::set_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(only_got));
  for (const auto& l : only_want) out += "  - " + l + "\n";
  for (const auto& l : only_got) out += "  + " + l + "\n";
  return out;
}

/// The transitions a coordinator process printed (its own observer stream, one line per
/// transition and component transition, printed before the node queues the record), restricted
/// to its own components: a client also prints the transitions of its stand-ins for remote
/// providers, which are the provider's to publish.
std::vector<std::string> transitions_printed(const std::string& log, const std::string& coordinator,
                                             const std::set<std::string>& components) {
  std::vector<std::string> out;
  const std::string prefix = "[" + coordinator + "] ";
  for (std::string& line : lines_of(log)) {
    if (line.rfind(prefix, 0) != 0 || line.find(" -> ") == std::string::npos) continue;
    const std::string address = line.substr(prefix.size(), line.find(' ', prefix.size()) - prefix.size());
    if (components.count(address.substr(0, address.find('.'))) == 0) continue;
    out.push_back(std::move(line));
  }
  return out;
}

/// What a supervisor process printed, read back: its view (rebuilt as Supervisor::view() builds
/// it), which coordinators it considers lost, and the transitions of each coordinator's latest
/// incarnation it received, with the records it reported missed.
struct SupervisorLog {
  bool connected = false;
  std::map<std::string, std::pair<std::string, std::string>> view;  ///< address -> (coordinator, state)
  std::map<std::string, bool> lost;
  std::map<std::string, std::vector<std::string>> received;
  /// Records printed late (" (late: seq N arrived after newer records)"): received out of order,
  /// which a replicated IceStorm does when a publisher moves from one replica to another. Either
  /// within the reorder grace (they fill a gap, never reported missed) or after it (reported
  /// missed first). Not in `received` (which is in order), and they take no row back.
  std::map<std::string, std::vector<std::string>> late;
  std::map<std::string, std::uint64_t> missed;
  std::uint64_t missed_total = 0;  ///< over every incarnation
  std::uint64_t refused = 0;

  explicit SupervisorLog(const std::string& path) {
    auto quoted = [](const std::string& line) {
      const auto a = line.find('\'');
      const auto b = line.find('\'', a + 1);
      return a == std::string::npos || b == std::string::npos ? std::string() : line.substr(a + 1, b - a - 1);
    };
    for (std::string line : lines_of(path)) {  // a copy: a note may be cut off
      if (line.rfind("supervisor: connected to IceStorm", 0) == 0) {
        connected = true;
      } else if (line.rfind("supervisor: coordinator '", 0) == 0) {
        const std::string who = quoted(line);
        if (line.find("' restarted; its view is refreshed") != std::string::npos) {
          std::erase_if(view, [&](const auto& row) { return row.second.first == who; });
          received[who].clear();
          late[who].clear();
          missed[who] = 0;
        } else if (line.find("' lost: ") != std::string::npos) {
          lost[who] = true;
        } else if (line.find("' recovered") != std::string::npos || line.find("' is up") != std::string::npos) {
          lost[who] = false;
        }
      } else if (line.rfind("supervisor: ", 0) == 0 && line.find(" event record(s) of '") != std::string::npos &&
                 line.find("' missed") != std::string::npos) {
        const std::uint64_t n = std::strtoull(line.c_str() + 12, nullptr, 10);
        missed[quoted(line)] += n;
        missed_total += n;
      } else if (line.rfind("supervisor: refused", 0) == 0) {
        ++refused;
      } else if (line.rfind("[", 0) == 0 && line.find("] ") != std::string::npos) {
        const std::string who = line.substr(1, line.find("] ") - 1);
        std::istringstream words(line.substr(line.find("] ") + 2));
        std::string address, first, arrow, to;
        words >> address >> first >> arrow >> to;
        if (address == "reset") continue;  // a reset record: not a transition
        // Taken while its coordinator was lost (shown lost meanwhile): the same record.
        if (const auto at = line.find(" (while '"); at != std::string::npos) line.erase(at);
        if (const auto at = line.find(" (late: seq "); at != std::string::npos) {
          late[who].push_back(line.substr(0, at));
          continue;
        }
        if (arrow == "->") {
          view[address] = {who, to};
          received[who].push_back(line);
        } else {
          view[address] = {who, first};  // a state update: "[who] C.s_S.p State (roots ...)"
        }
      }
    }
  }
};

/// Whether every transition a process printed since `anchor` reached the supervisor or was
/// reported missed. The supervisor's lines are matched, newest first, against the newest lines of
/// the process (the latest match for each keeps the most matches after the anchor).
struct Delivery {
  std::size_t printed = 0, expected = 0, received = 0, unmatched = 0;
  std::uint64_t reported_missed = 0;
  bool foreign = false;  ///< the supervisor printed a transition the process never made
  std::string foreign_line;

  bool ok() const { return !foreign && unmatched <= reported_missed; }
  std::string text(const std::string& who) const {
    return who + ": " + std::to_string(printed) + " transitions printed, " + std::to_string(expected) +
           " since the supervisor subscribed, " + std::to_string(received) + " received by it, " +
           std::to_string(unmatched) + " of those not received, " + std::to_string(reported_missed) +
           " record(s) reported missed" +
           (foreign ? "; the supervisor printed a transition the process did not make: " + foreign_line : "");
  }
};

/// `received`: what the supervisor printed in order; `late`: what it printed out of order. A
/// printed transition is received when the in-order lines match it (walking back from the newest)
/// or, failing that, a late line equal to it is left to match.
Delivery delivered(const std::vector<std::string>& printed, std::size_t anchor,
                   const std::vector<std::string>& received, const std::vector<std::string>& late,
                   std::uint64_t missed) {
  Delivery d;
  d.printed = printed.size();
  d.received = received.size() + late.size();
  d.reported_missed = missed;
  anchor = std::min(anchor, printed.size());
  d.expected = printed.size() - anchor;
  std::multiset<std::string> late_left(late.begin(), late.end());
  auto late_match = [&](std::size_t i) {
    const auto it = late_left.find(printed[i]);
    if (i < anchor || it == late_left.end()) return false;
    late_left.erase(it);
    return true;
  };
  std::size_t i = printed.size(), j = received.size(), matched = 0;
  while (j > 0) {
    if (i == 0) {
      d.foreign = true;
      d.foreign_line = received[j - 1];
      break;
    }
    if (printed[i - 1] == received[j - 1]) {
      if (i - 1 >= anchor) ++matched;
      --j;
    } else if (late_match(i - 1)) {
      ++matched;
    }
    --i;
  }
  while (i > 0) matched += late_match(--i) ? 1 : 0;
  d.unmatched = d.expected - matched;
  return d;
}

enum class Action { KillRobot, StopRobot, KillUi, KillIceStorm, KillSupervisor, Burst };

const char* name_of(Action a) {
  switch (a) {
    case Action::KillRobot: return "kill -9 the robot and restart it";
    case Action::StopRobot: return "SIGSTOP the robot, then SIGCONT";
    case Action::KillUi: return "kill -9 the ui and restart it";
    case Action::KillIceStorm: return "kill IceStorm, change faults while it is down, restart it";
    case Action::KillSupervisor: return "kill -9 the supervisor and restart it";
    case Action::Burst: return "a burst of faults";
  }
  return "?";
}

/// One operation on the robot, applied through RemoteClient and to the reference alike.
struct Operation {
  bool reset = false;
  std::string event, target;
  std::string text() const { return reset ? "reset " + target : "generate " + event + " " + target; }
};

/// The robot's faults the bursts draw from: onsets and completions (application errors and
/// warnings, a latched one, a framework error) on machines no filter of the quiet feed drives, and
/// resets of components and machines. None is an event the robot raises or clears on its own: its
/// runtime raises EVT_PERIOD_OVERRUN on the s_F of a component whose cycle overran and clears it at
/// the next cycle in time, which on a loaded machine cleared a generated EVT_PERIOD_OVERRUN that the
/// reference kept (the process was right, the test wrong); no component of `safecass run` has a
/// body that can throw, so nothing but the test raises or clears EVT_THREAD_EXCEPTION.
const std::vector<Operation>& operations() {
  static const std::vector<Operation> ops = [] {
    std::vector<Operation> v;
    const std::vector<std::pair<std::string, std::string>> faults{{"EVT_FORCE_ERROR", "JR3.s_A"},
                                                                  {"EVT_FORCE_HIGH", "JR3.s_A"},
                                                                  {"EVT_BONE_MOTION", "BMM.s_A"},
                                                                  {"EVT_CONTROL_FORCE_FREEZE", "CONTROL.s_A"},
                                                                  {"EVT_TRACKING_ERROR", "CONTROL.s_A"},
                                                                  {"EVT_TRACKING_ERROR", "CONTROL.s_P.Status"},
                                                                  {"EVT_FORCE_ERROR", "CONTROL.s_P.Command"},
                                                                  {"EVT_SERVO_OVERLOAD", "SERVO.s_A"},
                                                                  {"EVT_THREAD_EXCEPTION", "CONTROL.s_F"}};
    for (const auto& [event, target] : faults) {
      v.push_back({false, event, target});
      v.push_back({false, "/" + event, target});
    }
    for (const char* target : {"JR3", "BMM", "CONTROL", "SERVO", "JR3.s_A", "CONTROL.s_A", "BMM.s_A"}) {
      v.push_back({true, "", target});
    }
    return v;
  }();
  return ops;
}

class Chaos {
public:
  /// `replicas` > 0: a replicated IceStorm of that many replicas instead of one IceStorm.
  explicit Chaos(int replicas = 0)
      : bin_(env("SAFECASS_BIN")),
        source_(env("SAFECASS_SOURCE_DIR")),
        scratch_(env("SAFECASS_SCRATCH", "/tmp")),
        system_(source_ + "/examples/robodoc/robodoc.json"),
        feed_(source_ + "/tests/integration/middleware/chaos_robot_feed.json"),
        icestorm_(source_, scratch_, replicas),
        reference_(system_) {
    if (reference_.load.ok()) {
      for (const auto& [coordinator, components] : reference_.load.system->coordinators) {
        components_[coordinator] = std::set<std::string>(components.begin(), components.end());
      }
    }
  }
  ~Chaos() {
    for (const std::string& t : token_files_) std::remove(t.c_str());
  }

  Reference& reference() { return reference_; }
  /// More options for every robot process started from now on.
  void robot_options(std::vector<std::string> options) { robot_options_ = std::move(options); }
  IceStorm& icestorm() { return icestorm_; }
  middleware::RemoteClient* robot() { return robot_client_.get(); }
  middleware::RemoteClient* ui() { return ui_client_.get(); }

  /// Starts IceStorm, the supervisor, the robot and the ui; false (with a failure) if one of them
  /// does not come up.
  bool start() {
    if (!icestorm_.start()) {
      ADD_FAILURE() << "scripts/start-icestorm failed";
      return false;
    }
    return start_supervisor() && start_robot() && start_ui();
  }

  bool start_supervisor() {
    ++supervisor_n_;
    supervisor_ = std::make_unique<Process>(
        std::vector<std::string>{bin_, "supervisor", system_, "--ice", icestorm_.endpoint(), "--duration", "300"},
        log_path("supervisor", supervisor_n_));
    if (!eventually([&] { return SupervisorLog(supervisor_->log()).connected; }, 15000ms)) {
      ADD_FAILURE() << "the supervisor did not connect to IceStorm\n" << tail(supervisor_->log());
      return false;
    }
    // It is subscribed: from here on it must receive every record (or report it missed).
    for (const auto* p : {&robot_, &ui_}) {
      if (*p == nullptr) continue;
      const std::string who = p == &robot_ ? "robot" : "ui";
      anchor_[who] = transitions_printed((*p)->log(), who, components_[who]).size();
    }
    return true;
  }

  bool start_robot() {
    ++robot_n_;
    const std::string token_file = scratch_ + "/chaos-robot-" + std::to_string(robot_n_) + ".token";
    std::remove(token_file.c_str());
    token_files_.push_back(token_file);
    robot_ = std::make_unique<Process>(
        with(std::vector<std::string>{bin_, "run", system_, "--coordinator", "robot", "--scenario", feed_, "--ice",
                                      icestorm_.endpoint(), "--allow-write", "--token-file", token_file, "--duration",
                                      "300"},
             robot_options_),
        log_path("robot", robot_n_));
    anchor_["robot"] = 0;  // the supervisor runs: it receives this process's records from its start
    std::string token;
    if (!eventually(
            [&] {
              auto t = middleware::read_token_file(token_file);
              if (t) token = *t;
              return t.has_value();
            },
            15000ms)) {
      ADD_FAILURE() << "the robot wrote no token\n" << tail(robot_->log());
      return false;
    }
    robot_client_ = connect("robot", token);
    robot_up_ = Steady::now();
    if (robot_client_ == nullptr) ADD_FAILURE() << "cannot reach the robot\n" << tail(robot_->log());
    return robot_client_ != nullptr;
  }

  bool start_ui() {
    ++ui_n_;
    ui_ = std::make_unique<Process>(std::vector<std::string>{bin_, "run", system_, "--coordinator", "ui", "--ice",
                                                             icestorm_.endpoint(), "--duration", "300"},
                                    log_path("ui", ui_n_));
    anchor_["ui"] = 0;
    ui_client_ = connect("ui", "");
    ui_up_ = Steady::now();
    if (ui_client_ == nullptr) ADD_FAILURE() << "cannot reach the ui\n" << tail(ui_->log());
    return ui_client_ != nullptr;
  }

  /// `safecass console --ice ... ARGS`, its output in a log named `name`.
  std::unique_ptr<Process> console(const std::vector<std::string>& args, const std::string& name) {
    return std::make_unique<Process>(
        with(std::vector<std::string>{bin_, "console", "--ice", icestorm_.endpoint()}, args), log_path(name, 1));
  }

  void kill_robot() {
    robot_client_.reset();
    robot_->stop(SIGKILL);
  }
  void stop_robot(bool stopped) { robot_->signal(stopped ? SIGSTOP : SIGCONT); }
  void kill_ui() {
    ui_client_.reset();
    ui_->stop(SIGKILL);
  }
  /// A coordinator watches the supervisor only once it has seen it (docs/semantics.md §7.3): a
  /// coordinator that has run for half a second has received several of its heartbeats (one per
  /// 100 ms). Waits until both have, then kills the supervisor.
  void kill_supervisor() {
    std::this_thread::sleep_until(std::max(robot_up_, ui_up_) + 500ms);
    supervisor_->stop(SIGKILL);
  }

  /// Applies `op` to the robot and to the reference; both must accept or refuse it alike.
  std::string apply(const Operation& op) {
    reference_.clock.advance(1ms);  // distinct onset times, as in the real run
    Expected<void> local =
        op.reset ? reset(*reference_.co, op.target, "chaos", "burst") : generate(*reference_.co, op.event, op.target);
    Expected<void> remote =
        robot_client_->apply(op.reset ? introspect::Action(introspect::ResetState{op.target, "chaos", "burst"})
                                      : introspect::Action(introspect::GenerateEvent{op.event, op.target}));
    if (local.has_value() != remote.has_value()) {
      return op.text() + ": in-process " + (local ? "accepted" : "refused (" + local.error().message + ")") +
             ", robot " + (remote ? "accepted" : "refused (" + remote.error().message + ")");
    }
    return "";
  }

  /// The new robot process starts clean: the reference forgets the robot's faults too.
  void reference_robot_restarted() {
    for (const std::string& c : components_["robot"]) ASSERT_TRUE(reset(*reference_.co, c, "chaos", "robot restarted"));
  }

  /// Polls divergence() every 20 ms for at most `bound`; true once it is empty, else `problem`
  /// holds the last one.
  bool converges(Millis bound, std::string& problem) {
    return eventually([&] { return (problem = divergence()).empty(); }, bound);
  }

  /// Everything that differs from the reference now; empty when every process has converged.
  std::string divergence() {
    std::string out;
    for (const auto& [who, client] :
         {std::pair{std::string("robot"), robot_client_.get()}, std::pair{std::string("ui"), ui_client_.get()}}) {
      const std::vector<std::string> components(components_[who].begin(), components_[who].end());
      auto rows = client->state_list();
      if (!rows) {
        out += who + ": state list failed: " + rows.error().message + "\n";
        continue;
      }
      out += diff(who + " state list", rows_of(*reference_.co, components), rows_of(*rows));
      for (const std::string& c : components) {
        auto why = client->explain(c);
        if (!why) {
          out += who + ": explain " + c + " failed: " + why.error().message + "\n";
          continue;
        }
        out += diff(who + " explain " + c, causes_of(*explain(*reference_.co, c)), causes_of(why->conditions));
      }
    }
    const SupervisorLog s(supervisor_->log());
    std::vector<std::string> want, got;
    for (const auto& [address, row] : s.view) {
      got.push_back("[" + row.first + "] " + address + " " + row.second);
      auto a = reference_.co->structure().resolve(address);
      want.push_back("[" + row.first + "] " + address + " " +
                     (a ? std::string(to_string(reference_.co->state_of(*a))) : std::string("(no such address)")));
    }
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    out += diff("supervisor view", want, got);
    for (const auto& [who, lost] : s.lost) {
      if (lost) out += "supervisor: coordinator '" + who + "' is lost\n";
    }
    return out + undelivered(s);
  }

  /// The robot's and the ui's transitions that the supervisor neither received nor reported
  /// missed (check 3 of the file comment); empty when there are none.
  std::string undelivered() { return undelivered(SupervisorLog(supervisor_->log())); }
  std::string undelivered(const SupervisorLog& s) {
    std::string out;
    for (const auto* p : {&robot_, &ui_}) {
      const std::string who = p == &robot_ ? "robot" : "ui";
      const auto printed = transitions_printed((*p)->log(), who, components_[who]);
      const Delivery d = delivered(
          printed, anchor_[who], s.received.count(who) ? s.received.at(who) : std::vector<std::string>{},
          s.late.count(who) ? s.late.at(who) : std::vector<std::string>{}, s.missed.count(who) ? s.missed.at(who) : 0);
      if (!d.ok()) out += "records: " + d.text(who) + "\n";
      for (const std::string& line : s.late.count(who) ? s.late.at(who) : std::vector<std::string>{}) {
        if (std::find(printed.begin(), printed.end(), line) == printed.end())
          out += "records: the supervisor printed late a transition the process did not make: " + line + "\n";
      }
    }
    return out;
  }

  std::string logs() const {
    std::string out;
    for (const auto* p : {&robot_, &ui_, &supervisor_}) {
      if (*p != nullptr) out += tail((*p)->log());
    }
    return out + tail(icestorm_.log(), 10);
  }

  /// Robot and ui transitions printed by the processes and received by the supervisors, and
  /// records reported missed, over the whole run.
  std::string totals() const {
    std::size_t printed = 0;
    std::uint64_t missed = 0, refused = 0;
    for (int n = 1; n <= robot_n_; ++n)
      printed += transitions_printed(log_path("robot", n), "robot", components_.at("robot")).size();
    for (int n = 1; n <= ui_n_; ++n)
      printed += transitions_printed(log_path("ui", n), "ui", components_.at("ui")).size();
    for (int n = 1; n <= supervisor_n_; ++n) {
      const SupervisorLog s(log_path("supervisor", n));
      missed += s.missed_total;
      refused += s.refused;
    }
    return std::to_string(robot_n_) + " robot, " + std::to_string(ui_n_) + " ui and " + std::to_string(supervisor_n_) +
           " supervisor processes; " + std::to_string(printed) + " transitions printed by the coordinators; " +
           std::to_string(missed) + " record(s) reported missed and " + std::to_string(refused) +
           " message(s) reported refused by the supervisors";
  }

  /// Stops every process with SIGTERM (the supervisor first, so it still sees both coordinators)
  /// and returns what is wrong with their exit reports.
  std::string stop_all() {
    std::string out;
    if (supervisor_ == nullptr || robot_ == nullptr || ui_ == nullptr || !supervisor_->running() ||
        !robot_->running() || !ui_->running()) {
      return "not every process runs at the end\n";
    }
    supervisor_->stop(SIGTERM);
    const auto lines = lines_of(supervisor_->log());
    const auto view = std::find(lines.begin(), lines.end(), "safecass supervisor: system-wide view");
    if (view == lines.end()) out += "the supervisor printed no system-wide view at exit\n";
    for (auto it = view; it != lines.end(); ++it) {
      if (it->find("' lost") != std::string::npos) out += "the supervisor's final view: " + *it + "\n";
    }
    for (auto* p : {&robot_, &ui_}) {
      const std::string who = p == &robot_ ? "robot" : "ui";
      (p == &robot_ ? robot_client_ : ui_client_).reset();
      const int status = (*p)->stop(SIGTERM);
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) out += who + " did not exit with status 0\n";
      std::string stats;
      for (const std::string& line : lines_of((*p)->log())) {
        if (line.rfind("safecass run: middleware: ", 0) == 0) stats = line;
      }
      if (stats.empty()) {
        out += who + " printed no middleware statistics at exit\n";
      } else if (stats.find(", 0 event records dropped") == std::string::npos) {
        out += who + ": " + stats + "\n";
      }
      std::printf("[chaos] %s at exit: %s\n", who.c_str(), stats.c_str());
    }
    return out;
  }

  std::string log_of(const std::string& who) const {
    return who == "robot" ? robot_->log() : who == "ui" ? ui_->log() : supervisor_->log();
  }

private:
  static std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
  }

  std::string log_path(const std::string& who, int n) const {
    return scratch_ + "/chaos-" + who + "-" + std::to_string(n) + ".log";
  }

  std::unique_ptr<middleware::RemoteClient> connect(const std::string& coordinator, const std::string& token) {
    middleware::ClientOptions o;
    o.ice = *middleware::parse_ice_endpoint(icestorm_.endpoint());
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
        15000ms);
    return c;
  }

  std::string bin_, source_, scratch_, system_, feed_;
  IceStorm icestorm_;
  Reference reference_;
  std::map<std::string, std::set<std::string>> components_;
  std::unique_ptr<Process> supervisor_, robot_, ui_;
  int supervisor_n_ = 0, robot_n_ = 0, ui_n_ = 0;
  Steady::time_point robot_up_{}, ui_up_{};  ///< when the current processes first answered
  std::unique_ptr<middleware::RemoteClient> robot_client_, ui_client_;
  /// Per coordinator: how many of its current process's transitions were printed before the
  /// current supervisor subscribed (those it cannot have received).
  std::map<std::string, std::size_t> anchor_;
  std::vector<std::string> token_files_;
  std::vector<std::string> robot_options_;
};

int count_lines_containing(const std::string& log, const std::string& text) {
  const auto lines = lines_of(log);
  return static_cast<int>(std::count_if(lines.begin(), lines.end(),
                                        [&](const std::string& l) { return l.find(text) != std::string::npos; }));
}

TEST(Chaos, EveryProcessConvergesToTheInProcessStatesAfterEachOfTwentyRandomFaultsAndRestarts) {
  const auto started = Steady::now();
  const unsigned seed = static_cast<unsigned>(std::stoul(env("SAFECASS_CHAOS_SEED", "20240611")));
  const int rounds = std::stoi(env("SAFECASS_CHAOS_ROUNDS", "20"));
  const Millis bound(std::stoi(env("SAFECASS_CHAOS_BOUND_MS", "2000")));
  std::printf("[chaos] seed %u (SAFECASS_CHAOS_SEED), %d rounds, convergence bound %lld ms\n", seed, rounds,
              static_cast<long long>(bound.count()));
  std::fflush(stdout);
  RecordProperty("seed", std::to_string(seed));
  std::mt19937 random(seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random); };

  Chaos chaos;
  ASSERT_TRUE(chaos.reference().co != nullptr);
  ASSERT_TRUE(chaos.start()) << chaos.logs();

  std::vector<Action> plan{Action::KillRobot,    Action::StopRobot,      Action::KillUi,
                           Action::KillIceStorm, Action::KillSupervisor, Action::Burst};
  std::shuffle(plan.begin(), plan.end(), random);
  while (static_cast<int>(plan.size()) < rounds) {
    const int pick = uniform(0, 6);  // bursts twice as often as each disruption
    plan.push_back(pick >= 5 ? Action::Burst : static_cast<Action>(pick));
  }
  plan.resize(static_cast<std::size_t>(std::max(rounds, 0)));

  // The processes start from Normal, as the reference does.
  std::string problem;
  {
    const auto t0 = Steady::now();
    const bool ok = chaos.converges(10000ms, problem);
    ASSERT_TRUE(ok) << "start-up: the processes do not show the in-process states\n" << problem << chaos.logs();
    std::printf("[chaos] start-up converged in %.0f ms\n", seconds_since(t0) * 1000);
  }

  double slowest = 0.0;
  int slowest_round = -1;
  for (int round = 0; round < static_cast<int>(plan.size()); ++round) {
    const Action action = plan[static_cast<std::size_t>(round)];
    std::string what = name_of(action);
    std::string failure;
    auto burst = [&](int n) {
      for (int i = 0; i < n && failure.empty(); ++i) {
        const Operation& op =
            operations()[static_cast<std::size_t>(uniform(0, static_cast<int>(operations().size()) - 1))];
        what += "\n    " + op.text();
        failure = chaos.apply(op);
      }
    };
    const auto round_started = Steady::now();
    switch (action) {
      case Action::KillRobot: {
        chaos.kill_robot();
        // Fail toward safe: the ui does not keep showing the dead robot's last state.
        if (!eventually([&] { return has_root(chaos.ui()->explain("PENDANT.s_R.Status"), "EVT_COORDINATOR_LOST"); },
                        3000ms)) {
          failure = "the ui does not show EVT_COORDINATOR_LOST on PENDANT.s_R.Status while the robot is dead";
        }
        std::this_thread::sleep_for(Millis(uniform(0, 500)));
        chaos.reference_robot_restarted();
        if (failure.empty() && !chaos.start_robot()) failure = "the robot did not restart";
        break;
      }
      case Action::StopRobot: {
        const int pause = uniform(600, 1000);
        what += " (" + std::to_string(pause) + " ms)";
        const int lost_before = count_lines_containing(chaos.log_of("ui"), "coordinator 'robot' lost");
        chaos.stop_robot(true);
        std::this_thread::sleep_for(Millis(pause));
        // While it is stopped the ui must have declared it lost (bound: 3 heartbeats, 300 ms).
        const int lost_after = count_lines_containing(chaos.log_of("ui"), "coordinator 'robot' lost");
        chaos.stop_robot(false);
        if (lost_after <= lost_before)
          failure = "the ui did not declare the stopped robot lost within " + std::to_string(pause) + " ms";
        break;
      }
      case Action::KillUi: {
        chaos.kill_ui();
        std::this_thread::sleep_for(Millis(uniform(0, 500)));
        if (!chaos.start_ui()) failure = "the ui did not restart";
        break;
      }
      case Action::KillIceStorm: {
        chaos.icestorm().kill();
        // Remote operations go straight to the processes: the robot's faults change while the
        // bus is down, and the ui, which cannot hear the robot, shows it lost.
        burst(uniform(0, 5));
        if (failure.empty() &&
            !eventually([&] { return has_root(chaos.ui()->explain("PENDANT.s_R.Status"), "EVT_COORDINATOR_LOST"); },
                        3000ms)) {
          failure = "the ui does not show EVT_COORDINATOR_LOST on PENDANT.s_R.Status while IceStorm is down";
        }
        std::this_thread::sleep_for(Millis(uniform(0, 700)));
        if (failure.empty() && !chaos.icestorm().start()) failure = "IceStorm did not restart on the same port";
        break;
      }
      case Action::KillSupervisor: {
        chaos.kill_supervisor();
        // The monitor is itself monitored: both coordinators raise EVT_SUPERVISOR_LOST.
        if (!eventually(
                [&] {
                  return has_root(chaos.robot()->explain("JR3.s_F"), "EVT_SUPERVISOR_LOST") &&
                         has_root(chaos.ui()->explain("PENDANT.s_F"), "EVT_SUPERVISOR_LOST");
                },
                3000ms)) {
          failure = "the coordinators do not show EVT_SUPERVISOR_LOST while the supervisor is dead";
        }
        std::this_thread::sleep_for(Millis(uniform(0, 500)));
        if (failure.empty() && !chaos.start_supervisor()) failure = "the supervisor did not restart";
        break;
      }
      case Action::Burst: burst(uniform(5, 30)); break;
    }
    if (!failure.empty()) {
      ADD_FAILURE() << "round " << round << " (" << what << "): " << failure << "\n" << chaos.logs();
      break;
    }
    // The disruption is over: the restarted process answers, IceStorm is ready, the supervisor is
    // connected, or the last operation returned. Every process must now converge within the bound.
    const auto over = Steady::now();
    const bool converged = chaos.converges(bound, problem);
    const double took = seconds_since(over);
    std::printf("[chaos] round %2d: %-60s converged in %4.0f ms (round %.1f s)\n", round,
                what.substr(0, what.find('\n')).c_str(), took * 1000, seconds_since(round_started));
    std::fflush(stdout);
    if (!converged) {
      ADD_FAILURE() << "round " << round << " (" << what << "): not converged " << bound.count()
                    << " ms after the disruption was over (seed " << seed << ")\n"
                    << problem << chaos.logs();
      break;
    }
    if (took > slowest) {
      slowest = took;
      slowest_round = round;
    }
  }

  const std::string totals = chaos.totals();
  const bool rounds_passed = !HasFailure();
  const std::string exit_problems = chaos.stop_all();
  if (rounds_passed) {
    EXPECT_EQ(exit_problems, "") << chaos.logs();
  }
  const double total = seconds_since(started);
  std::printf("[chaos] %s\n[chaos] slowest convergence %.0f ms (round %d); total %.1f s\n", totals.c_str(),
              slowest * 1000, slowest_round, total);
  RecordProperty("duration_s", std::to_string(total));
  EXPECT_LT(total, 180.0) << "the chaos test must stay under 3 minutes";
}

// The two tests below show what the loop above found when IceStorm was also killed right after a
// burst, before the supervisor had received the burst's records (3 of 18 seeds failed then; the
// loop now lets every round settle first). They make the loss deterministic: IceStorm is frozen
// (SIGSTOP) while the robot changes a fault, so the robot's records are accepted by IceStorm's
// socket and never forwarded; then it is killed and restarted on the same port and database, as
// after a crash. (Once the supervisor handles both cases, the loop can kill IceStorm mid-burst.)

/// Freezes IceStorm, raises EVT_FORCE_ERROR on JR3.s_A while it is frozen, kills and restarts it.
/// Starts every process with a robot that raises no EVT_SUPERVISOR_LOST during a short outage
/// (--lost-after 5000), so nothing follows the records lost in it, and waits until all converge.
void start_with_a_patient_robot(Chaos& chaos) {
  ASSERT_TRUE(chaos.reference().co != nullptr);
  chaos.robot_options({"--lost-after", "5000"});
  ASSERT_TRUE(chaos.start()) << chaos.logs();
  std::string problem;
  ASSERT_TRUE(chaos.converges(10000ms, problem)) << problem << chaos.logs();
}

void lose_a_fault_in_an_icestorm_crash(Chaos& chaos) {
  chaos.icestorm().signal(SIGSTOP);
  ASSERT_EQ(chaos.apply({false, "EVT_FORCE_ERROR", "JR3.s_A"}), "");
  std::this_thread::sleep_for(300ms);  // the robot publishes its records (5 ms) into the frozen IceStorm
  chaos.icestorm().kill();
  ASSERT_TRUE(chaos.icestorm().start());
}
// A replicated IceStorm (scripts/start-icestorm --replicas 3: IceGrid, one node, three IceBoxes)
// under the same four processes. Rounds alternate: kill -9 the master replica, kill -9 the replica
// every process publishes to (the first in priority order; not the master, which IceStorm elects
// from the highest id), and bursts. For 3 s after a kill the robot raises and clears a fault that
// reaches the ui's PENDANT.s_R.Status, the next one as soon as the ui shows the last, then more
// faults follow; the round measures the failover (the longest of those faults' ways: how long
// updates stopped flowing) and then requires, as every chaos round does, that every
// process converges to the in-process states and that no record is lost unreported. A loss the
// processes raise during the failover (it outlasts the 300 ms loss bound when the master dies: the
// replicas elect again, which takes IceStorm about a second) must clear. Before the next kill the
// killed replica is back (its node restarts it) and the replicas agree on a master again.
TEST(Chaos, WithAReplicatedBrokerEveryProcessConvergesAfterItsMasterOrAnotherReplicaIsKilledWhileFaultsAreRaised) {
  const auto started = Steady::now();
  const unsigned seed = static_cast<unsigned>(std::stoul(env("SAFECASS_CHAOS_SEED", "20261127")));
  const int rounds = std::stoi(env("SAFECASS_CHAOS_ROUNDS", "8"));
  const Millis bound(std::stoi(env("SAFECASS_CHAOS_BOUND_MS", "2000")));
  std::printf("[chaos] replicated broker: seed %u, %d rounds, convergence bound %lld ms\n", seed, rounds,
              static_cast<long long>(bound.count()));
  std::fflush(stdout);
  std::mt19937 random(seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random); };

  Chaos chaos(3);
  ASSERT_TRUE(chaos.reference().co != nullptr);
  ASSERT_TRUE(chaos.start()) << chaos.logs();
  std::string problem;
  ASSERT_TRUE(chaos.converges(10000ms, problem)) << "start-up\n" << problem << chaos.logs();

  // The marker fault: JR3's force error reaches the ui through CONTROL (PENDANT.s_R.Status).
  const Operation raise{false, "EVT_FORCE_ERROR", "JR3.s_A"}, clear{false, "/EVT_FORCE_ERROR", "JR3.s_A"};
  std::vector<double> failover_ms[2];
  for (int round = 0; round < rounds; ++round) {
    const int kind = round % 3;  // 0: the master, 1: the publishers' replica, 2: a burst
    std::string what = kind == 0   ? "kill -9 the master replica"
                       : kind == 1 ? "kill -9 the publishers' replica"
                                   : "a burst of faults";
    std::string failure;
    auto burst = [&](int n) {
      for (int i = 0; i < n && failure.empty(); ++i) {
        const Operation& op =
            operations()[static_cast<std::size_t>(uniform(0, static_cast<int>(operations().size()) - 1))];
        failure = chaos.apply(op);
      }
    };
    const auto round_started = Steady::now();
    if (kind == 2) {
      burst(uniform(5, 20));
    } else {
      int master = 0;
      if (!eventually([&] { return (master = chaos.icestorm().settled_master()) != 0; }, 15000ms)) {
        failure = "the replicas do not agree on a master before the kill:\n" + chaos.icestorm().replica_report();
      }
      const int victim = kind == 0 ? master : (master == 1 ? 2 : 1);
      what += " (" + std::to_string(victim) + ")";
      const auto killed = Steady::now();
      if (failure.empty() && !chaos.icestorm().kill_replica(victim))
        failure = "replica " + std::to_string(victim) + " was not running";
      // For 3 s after the kill the robot raises and clears the marker fault, each time as soon
      // as the ui shows the last one: the longest of those waits is how long updates stopped.
      auto in_process = [&] {
        auto why = explain(*chaos.reference().co, "PENDANT.s_R.Status");
        return why && std::any_of(why->begin(), why->end(),
                                  [](const Explanation& e) { return e.root.event == "EVT_FORCE_ERROR"; });
      };
      double longest = 0;
      int toggles = 0;
      while (failure.empty() && seconds_since(killed) < 3.0) {
        const bool before = in_process();
        const auto sent = Steady::now();
        failure = chaos.apply(before ? clear : raise);
        const bool after = in_process();
        if (!failure.empty() || after == before) break;  // another fault hides the marker: no figure
        // The failover is IceStorm's election (about a second idle); beside two busy loops and
        // another test the replicas' election rounds time out and start again, and it took over
        // 10 s. The processes stay fail-safe meanwhile (the robot lost, the ui in Error); the
        // figure printed says how long it took.
        if (!eventually([&] { return has_root(chaos.ui()->explain("PENDANT.s_R.Status"), "EVT_FORCE_ERROR") == after; },
                        30000ms)) {
          failure = "the ui does not show the fault raised " +
                    std::to_string(static_cast<int>(seconds_since(killed) * 1000)) + " ms after the kill within 30 s";
        }
        longest = std::max(longest, seconds_since(sent) * 1000);
        ++toggles;
      }
      if (toggles > 0) {
        failover_ms[kind].push_back(longest);
        what += ": " + std::to_string(toggles) + " faults, the slowest seen by the ui after " +
                std::to_string(static_cast<int>(longest)) + " ms";
      } else {
        what += ": another fault hid the marker fault (no figure)";
      }
      burst(uniform(0, 5));
      if (failure.empty() && !eventually([&] { return chaos.icestorm().settled_master() != 0; }, 15000ms)) {
        failure = "the replicas do not agree on a master again within 15 s:\n" + chaos.icestorm().replica_report();
      }
    }
    if (!failure.empty()) {
      ADD_FAILURE() << "round " << round << " (" << what << "): " << failure << "\n" << chaos.logs();
      break;
    }
    const auto over = Steady::now();
    const bool converged = chaos.converges(bound, problem);
    std::printf("[chaos] round %2d: %-90s converged in %4.0f ms (round %.1f s)\n", round, what.c_str(),
                seconds_since(over) * 1000, seconds_since(round_started));
    std::fflush(stdout);
    if (!converged) {
      ADD_FAILURE() << "round " << round << " (" << what << "): not converged " << bound.count()
                    << " ms after the disruption was over\n"
                    << problem << chaos.logs();
      break;
    }
  }
  for (int kind = 0; kind < 2; ++kind) {
    auto& v = failover_ms[kind];
    if (v.empty()) continue;
    std::sort(v.begin(), v.end());
    std::printf("[chaos] failover, %s killed: %zu rounds, %.0f–%.0f ms (median %.0f)\n",
                kind == 0 ? "the master replica" : "the publishers' replica", v.size(), v.front(), v.back(),
                v[v.size() / 2]);
  }
  const bool rounds_passed = !HasFailure();
  const std::string exit_problems = chaos.stop_all();
  if (rounds_passed) {
    EXPECT_EQ(exit_problems, "") << chaos.logs();
  }
  std::printf("[chaos] %s; total %.1f s\n", chaos.totals().c_str(), seconds_since(started));
}

// Nothing lost silently (DESIGN §7, STYLE "say what was lost"): the supervisor detects a gap in a
// coordinator's event records only when a later record arrives, although every heartbeat lists
// the last number of the coordinator's event stream (Heartbeat::events). When nothing follows
// the lost records — here the robot runs with --lost-after 5000, so it raises no
// EVT_SUPERVISOR_LOST during the outage, as after any outage shorter than the bound — they are
// never reported: the robot printed six transitions that the supervisor neither received nor
// counted as missed.
TEST(Chaos, RecordsLostInAnIceStormCrashAreReportedEvenWhenNoLaterRecordFollows) {
  Chaos chaos;
  ASSERT_NO_FATAL_FAILURE(start_with_a_patient_robot(chaos));
  std::string problem;

  lose_a_fault_in_an_icestorm_crash(chaos);
  // After the restart every process re-subscribes (with back-off) before its next heartbeat can
  // reveal the loss: 15 s bounds that on a loaded machine; an idle one takes well under a second.
  EXPECT_TRUE(eventually([&] { return (problem = chaos.undelivered()).empty(); }, 15000ms))
      << "records the robot published were lost and the supervisor does not say so\n"
      << problem << chaos.logs();
  (void)chaos.stop_all();
}

// Nothing lost silently (DESIGN §7): `console --ice watch` follows the records the robot pushes.
// Records lost in an IceStorm crash with no later record to reveal the gap would never be shown;
// the watch asks the coordinator for what its stream did not deliver before it stops.
TEST(Chaos, ConsoleWatchShowsRecordsLostInAnIceStormCrashEvenWhenNoLaterRecordFollows) {
  Chaos chaos;
  ASSERT_NO_FATAL_FAILURE(start_with_a_patient_robot(chaos));

  const auto watch = chaos.console({"--coordinator", "robot", "-c", "watch 5"}, "watch");
  std::this_thread::sleep_for(1000ms);  // connected and subscribed
  lose_a_fault_in_an_icestorm_crash(chaos);
  ASSERT_EQ(watch->wait_exit(30000ms), 0) << tail(watch->log());
  const std::string out = slurp(watch->log());
  EXPECT_NE(out.find("  JR3.s_A  Normal -> Error  EVT_FORCE_ERROR"), std::string::npos) << out << chaos.logs();
  EXPECT_NE(out.find("  SERVO.s_R.Command  Normal -> Error  EVT_SERVICE_FAILURE"), std::string::npos)
      << out << chaos.logs();
  (void)chaos.stop_all();
}

// Fail toward safe (DESIGN §4; STYLE "any doubt about a remote provider (... a gap) makes the local
// view worse, never stale-but-green"): when a later record reveals the gap, the supervisor prints
// "N event record(s) of 'robot' missed" but keeps, for every machine and component whose
// transitions were lost, the state of the last transition it received. Its system-wide view (and
// the one printed at exit) shows JR3.s_A, JR3, CONTROL.s_R.ForceData, CONTROL, SERVO.s_R.Command,
// SERVO Normal for good while the robot holds them in Error. (Only the s_S rows recover: they come
// from the state streams, which are republished.) After a reported gap the view must show the
// true states again within the chaos bound, or leave out what it cannot vouch for.
TEST(Chaos, TheSupervisorsViewShowsTheTrueStatesAgainAfterItReportsRecordsLostInAnIceStormCrash) {
  const Millis bound(std::stoi(env("SAFECASS_CHAOS_BOUND_MS", "2000")));
  Chaos chaos;
  ASSERT_TRUE(chaos.reference().co != nullptr);
  ASSERT_TRUE(chaos.start()) << chaos.logs();
  std::string problem;
  ASSERT_TRUE(chaos.converges(10000ms, problem)) << problem << chaos.logs();
  // The supervisor's view gets rows for JR3.s_A and what it feeds (Normal again after an error
  // and its completion).
  ASSERT_EQ(chaos.apply({false, "EVT_FORCE_ERROR", "JR3.s_A"}), "");
  ASSERT_EQ(chaos.apply({false, "/EVT_FORCE_ERROR", "JR3.s_A"}), "");
  ASSERT_TRUE(chaos.converges(bound, problem)) << problem << chaos.logs();

  lose_a_fault_in_an_icestorm_crash(chaos);
  // A later record of the robot reveals the gap.
  ASSERT_EQ(chaos.apply({false, "EVT_TRACKING_ERROR", "CONTROL.s_A"}), "");
  ASSERT_TRUE(eventually([&] { return SupervisorLog(chaos.log_of("supervisor")).missed["robot"] > 0; }, 10000ms))
      << "the supervisor does not report the robot's records lost in the crash\n"
      << chaos.logs();
  // The ui's records lost in the crash (it may have raised and cleared losses around it) are
  // revealed by its heartbeats once it is subscribed again: as in the test above, 15 s bounds that
  // on a loaded machine.
  EXPECT_TRUE(eventually([&] { return (problem = chaos.undelivered()).empty(); }, 15000ms)) << problem << chaos.logs();
  EXPECT_TRUE(chaos.converges(bound, problem))
      << "after reporting the missed records the supervisor still shows states the robot no longer has\n"
      << problem << chaos.logs();
  (void)chaos.stop_all();
}

}  // namespace
}  // namespace safecass
