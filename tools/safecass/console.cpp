// `safecass console`: the one backend (every command over a SystemQuery, in-process or live), the
// in-process target (a system in simulated time) and the terminal front end (run_console). The
// parser and `help` are in console_shell.cpp; the live target is in console_remote.cpp.

#include "console.hpp"
#include "console_shell.hpp"
#ifdef SAFECASS_WITH_ICE
#include "console_remote.hpp"
#endif

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <editline/readline.h>
#include <CLI/CLI.hpp>

#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/file.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::tools {

namespace in = introspect;

namespace {

// ---- the one backend -----------------------------------------------------------------------------

/// Runs every command against one SystemQuery. A simulated system (target.advance set) is
/// followed for the whole session, so a write prints the records it caused; a live one is
/// followed during `watch` only (its records arrive by themselves, pushed by the coordinator).
class QueryBackend final : public Backend {
public:
  QueryBackend(Target target, ConsoleOptions options) : target_(std::move(target)), options_(options) {}

  [[nodiscard]] Expected<void> init() {
    auto clock = target_.query->clock();
    if (!clock) return tl::unexpected(clock.error());
    time_ = in::TimeFormat(*clock);
    simulated_ = clock->base == in::TimeBase::Simulated;
    auto names = target_.query->names();
    if (!names) return tl::unexpected(names.error());
    names_ = std::move(*names);
    if (target_.advance) {
      auto sub = target_.query->follow([this](const in::HistoryEntry& e) { capture(e); });
      if (!sub) return tl::unexpected(sub.error());
      following_ = std::move(*sub);
    }
    return {};
  }

  std::vector<std::string> names(Arg kind) const override {
    switch (kind) {
      case Arg::Component: return names_.components;
      case Arg::Machine: return names_.machines;
      case Arg::Address: return names_.addresses;
      case Arg::Event: return names_.events;
      case Arg::Filter: return names_.filters;
      case Arg::FilterOrType: {
        std::vector<std::string> out = names_.filters;
        out.insert(out.end(), names_.filter_types.begin(), names_.filter_types.end());
        return out;
      }
      case Arg::Signal: return names_.signals;
      case Arg::Command:
      case Arg::None:
      case Arg::File: break;
    }
    return {};
  }

  std::string banner() const override {
    std::string access = "read-only";
    if (options_.allow_write) access = target_.write_access.empty() ? "writes allowed" : target_.write_access;
    std::string when;
    if (simulated_) {
      auto clock = target_.query->clock();
      if (clock) when = ", simulated time " + time_.at(clock->now);
    } else {
      when = ", live";
    }
    return "safecass console: " + target_.subject + when + ", " + access + ". Type help, or TAB to complete.";
  }

  void begin() override { take_captured(); }
  void end(Out& out, bool ok) override {
    std::vector<std::string> lines = take_captured();
    if (!ok) return;
    for (std::string& l : lines) out.line(std::move(l));
  }

  std::string run(const CommandSpec& c, const std::vector<std::string>& args, Out& out) override {
    in::SystemQuery& q = *target_.query;
    switch (c.id) {
      case Id::StateList: {
        auto rows = q.state_list(args.empty() ? std::string() : args[0]);
        if (!rows) return rows.error().message;
        out.reply.out += options_.json ? in::state_list_json(*rows) : in::state_list_text(*rows);
        return {};
      }
      case Id::Read: {
        auto answer = q.read(c.name, args);
        if (!answer) return answer.error().message;
        if (options_.json) {
          out.reply.out += *answer;
          return {};
        }
        auto text = in::read_text(c.name, *answer);
        if (!text) return text.error().message;
        out.reply.out += *text;
        return {};
      }
      case Id::StateHistory: return state_history(args, out);
      case Id::FilterList: {
        auto rows = q.filter_list();
        if (!rows) return rows.error().message;
        out.reply.out += options_.json ? in::filter_list_json(*rows) : in::filter_list_text(*rows);
        return {};
      }
      case Id::FilterInfo: {
        auto info = q.filter_info(args[0]);
        if (!info) return info.error().message;
        out.reply.out += options_.json ? in::filter_info_json(*info) : in::filter_info_text(*info);
        return {};
      }
      case Id::FilterInject: {
        auto samples = parse_samples({args.begin() + 1, args.end()});
        if (!samples) return samples.error().message;
        if (auto r = q.apply(in::InjectShallow{args[0], *samples}); !r) return r.error().message;
        done(out, c, Json().str("filter", args[0]).integer("samples", static_cast<long long>(samples->size())),
             "queued " + count_text(samples->size()) + " into filter " + args[0] +
                 " (seen by that filter alone on its next runs: use watch)");
        return {};
      }
      case Id::FilterDinject: {
        auto samples = parse_samples({args.begin() + 1, args.end()});
        if (!samples) return samples.error().message;
        return deep_inject(c, args[0], *samples, out);
      }
      case Id::FilterDinload: {
        std::string text;
        std::string error;
        if (!spec::read_file(args[1], text, error)) return error;
        auto samples = parse_sample_file(args[1], text);
        if (!samples) return samples.error().message;
        return deep_inject(c, args[0], *samples, out);
      }
      case Id::EventList: {
        auto rows = q.event_list();
        if (!rows) return rows.error().message;
        out.reply.out += options_.json ? in::event_list_json(*rows) : in::event_list_text(*rows);
        return {};
      }
      case Id::EventHistory: {
        std::size_t last = kDefaultHistory;
        if (!args.empty()) {
          const auto n = parse_count(args[0]);
          if (!n) return "N must be a positive whole number, not '" + args[0] + "'";
          last = static_cast<std::size_t>(*n);
        }
        auto records = q.history("SYSTEM", last, in::HistoryFilter::Events);
        if (!records) return records.error().message;
        print_records(*records, out, "no events yet");
        return {};
      }
      case Id::EventGenerate: {
        if (auto r = q.apply(in::GenerateEvent{args[0], args[1]}); !r) return r.error().message;
        done(out, c, Json().str("event", args[0]).str("target", args[1]), "generated " + args[0] + " on " + args[1],
             true);
        return {};
      }
      case Id::EventBroadcast: {
        if (auto r = q.apply(in::BroadcastEvent{args[0]}); !r) return r.error().message;
        done(out, c, Json().str("event", args[0]), "broadcast " + args[0], true);
        return {};
      }
      case Id::ConnectionList: {
        auto rows = q.connection_list();
        if (!rows) return rows.error().message;
        out.reply.out += options_.json ? in::connection_list_json(*rows) : in::connection_list_text(*rows);
        return {};
      }
      case Id::ServiceList: {
        auto rows = q.service_list();
        if (!rows) return rows.error().message;
        out.reply.out += options_.json ? in::service_list_json(*rows) : in::service_list_text(*rows);
        return {};
      }
      case Id::Explain: {
        auto answer = q.explain(args[0]);
        if (!answer) return answer.error().message;
        out.reply.out += options_.json ? in::explain_json(*answer) : in::explain_text(*answer, time_);
        return {};
      }
      case Id::Watch: return watch(args, out);
      case Id::Reset: {
        std::string reason;
        for (std::size_t i = 1; i < args.size(); ++i) reason += (reason.empty() ? "" : " ") + args[i];
        if (reason.empty()) reason = "reset from the console";
        if (auto r = q.apply(in::ResetState{args[0], "console", reason}); !r) return r.error().message;
        const std::string when = now_text();
        done(out, c, Json().str("target", args[0]).str("reason", reason),
             "reset " + args[0] + (when.empty() ? std::string() : " at " + when) + " (" + reason + ")");
        return {};
      }
      case Id::Time: return time(out);
      case Id::Help:
      case Id::Quit: break;  // the Console answers these itself
    }
    return "not available here";
  }

private:
  /// A record that `watch` (or a write, in-process) shows, formatted; any thread.
  void capture(const in::HistoryEntry& e) {
    if (!in::shown_while_watching(e)) return;
    std::string line = options_.json ? in::history_json(e) : in::history_text(e, time_);
    std::lock_guard lock(mutex_);
    if (e.kind == RecordKind::Transition) ++transitions_;
    captured_.push_back(std::move(line));
  }

  std::vector<std::string> take_captured() {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    out.swap(captured_);
    return out;
  }

  std::size_t transitions() {
    std::lock_guard lock(mutex_);
    return transitions_;
  }

  /// The system's current time as a record line starts it ("t=0.301000", or wall-clock time).
  std::string now_text() const {
    auto clock = target_.query->clock();
    return clock ? time_.at(clock->now) : std::string();
  }

  /// The confirmation of a write: `text` (with the time when `timed`), or a JSON object with ok,
  /// command and the time t in seconds of the system's clock.
  void done(Out& out, const CommandSpec& c, Json json, const std::string& text, bool timed = false) const {
    auto clock = target_.query->clock();
    if (!options_.json) {
      out.line(timed && clock ? text + " at " + time_.at(clock->now) : text);
      return;
    }
    json.boolean("ok", true).str("command", c.name);
    if (clock) json.num("t", to_seconds(clock->now));
    out.line(json.text());
  }

  std::string deep_inject(const CommandSpec& c, const std::string& signal,
                          const std::vector<std::vector<double>>& samples, Out& out) {
    if (auto r = target_.query->apply(in::InjectDeep{signal, samples}); !r) return r.error().message;
    const std::string when = now_text();
    done(out, c, Json().str("signal", signal).integer("samples", static_cast<long long>(samples.size())),
         "wrote " + count_text(samples.size()) + " into signal " + signal +
             (when.empty() ? std::string() : " at " + when) + " (seen by every consumer on its next run: use watch)");
    return {};
  }

  void print_records(const std::vector<in::HistoryEntry>& records, Out& out, std::string_view empty) const {
    for (const in::HistoryEntry& e : records)
      out.line(options_.json ? in::history_json(e) : in::history_text(e, time_));
    if (records.empty() && !options_.json) out.line(std::string(empty));
  }

  std::string state_history(const std::vector<std::string>& args, Out& out) {
    std::string scope = "SYSTEM";
    std::size_t last = kDefaultHistory;
    std::size_t next = 0;
    if (!args.empty() && !parse_count(args[0])) {
      scope = args[0];
      next = 1;
    }
    if (next < args.size()) {
      const auto n = parse_count(args[next]);
      if (!n) return "N must be a positive whole number, not '" + args[next] + "'";
      last = static_cast<std::size_t>(*n);
      ++next;
    }
    if (next < args.size()) return "too many arguments";
    auto records = target_.query->history(scope, last);
    if (!records) return records.error().message;
    print_records(*records, out, "no records");
    return {};
  }

  /// Simulated: advances time tick by tick, printing each record as it happens. Live: follows the
  /// coordinator's pushed records for SECONDS of real time, each printed with its own time.
  std::string watch(const std::vector<std::string>& args, Out& out) {
    double seconds = 1.0;
    if (!args.empty()) {
      const auto v = parse_number(args[0]);
      if (!v || !std::isfinite(*v) || *v <= 0 || *v > kMaxWatchSeconds) {
        return "SECONDS must be a number of seconds above 0 and at most " + number_text(kMaxWatchSeconds) + ", not '" +
               args[0] + "'";
      }
      seconds = *v;
    }
    auto clock = target_.query->clock();
    if (!clock) return clock.error().message;
    const Time start = clock->now;
    const std::size_t before = transitions();
    if (target_.advance) {
      const Time tick = seconds_to_time(clock->period > 0 ? clock->period : 0.001);
      const Time until = start + seconds_to_time(seconds);
      for (Time t = start + tick; t <= until; t += tick) {
        const std::vector<std::string> failures = target_.advance(t);
        for (std::string& l : take_captured()) out.line(std::move(l));
        for (const std::string& f : failures)
          out.line(options_.json ? Json().str("kind", "expectation").str("failure", f).text() : f);
      }
    } else {
      auto sub = target_.query->follow([this](const in::HistoryEntry& e) { capture(e); });
      if (!sub) return sub.error().message;
      const auto until =
          std::chrono::steady_clock::now() +
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
      while (std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(
            std::chrono::milliseconds(50), until - std::chrono::steady_clock::now()));
      }
      // The last records of the watch may have been lost on the bus with nothing after them to
      // reveal the gap: fetch what the stream did not deliver before stopping.
      if (auto caught = (*sub)->catch_up(); !caught) out.line(caught.error().message);
      sub->reset();  // no record arrives after this
      for (std::string& l : take_captured()) out.line(std::move(l));
    }
    const std::size_t seen = transitions() - before;
    auto after = target_.query->clock();
    const Time end = after ? after->now : start;
    if (options_.json) {
      out.line(Json()
                   .str("command", "watch")
                   .num("from", to_seconds(start))
                   .num("t", to_seconds(end))
                   .num("seconds", seconds)
                   .integer("transitions", static_cast<long long>(seen))
                   .text());
    } else {
      out.line((simulated_ ? time_.at(end) + "  watched " : "watched " + target_.query->name() + " for ") +
               number_text(seconds) + " s: " + std::to_string(seen) + (seen == 1 ? " transition" : " transitions"));
    }
    return {};
  }

  std::string time(Out& out) {
    auto clock = target_.query->clock();
    if (!clock) return clock.error().message;
    if (clock->base != in::TimeBase::Simulated) {
      return "in-process only: coordinator '" + target_.query->name() +
             "' runs in real time (use watch SECONDS to follow it)";
    }
    const Time now = clock->now;
    if (options_.json) {
      Json j;
      j.num("t", to_seconds(now)).num("period", clock->period);
      if (!clock->scenario.empty()) j.str("scenario", clock->scenario).num("duration", clock->duration);
      out.line(j.text());
      return {};
    }
    std::string line = "t=" + seconds_text(now) + " s (simulated; tick " + number_text(clock->period) + " s";
    if (!clock->scenario.empty()) {
      line += "; scenario " + clock->scenario + " lasts " + number_text(clock->duration) + " s" +
              (now > seconds_to_time(clock->duration) ? ", ended" : "");
    }
    out.line(line + ")");
    return {};
  }

  Target target_;
  ConsoleOptions options_;
  in::TimeFormat time_;
  bool simulated_ = true;
  in::Names names_;
  std::mutex mutex_;  // captured_ and transitions_: records may arrive on another thread
  std::vector<std::string> captured_;
  std::size_t transitions_ = 0;
  std::unique_ptr<in::Subscription> following_;  // last: unsubscribed first
};

/// A system built in this process, run in simulated time by a scenario runner.
struct InProcessSystem {
  std::unique_ptr<runner::ScenarioRunner> runner;
  runner::RunResult result;  // expectation failures of the scenario so far
  std::size_t failures_reported = 0;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<Backend>> make_backend(Target target, ConsoleOptions options) {
  auto backend = std::make_unique<QueryBackend>(std::move(target), options);
  if (auto r = backend->init(); !r) return tl::unexpected(r.error());
  return std::unique_ptr<Backend>(std::move(backend));
}

// ---- Console -------------------------------------------------------------------------------------

Expected<std::unique_ptr<Console>> Console::open(const std::string& system, const std::string& scenario,
                                                 ConsoleOptions options) {
  auto sys = std::make_shared<InProcessSystem>();
  auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{scenario, system}, builtin_filters());
  if (!opened) return fail(ErrorCode::InvalidArgument, spec::to_text(opened.error()));
  sys->runner = std::move(*opened);
  const spec::Scenario& sc = sys->runner->scenario();
  const std::string system_path = sc.system;
  in::LocalOptions local;
  local.base = in::TimeBase::Simulated;
  local.period = sc.period;
  local.scenario = scenario;
  local.duration = sc.duration;
  sys->runner->advance_to(Time{0}, sys->result);  // what happens at t = 0 is in the histories
  Coordinator& co = sys->runner->coordinator();
  Target target;
  target.query = std::make_unique<in::LocalQuery>(co, sys->runner->monitor(), builtin_filters(), local);
  target.subject = "system " + system_path + " (" + std::to_string(co.structure().component_count()) + " components" +
                   (scenario.empty() ? "" : ", scenario " + scenario) + ")";
  InProcessSystem* raw = sys.get();
  target.advance = [raw](Time t) {
    raw->runner->advance_to(t, raw->result);
    std::vector<std::string> failures(
        raw->result.failures.begin() + static_cast<std::ptrdiff_t>(raw->failures_reported), raw->result.failures.end());
    raw->failures_reported = raw->result.failures.size();
    return failures;
  };
  target.owner = std::move(sys);
  auto backend = make_backend(std::move(target), options);
  if (!backend) return tl::unexpected(backend.error());
  return std::make_unique<Console>(std::move(*backend), options);
}

// ---- terminal front end --------------------------------------------------------------------------

namespace {

void print(const ConsoleReply& reply) {
  std::fputs(reply.out.c_str(), stdout);
  std::fflush(stdout);
  std::fputs(reply.err.c_str(), stderr);
  std::fflush(stderr);
}

/// Runs commands one after the other; 2 when any failed, 0 otherwise.
int run_batch(Console& console, const std::vector<std::string>& lines) {
  bool failed = false;
  for (const std::string& line : lines) {
    const ConsoleReply reply = console.execute(line);
    print(reply);
    failed = failed || !reply.ok;
    if (reply.quit) break;
  }
  return failed ? 2 : 0;
}

// libedit calls plain C functions: these statics connect them to the one interactive console.
Console* g_console = nullptr;
std::vector<std::string> g_matches;
std::size_t g_next_match = 0;

char* next_match(const char* /*text*/, int state) {
  if (state == 0) g_next_match = 0;
  if (g_next_match >= g_matches.size()) return nullptr;
  return strdup(g_matches[g_next_match++].c_str());
}

char** attempt_completion(const char* text, int start, int /*end*/) {
  const std::string line = rl_line_buffer != nullptr ? std::string(rl_line_buffer) : std::string();
  const std::string before = line.substr(0, std::min(line.size(), static_cast<std::size_t>(std::max(start, 0))));
  if (g_console->completes_file(before)) return nullptr;  // libedit completes the file name
  rl_attempted_completion_over = 1;
  g_matches = g_console->complete(before, text);
  if (g_matches.empty()) return nullptr;
  return rl_completion_matches(text, next_match);
}

int run_interactive(Console& console) {
  g_console = &console;
  rl_readline_name = "safecass";
  rl_attempted_completion_function = attempt_completion;
  using_history();
  stifle_history(1000);
  std::printf("%s\n", console.banner().c_str());
  std::fflush(stdout);
  std::string previous;
  for (;;) {
    char* raw = readline("safecass> ");
    if (raw == nullptr) {  // end of input (Ctrl-D)
      std::printf("\n");
      break;
    }
    const std::string line(raw);
    std::free(raw);
    const std::string entry(trim(line));
    if (!entry.empty() && entry != previous) {
      add_history(entry.c_str());
      previous = entry;
    }
    const ConsoleReply reply = console.execute(line);
    print(reply);
    if (reply.quit) break;
  }
  g_console = nullptr;
  return 0;
}

}  // namespace

std::vector<std::string> split_commands(const std::string& text) {
  std::vector<std::string> out;
  std::string current;
  for (const char c : text) {
    if (c == ';' || c == '\n') {
      out.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  out.push_back(current);
  return out;
}

int run_console(const ConsoleArgs& args) {
  std::vector<std::string> script;
  if (!args.script.empty()) {
    std::string text;
    std::string error;
    if (!spec::read_file(args.script, text, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 2;
    }
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) script.push_back(line);
  }
  Expected<std::unique_ptr<Console>> console = fail(ErrorCode::InvalidArgument, "no console");
  if (!args.ice.empty()) {
#ifdef SAFECASS_WITH_ICE
    console = connect_console(args);
#else
    std::fprintf(stderr,
                 "console: --ice needs the middleware, and this safecass was built without it (SAFECASS_WITH_ICE)\n");
    return 2;
#endif
  } else {
    console = Console::open(args.system, args.scenario, ConsoleOptions{args.json, args.allow_write});
  }
  if (!console) {
    std::fprintf(stderr, "%s\n", console.error().message.c_str());
    return 2;
  }
  if (!args.commands.empty()) return run_batch(**console, split_commands(args.commands));
  if (!args.script.empty()) return run_batch(**console, script);
  if (isatty(STDIN_FILENO) != 0) return run_interactive(**console);
  std::vector<std::string> lines;
  for (std::string line; std::getline(std::cin, line);) lines.push_back(line);
  return run_batch(**console, lines);
}

void add_console_command(CLI::App& app, int& code) {
  auto args = std::make_shared<ConsoleArgs>();
  auto* cmd =
      app.add_subcommand("console", "Read and write the component model of a system, interactively or from commands");
  cmd->footer(
      "Runs the system in-process in simulated time (as `safecass run` does); with --scenario its steps are "
      "applied as `watch` advances time. With --ice HOST:PORT --coordinator NAME it works on a live coordinator "
      "process instead (`safecass run ... --coordinator NAME --ice ...`), found through IceStorm; writes then also "
      "need the coordinator's token (--token-file), and `watch SECONDS` prints its records as the bus pushes them. "
      "Write commands (filter "
      "inject/dinject/dinload, event generate/broadcast, reset) are refused unless --allow-write is given. Without "
      "-c or --script, commands are read from the terminal (line editing, history, TAB completion) or from stdin. "
      "Exit code 2 when the system cannot be loaded or the coordinator cannot be reached, or, with "
      "-c/--script/stdin, when any command failed; 0 otherwise. Type `help` inside the console for the commands.");
  cmd->add_option("--system", args->system, "system file (default: the scenario's \"system\")");
  cmd->add_option("--scenario,-s", args->scenario, "scenario file whose steps are applied as simulated time advances");
  auto* commands = cmd->add_option("-c,--command", args->commands, "commands to run, separated by ';'");
  cmd->add_option("--script", args->script, "file of commands, one per line ('#' starts a comment)")
      ->excludes(commands);
  cmd->add_flag("--json", args->json, "print one JSON object per result line");
  cmd->add_flag("--allow-write", args->allow_write, "accept write commands (inject, generate, broadcast, reset)");
  cmd->add_option("--ice", args->ice,
                  "work on a live coordinator: IceStorm at HOST:PORT, or locator:HOST:PORT for a replicated one (with "
                  "--coordinator)");
  cmd->add_option("--coordinator", args->coordinator, "with --ice: the coordinator's name");
  cmd->add_option("--keys", args->keys,
                  "with --ice: the system's bus keys (only the keyring is read; default $SAFECASS_KEYS)");
  cmd->add_flag("--insecure", args->insecure,
                "with --ice: accept a coordinator not on this host although requests and the token are not encrypted");
  cmd->add_option("--read-token-file", args->read_token_file,
                  "with --ice: the coordinator's read credential file (when it was started with one)");
  cmd->add_option("--tls", args->tls,
                  "with --ice: the certificates' directory (ca.pem, reader.pem/.key) when not the key directory, which "
                  "is used when it holds ca.pem");
  cmd->add_option("--token-file", args->token_file, "with --ice: the coordinator's token file (writes need it)");
  cmd->add_option("--timeout", args->timeout_ms,
                  "with --ice: milliseconds to wait for the coordinator and each answer (default 2000)")
      ->check(CLI::Range(100, 600000));
  cmd->callback([args, &code] {
    const bool remote = !args->ice.empty() || !args->coordinator.empty() || !args->token_file.empty();
    std::string usage;
    if (remote && (args->ice.empty() || args->coordinator.empty())) {
      usage = "console: --ice HOST:PORT and --coordinator NAME go together";
    } else if (remote && (!args->system.empty() || !args->scenario.empty())) {
      usage = "console: --ice works on a live coordinator: --system and --scenario are for the in-process console";
    } else if (!remote && args->system.empty() && args->scenario.empty()) {
      usage = "console: --system (or --scenario, or --ice with --coordinator) is required";
    }
    if (!usage.empty()) {
      std::fprintf(stderr, "%s\n", usage.c_str());
      code = 2;
      return;
    }
    code = run_console(*args);
  });
}

}  // namespace safecass::tools
