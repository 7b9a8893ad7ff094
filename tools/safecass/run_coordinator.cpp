// `safecass run SYSTEM --coordinator NAME [--scenario S] [--ice HOST:PORT] [--duration SECONDS] [--record FILE]`:
// one coordinator of a system in real time, as one process of a multi-process system.
//
// The coordinator runs only its own components (spec::instantiate with only_coordinator); the
// providers of other coordinators its components require are remote provided interfaces fed by
// the middleware. A scenario is applied in real time: only the steps that name this coordinator's
// signals, filters and machines (the others belong to another process); an expectation is met
// when it holds at its time or within the next 200 ms (propagation across processes is
// asynchronous). With --record FILE the whole history of this coordinator is written to FILE by the
// recorder of in-process `safecass run --record` (record/recorder.hpp: a writer thread fed by a
// bounded queue, so the coordinator's threads never wait for the disk), and its losses are
// reported the same way: one line each on stderr, the exit code 2, and with --json a last
// {"kind":"recorder",...} line on stdout.

#include <CLI/CLI.hpp>

#include <unistd.h>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

#include "middleware_commands.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/native/runtime.hpp"
#include "safecass/native/system.hpp"
#include "safecass/record/input_recorder.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"
#include "stop_signals.hpp"

namespace safecass::tools {

namespace {

std::atomic<bool> g_stop{false};  ///< the end of the run: the scenario's driver stops too

std::mutex g_print;
void say(const std::string& line) {
  std::lock_guard lock(g_print);
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

struct Driver {
  Coordinator& co;
  Monitor& monitor;
  const spec::SystemSpec& system;
  const spec::Scenario& scenario;
  Time start;
  int failures = 0;
  int checks = 0;
  InputRecorder* inputs = nullptr;  ///< records the actions it applies (with --record)

  bool local_machine(const std::string& address) const {
    auto a = co.structure().resolve(address);
    if (!a) return false;
    if (a->kind == Address::Kind::System) return true;
    return !co.structure().is_remote(a->component);
  }

  /// Whether `action` belongs to this process: its signal, filter or machine is one of ours (the
  /// others belong to another coordinator's process).
  bool applies_here(const introspect::Action& action) const {
    return std::visit(
        [&](const auto& x) {
          using X = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<X, introspect::GenerateEvent> || std::is_same_v<X, introspect::ResetState>) {
            return local_machine(x.target);
          } else if constexpr (std::is_same_v<X, introspect::BroadcastEvent>) {
            return true;
          } else if constexpr (std::is_same_v<X, introspect::InjectShallow>) {
            return monitor.find_filter(x.filter) != nullptr;
          } else {  // PushSample, InjectDeep
            return monitor.signals().find(x.signal) != nullptr;
          }
        },
        action);
  }

  void run_step(const spec::ScenarioStep& s) {
    const Time now = co.clock().now();
    switch (s.kind) {
      case spec::ScenarioStep::Kind::Ramp: break;  // handled by the ramp thread
      case spec::ScenarioStep::Kind::Sample:
      case spec::ScenarioStep::Kind::Generate:
      case spec::ScenarioStep::Kind::Inject:
      case spec::ScenarioStep::Kind::Reset:
        for (const introspect::Action& action : runner::step_actions(s, monitor, system)) {
          if (!applies_here(action)) continue;
          if (auto r = introspect::apply(action, co, monitor, now, inputs); !r) {
            say("scenario: " + std::string(introspect::action_name(action)) + ": " + r.error().message);
          }
        }
        break;
      default: {
        for (const auto& [address, expected] : s.action->expectations) {
          if (!local_machine(address)) continue;
          std::string failure = runner::expectation_problem(co, s, address, expected);
          for (int i = 0; !failure.empty() && i < 20; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
            failure = runner::expectation_problem(co, s, address, expected);
          }
          ++checks;
          if (!failure.empty()) {
            ++failures;
            say("scenario: expectation failed at t=" + std::to_string(s.at) + ": " + failure);
          }
        }
      }
    }
  }

  /// Applies the steps at their times; ramps write a sample every scenario period.
  void run(const std::atomic<bool>& stop) {
    struct Ramp {
      Signal* signal;
      double from_t, until, from, to;
    };
    std::vector<Ramp> ramps;
    const double period = scenario.period > 0 ? scenario.period : 0.001;
    std::size_t next = 0;
    for (std::int64_t tick = 0; !stop.load(); ++tick) {
      const double t = static_cast<double>(tick) * period;
      if (next >= scenario.steps.size() && ramps.empty()) return;
      std::this_thread::sleep_until(std::chrono::steady_clock::time_point(
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(start + seconds_to_time(t))));
      for (; next < scenario.steps.size() && scenario.steps[next].at <= t + 1e-9; ++next) {
        const spec::ScenarioStep& s = scenario.steps[next];
        if (s.kind == spec::ScenarioStep::Kind::Ramp) {
          if (Signal* signal = monitor.signals().find(s.action->signal)) {
            ramps.push_back(Ramp{signal, s.at, s.action->until, s.action->from, s.action->to});
          }
        }
        run_step(s);
      }
      const Time now = co.clock().now();
      for (const Ramp& r : ramps) {
        const double f = r.until > r.from_t ? (t - r.from_t) / (r.until - r.from_t) : 1.0;
        r.signal->push(now, r.from + (r.to - r.from) * std::min(1.0, std::max(0.0, f)));
      }
      std::erase_if(ramps, [&](const Ramp& r) { return t >= r.until; });
    }
  }
};

}  // namespace

void add_middleware_options(CLI::App& run, RunArgs& args) {
  run.add_option("--coordinator", args.coordinator,
                 "run only this coordinator's components, in real time (a process of a multi-process system)");
  run.add_option("--ice", args.ice,
                 "with --coordinator: join the system through IceStorm at HOST:PORT (locator:HOST:PORT: a replicated "
                 "IceStorm's IceGrid registry)");
  run.add_option("--duration", args.duration,
                 "with --coordinator: stop after SECONDS (default: the scenario's, else until SIGINT/SIGTERM)");
  run.add_flag("--allow-write", args.allow_write,
               "with --ice: serve write operations (inject, generate, broadcast, reset) to holders of the token");
  run.add_option("--token-file", args.token_file, "with --allow-write: where to write the token (mode 0600)");
  run.add_option("--keys", args.keys,
                 "with --ice: the system's bus keys (safecass keys SYSTEM --out DIR; default $SAFECASS_KEYS)");
  run.add_option("--lost-after", args.lost_after_ms,
                 "with --ice: milliseconds without a provider's heartbeat before EVT_COORDINATOR_LOST (default 300)");
  run.add_flag("--insecure", args.insecure,
               "with --ice: accept a non-loopback IceStorm or listening address without TLS (unencrypted)");
  run.add_option("--tls", args.tls,
                 "with --ice: the certificates' directory (ca.pem, <coordinator>.pem/.key) when not the key directory, "
                 "which is used when it holds ca.pem");
  run.add_option("--listen", args.listen, "with --ice: the address to serve on (default 127.0.0.1)");
  run.add_option("--read-token-file", args.read_token_file,
                 "with --ice: reads (state, history, explain...) need the credential this file will hold (mode 0600)");
}

namespace {

/// The scenario of `--scenario` (checked against the whole system before anything runs) and the
/// system file to open (SYSTEM, or the scenario's). False (said) on an error.
bool load_run_scenario(const RunArgs& args, const FilterRegistry& registry, std::optional<spec::Scenario>& scenario,
                       std::string& system_path) {
  if (!args.scenario.empty()) {
    spec::ScenarioLoad loaded = spec::load_scenario(args.scenario);
    for (const auto& d : loaded.diagnostics) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
    if (!loaded.scenario) return false;
    scenario = std::move(loaded.scenario);
  }
  system_path = args.system;
  if (system_path.empty() && scenario) system_path = scenario->system;
  if (system_path.empty()) {
    std::fprintf(stderr, "safecass run: --coordinator needs a SYSTEM file (or a scenario that names one)\n");
    return false;
  }
  if (scenario) {
    // Every name the scenario uses is checked against the whole system before anything runs, as
    // `safecass run` does in simulated time; this process then applies the steps on its part.
    auto checked = runner::ScenarioRunner::open(runner::ScenarioSource{args.scenario, system_path}, registry);
    if (!checked) {
      spec::print(checked.error(), stderr);
      return false;
    }
  }
  return true;
}

/// The durable history (--record), opened before anything runs so that it holds every record of
/// the process, and the inputs next to it (samples of the local input signals and the scenario's
/// actions, read from the signals' buffers every 10 ms by the recorder's own thread). False (said)
/// on an error.
bool open_histories(const RunArgs& args, Coordinator& co, Monitor& monitor, Time period,
                    std::unique_ptr<Recorder>& recorder, std::unique_ptr<InputRecorder>& inputs) {
  if (!args.record.empty()) {
    auto history_file = Recorder::open(co, args.record, 65536, FileLimits{args.max_bytes});
    if (!history_file) {
      std::fprintf(stderr, "safecass run: %s\n", history_file.error().message.c_str());
      return false;
    }
    recorder = std::move(*history_file);
  }
  const std::string inputs_path = !args.record_inputs.empty() ? args.record_inputs
                                  : args.record.empty()       ? std::string()
                                                              : InputRecorder::path_for_history(args.record);
  if (inputs_path.empty() || inputs_path == "-") return true;
  InputRecorderOptions o;
  o.limits.max_bytes = args.max_bytes;
  o.period = period;
  o.clock = "steady";
  auto input_recorder = InputRecorder::open(monitor, inputs_path, o);
  if (!input_recorder) {
    std::fprintf(stderr, "safecass run: %s\n", input_recorder.error().message.c_str());
    return false;
  }
  inputs = std::move(*input_recorder);
  inputs->start_polling();
  return true;
}

/// A coordinator process on the bus (--ice): its token files and its node. Members are destroyed
/// in reverse order: the node before the recorded writes it calls.
struct BusPart {
  std::string token_path;
  std::unique_ptr<middleware::TokenFile> token_file;  ///< held (locked) until the process ends
  std::unique_ptr<middleware::TokenFile> read_token_file;
  std::unique_ptr<middleware::CoordinatorNode> node;
};

/// Joins the bus when --ice is given: makes the token files, then creates and starts the node.
/// False (said) on an error, or on --allow-write without --ice.
bool join_bus(const RunArgs& args, native::System& built, const FilterRegistry& registry, InputRecorder* inputs,
              BusPart& bus) {
  if (args.ice.empty()) {
    if (!args.allow_write) return true;
    std::fprintf(stderr, "safecass run: --allow-write needs --ice (write operations come through the middleware)\n");
    return false;
  }
  auto endpoint = middleware::parse_ice_endpoint(args.ice);
  if (!endpoint) {
    std::fprintf(stderr, "safecass run: %s\n", endpoint.error().message.c_str());
    return false;
  }
  std::string token;
  if (args.allow_write) {
    // Never over a file that is not ours, never shared with a running process (token.hpp).
    auto t = args.token_file.empty() ? middleware::TokenFile::create_default(args.coordinator)
                                     : middleware::TokenFile::create(args.token_file);
    if (!t) {
      std::fprintf(stderr, "safecass run: %s\n", t.error().message.c_str());
      return false;
    }
    bus.token_file = std::move(*t);
    token = bus.token_file->secret();
    bus.token_path = bus.token_file->path();
  }
  if (!args.read_token_file.empty()) {
    auto t = middleware::TokenFile::create(args.read_token_file);
    if (!t) {
      std::fprintf(stderr, "safecass run: --read-token-file: %s\n", t.error().message.c_str());
      return false;
    }
    bus.read_token_file = std::move(*t);
  }
  middleware::NodeOptions options;
  options.ice = *endpoint;
  options.allow_write = args.allow_write;
  options.token = token;
  if (bus.read_token_file) options.read_token = bus.read_token_file->secret();
  options.keys_dir = args.keys;
  options.insecure = args.insecure;
  options.tls.dir = args.tls;
  if (!args.listen.empty()) options.listen_host = args.listen;
  options.lost_after = std::chrono::milliseconds(std::max(0, args.lost_after_ms));
  options.log = [](const std::string& line) { say(line); };
  options.clock.actions = inputs;  // the console's and viewer's writes, recorded (with --record)
  auto created = middleware::CoordinatorNode::create(built.coordinator(), built.monitor(), registry, built.spec(),
                                                     args.coordinator, options);
  if (!created) {
    std::fprintf(stderr, "safecass run: %s\n", created.error().message.c_str());
    return false;
  }
  bus.node = std::move(*created);
  if (auto r = bus.node->start(); !r) {
    std::fprintf(stderr, "safecass run: %s\n", r.error().message.c_str());
    return false;
  }
  return true;
}

/// Closes the histories once every thread that makes records has stopped, and says every loss:
/// nothing is lost silently, and a history that misses records fails the command (`code` 2).
/// Returns whether both are complete; with --json, their status lines go to `status_json`.
bool close_histories(const RunArgs& args, InputRecorder* inputs, Recorder* recorder, int& code,
                     std::string& status_json) {
  bool complete = true;
  if (inputs != nullptr) {
    inputs->close();
    const InputRecordStatus status = inputs->status();
    for (const std::string& loss : describe_losses(status)) std::fprintf(stderr, "%s\n", loss.c_str());
    std::fflush(stderr);
    complete = status.complete();
    if (args.json) status_json = record_status_json(status);
  }
  if (recorder != nullptr) {
    recorder->close();  // what is queued is the end of the history
    const RecordStatus status = recorder->status();
    for (const std::string& loss : describe_losses(status)) std::fprintf(stderr, "%s\n", loss.c_str());
    std::fflush(stderr);
    complete = complete && status.complete();
    if (args.json) status_json += (status_json.empty() ? "" : "\n") + record_status_json(status);
  }
  if (!complete) code = 2;
  return complete;
}

}  // namespace

int run_coordinator(const RunArgs& args) {
  const StopSignals stop_signals;  // before any thread starts
  const FilterRegistry& registry = builtin_filters();
  std::optional<spec::Scenario> scenario;
  std::string system_path;
  if (!load_run_scenario(args, registry, scenario, system_path)) return 2;
  middleware::HostClock clock;
  native::SystemOptions system_options;
  system_options.coordinator = args.coordinator;
  system_options.clock = &clock;
  if (scenario) system_options.component_period = seconds_to_time(scenario->period);
  spec::Diagnostics notes;
  auto opened = native::open_system(system_path, registry, system_options, &notes);
  spec::print(notes, stderr);
  if (!opened) {
    spec::print(opened.error(), stderr);
    return 2;
  }
  native::System& built = **opened;
  const spec::SystemSpec& system = built.spec();
  Coordinator& co = built.coordinator();
  Monitor& monitor = built.monitor();
  native::Runtime& runtime = built.runtime();
  if (auto r = middleware::connect_remote_providers(system, args.coordinator, co); !r) {
    std::fprintf(stderr, "safecass run: %s\n", r.error().message.c_str());
    return 2;
  }
  co.subscribe([&co](const Record& r) {
    if (r.kind != RecordKind::Transition && r.kind != RecordKind::ComponentTransition) return;
    // The coordinator's lock is free while observers run: history_entry() may read it.
    say("[" + std::string(co.structure().name()) + "] " + introspect::live_line(introspect::history_entry(r, co)));
  });
  std::unique_ptr<Recorder> recorder;
  std::unique_ptr<InputRecorder> inputs;
  if (!open_histories(args, co, monitor, system_options.component_period, recorder, inputs)) return 2;
  BusPart bus;
  if (!join_bus(args, built, registry, inputs.get(), bus)) return 2;

  std::size_t local = 0;
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count()))
    local += co.structure().is_remote(c) ? 0 : 1;
  say("safecass run: coordinator '" + args.coordinator + "' of system '" + system.name + "', " + std::to_string(local) +
      " components, pid " + std::to_string(::getpid()) +
      (args.ice.empty() ? std::string(", no middleware") : ", IceStorm " + args.ice) +
      (args.allow_write ? ", write access (token file " + bus.token_path + ")" : ", read-only"));
  if (bus.node) say("safecass run: control " + bus.node->control_proxy());

  runtime.start();
  const double duration = args.duration > 0 ? args.duration : (scenario ? scenario->duration : 0.0);
  const Time start = clock.now();
  int failures = 0;
  int checks = 0;
  std::thread driver;
  std::unique_ptr<Driver> d;
  if (scenario) {
    d = std::make_unique<Driver>(Driver{co, monitor, system, *scenario, start});
    d->inputs = inputs.get();
    driver = std::thread([&] { d->run(g_stop); });
  }
  (void)stop_signals.wait(deadline_after(duration));
  g_stop.store(true);
  if (driver.joinable()) driver.join();
  if (d) {
    failures = d->failures;
    checks = d->checks;
  }
  runtime.stop();
  if (bus.node) {
    const middleware::NodeStats s = bus.node->stats();
    bus.node->stop();
    say("safecass run: middleware: " + std::to_string(s.updates_published) + " updates published, " +
        std::to_string(s.updates_applied) + " applied, " + std::to_string(s.updates_rejected) + " rejected, " +
        std::to_string(s.updates_missed) + " missed, " + std::to_string(s.resyncs_requested) + " resyncs, " +
        std::to_string(s.connects) + " connections, " + std::to_string(s.events_dropped) + " event records dropped");
  }
  if (bus.token_file) bus.token_file->remove();
  int code = failures == 0 ? 0 : 1;
  std::string recorder_status;
  const bool history_complete = close_histories(args, inputs.get(), recorder.get(), code, recorder_status);
  say("safecass run: coordinator '" + args.coordinator + "' stopped; system state " +
      std::string(to_string(co.coordinator_state())) +
      (scenario ? ", " + std::to_string(checks) + " expectations checked, " + std::to_string(failures) + " failed"
                : "") +
      (history_complete ? "" : "; the history file is incomplete (see above)"));
  if (!recorder_status.empty()) say(recorder_status);
  return code;
}

}  // namespace safecass::tools
