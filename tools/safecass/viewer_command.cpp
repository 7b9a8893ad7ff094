// `safecass viewer`: loads a system (and scenario), runs it in real time in this process and
// serves the live view until Ctrl-C / SIGTERM; with --ice, watches a live multi-process system
// through the middleware instead.

#include "viewer_command.hpp"

#include <spawn.h>
#include <sys/wait.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "safecass/middleware/token.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/replay_source.hpp"
#include "safecass/viewer/server.hpp"
#ifdef SAFECASS_WITH_ICE
#include "safecass/viewer/middleware_source.hpp"
#endif

extern char** environ;

namespace safecass::tools {

namespace {

struct ViewerArgs {
  std::string system;
  std::string scenario;
  int port = 8765;
  std::string bind = "127.0.0.1";
  double speed = 1.0;
  bool allow_write = false;
  bool open = false;
  std::string ice;                            ///< --ice HOST:PORT: a live system
  std::string keys;                           ///< --keys DIR: the system's bus keys
  std::string tls;                            ///< --tls DIR: mutual TLS
  std::vector<std::string> read_token_files;  ///< --read-token-file COORD=FILE
  std::vector<std::string> token_files;       ///< --token-file COORD=FILE
  bool speed_given = false;
  std::string replay;   ///< --replay LOG: a recorded input log fed through --system
  std::string format;   ///< --format of the log
  std::string mapping;  ///< --mapping: a bag's mapping file
};

/// The source: the system in this process, or (--ice) the live system through the middleware.
[[nodiscard]] Expected<std::unique_ptr<viewer::ViewSource>> open_source(const ViewerArgs& args) {
  if (!args.replay.empty()) {
    if (!args.ice.empty() || !args.scenario.empty()) {
      return fail(ErrorCode::InvalidArgument,
                  "safecass viewer: --replay shows a recorded log; --scenario and --ice drive a running system");
    }
    if (args.allow_write || !args.token_files.empty()) {
      return fail(ErrorCode::InvalidArgument,
                  "safecass viewer: a replay is read-only (--allow-write and --token-file are for a running system)");
    }
    if (args.system.empty()) {
      return fail(ErrorCode::InvalidArgument,
                  "safecass viewer: --replay needs --system SYSTEM, the system file the log is fed through");
    }
    viewer::ReplaySourceOptions options;
    options.system = args.system;
    options.input = args.replay;
    options.format = args.format;
    options.mapping = args.mapping;
    options.speed = args.speed;
    auto source = viewer::ReplaySource::open(options);
    if (!source) return tl::unexpected(source.error());
    return std::unique_ptr<viewer::ViewSource>(std::move(*source));
  }
  if (!args.format.empty() || !args.mapping.empty()) {
    return fail(ErrorCode::InvalidArgument, "safecass viewer: --format and --mapping describe a --replay log");
  }
  if (args.ice.empty()) {
    if (!args.token_files.empty()) {
      return fail(ErrorCode::InvalidArgument, "safecass viewer: --token-file is for a live system (--ice)");
    }
    viewer::InProcessOptions source_options;
    source_options.system = args.system;
    source_options.scenario = args.scenario;
    source_options.speed = args.speed;
    auto source = viewer::InProcessSource::open(source_options);
    if (!source) return tl::unexpected(source.error());
    return std::unique_ptr<viewer::ViewSource>(std::move(*source));
  }
#ifdef SAFECASS_WITH_ICE
  if (!args.scenario.empty() || args.speed_given) {
    return fail(ErrorCode::InvalidArgument,
                "safecass viewer: --scenario and --speed drive an in-process system, not a live one (--ice)");
  }
  if (args.system.empty())
    return fail(ErrorCode::InvalidArgument, "safecass viewer: --ice needs --system SYSTEM (its coordinators)");
  viewer::MiddlewareOptions options;
  options.ice = args.ice;
  options.keys_dir = args.keys;
  options.tls_dir = args.tls;
  options.system = args.system;
  for (const std::string& t : args.read_token_files) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == t.size()) {
      return fail(ErrorCode::InvalidArgument,
                  "safecass viewer: --read-token-file '" + t + "': write it COORDINATOR=FILE");
    }
    options.read_token_files[t.substr(0, eq)] = t.substr(eq + 1);
  }
  options.allow_write = args.allow_write;
  for (const std::string& t : args.token_files) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == t.size()) {
      return fail(ErrorCode::InvalidArgument, "safecass viewer: --token-file '" + t + "': write it COORDINATOR=FILE");
    }
    if (!options.token_files.emplace(t.substr(0, eq), t.substr(eq + 1)).second) {
      return fail(ErrorCode::InvalidArgument,
                  "safecass viewer: --token-file: coordinator '" + t.substr(0, eq) + "' given twice");
    }
  }
  auto source = viewer::MiddlewareSource::open(options);
  if (!source) return fail(source.error().code, "safecass viewer: " + source.error().message);
  return std::unique_ptr<viewer::ViewSource>(std::move(*source));
#else
  return fail(ErrorCode::InvalidArgument,
              "safecass viewer: --ice: this safecass was built without the middleware (ZeroC Ice)");
#endif
}

/// Starts the desktop's browser on `url` without waiting for it (and without a shell).
void open_browser(const std::string& url) {
  pid_t pid = 0;
  const char* argv[] = {"xdg-open", url.c_str(), nullptr};
  if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, const_cast<char* const*>(argv), environ) != 0) {
    std::fprintf(stderr, "safecass viewer: cannot start xdg-open: open %s yourself\n", url.c_str());
    return;
  }
  // xdg-open hands the URL to the browser and exits; reap it so it does not linger.
  int status = 0;
  waitpid(pid, &status, 0);
}

int run_viewer(const ViewerArgs& args) {
  if (args.port < 0 || args.port > 65535) {
    std::fprintf(stderr, "safecass viewer: --port must be 0 to 65535 (0: pick a free port)\n");
    return 2;
  }
  auto source = open_source(args);
  if (!source) {
    std::fprintf(stderr, "%s\n", source.error().message.c_str());
    return 2;
  }

  viewer::ProtocolOptions protocol;
  protocol.allow_write = args.allow_write;
  // The token goes into a private file (mode 0600, middleware/token.hpp), never to stdout: the
  // output of a server ends up in logs. It is removed when the viewer stops.
  std::unique_ptr<middleware::TokenFile> token_file;
  if (args.allow_write) {
    auto file = middleware::TokenFile::create_default("viewer");
    if (!file) {
      std::fprintf(stderr, "safecass viewer: %s\n", file.error().message.c_str());
      return 2;
    }
    token_file = std::move(*file);
    protocol.token = token_file->secret();
  }

  viewer::ServerOptions server_options;
  server_options.bind = args.bind;
  server_options.port = static_cast<std::uint16_t>(args.port);
  server_options.handle_signals = true;
  auto server = viewer::Server::open(**source, protocol, server_options);
  if (!server) {
    std::fprintf(stderr, "safecass viewer: %s\n", server.error().message.c_str());
    return 2;
  }
  const std::string url = (*server)->url();
  const viewer::SystemView v = (*source)->view();
  std::printf("safecass viewer: %s (%s)\n", v.system.c_str(), v.description.c_str());
  for (const viewer::CoordinatorView& co : v.coordinators) {
    if (!co.status.empty())
      std::printf("  coordinator %s: %s (tried again until it answers)\n", co.name.c_str(), co.status.c_str());
  }
  std::printf("  open %s\n", url.c_str());
  if (args.allow_write) {
    std::printf(
        "  write access: the token is in %s (mode 0600): paste it into the page, or open %s#token=<the token>\n",
        token_file->path().c_str(), url.c_str());
  } else if (!args.replay.empty()) {
    std::printf("  read-only: a replay; the page's slider plays, pauses and moves it in time\n");
  } else {
    std::printf("  read-only (start with --allow-write to generate, inject and reset)\n");
  }
  const std::string& bind = args.bind;
  if (bind != "127.0.0.1" && bind != "::1" && bind.rfind("127.", 0) != 0) {
    std::printf("  warning: listening on %s: everyone who can reach this address sees the system\n", bind.c_str());
  }
  std::printf("  Ctrl-C stops it.\n");
  std::fflush(stdout);
  // Without the token: a command line is visible to every local user (ps, /proc/PID/cmdline).
  if (args.open) open_browser(url);

  (*server)->run();
  if (token_file) token_file->remove();
  std::printf("safecass viewer: stopped\n");
  return 0;
}

}  // namespace

void add_viewer_command(CLI::App& app, int& code) {
  auto args = std::make_shared<ViewerArgs>();
  auto* cmd =
      app.add_subcommand("viewer", "Serve a live web view of a system: states, causes and the last transitions");
  cmd->footer(
      "The system runs in this process in real time (its simulated clock follows the wall clock times --speed), "
      "driven by the scenario if one is given; when the scenario ends the system stays up. The page shows every "
      "coordinator, component and state machine coloured Normal/Warning/Error; click a state for its cause. "
      "Read-only unless --allow-write: then every write request must carry the token written to a private file "
      "whose path is printed at start. With --ice the system is not run here: the viewer follows the live "
      "coordinators of the --system file through IceStorm (one that does not answer is shown unreachable and "
      "tried again), and each write goes to the coordinator owning its target with that coordinator's token. With "
      "--replay LOG the system is fed the recorded inputs in simulated time, as `safecass replay` feeds them, and "
      "the page moves through the recording with a time slider (--speed: its playing speed).");
  cmd->add_option("--system", args->system, "system file (default: the scenario's \"system\")");
  cmd->add_option("--scenario,-s", args->scenario, "scenario file: timed samples, events, injections and resets");
  cmd->add_option("--port,-p", args->port, "TCP port (0: pick a free one)")->capture_default_str();
  cmd->add_option("--bind", args->bind, "address to listen on")->capture_default_str();
  cmd->add_option("--speed", args->speed,
                  "simulated seconds per wall-clock second (0 < X <= 1000); with --replay, the playing speed")
      ->capture_default_str()
      ->each([args](const std::string&) { args->speed_given = true; });
  cmd->add_option("--keys", args->keys,
                  "with --ice: the system's bus keys (only the keyring is read; default $SAFECASS_KEYS)");
  cmd->add_option("--tls", args->tls,
                  "with --ice: the certificates' directory (ca.pem, reader.pem/.key) when not the key directory, which "
                  "is used when it holds ca.pem");
  cmd->add_option("--read-token-file", args->read_token_files,
                  "with --ice: COORDINATOR=FILE, a coordinator's read credential (repeatable)");
  cmd->add_option(
      "--ice", args->ice,
      "IceStorm HOST:PORT (locator:HOST:PORT: replicated): watch the live system whose coordinators run as processes "
      "(`safecass run SYSTEM --coordinator NAME --ice ...`); needs --system");
  cmd->add_option("--token-file", args->token_files,
                  "COORDINATOR=FILE (repeatable, with --ice): the token file of a coordinator started with "
                  "--allow-write; writes to it carry its token");
  cmd->add_option("--replay", args->replay,
                  "a recorded input log (SAFECASS recording, CSV or ROS 1 bag) fed through --system in simulated "
                  "time; the page gets a time slider (play, pause, speed, seek, next transition); read-only");
  cmd->add_option("--format", args->format,
                  "with --replay: recording, csv, bag or rosbag2 (default: from the file's first bytes)")
      ->check(CLI::IsMember({"recording", "csv", "bag", "rosbag2"}));
  cmd->add_option("--mapping", args->mapping, "with --replay of a ROS bag: the ROS extension's mapping file");
  cmd->add_flag("--allow-write", args->allow_write, "accept generate, inject and reset requests that carry the token");
  cmd->add_flag("--open", args->open, "open the page in the desktop's browser (xdg-open)");
  cmd->callback([args, &code] { code = run_viewer(*args); });
}

}  // namespace safecass::tools
