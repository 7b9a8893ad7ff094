#pragma once
// `safecass console`: read and write the Generic Component Model of a system (DESIGN §6).
//
// The console is split so that its commands can be tested without a terminal:
// - Console parses and executes one command line and returns the output text and whether the
//   command succeeded. It never prints and never throws for a bad command: a wrong command is a
//   usage line and changes nothing. The parsing, completion, usage lines and `help` are shared
//   (console_shell.hpp); a backend runs the commands: an in-process system in simulated time
//   (Console::open), or a live coordinator process reached through the middleware
//   (console_remote.hpp, built with SAFECASS_WITH_ICE).
// - run_console() does the I/O: -c commands, a script, stdin, or an interactive terminal with line
//   editing, history and TAB completion (libedit).
//
// Write operations (filter inject/dinject/dinload, event generate/broadcast, reset) are refused
// unless the console was opened with write access. In-process there is no token; a remote
// coordinator also wants its token (--token-file) and refuses writes without it.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"

namespace CLI {
class App;
}

namespace safecass::tools {

class Backend;

struct ConsoleArgs {
  std::string system;           ///< system file (default: the scenario's "system")
  std::string scenario;         ///< optional: its steps are applied as simulated time advances
  std::string ice;              ///< remote mode: IceStorm at HOST:PORT (instead of system/scenario)
  std::string coordinator;      ///< remote mode: the coordinator's name
  std::string token_file;       ///< remote mode: the coordinator's token file (for writes)
  std::string read_token_file;  ///< remote mode: the coordinator's read credential file
  int timeout_ms = 2000;        ///< remote mode: how long to wait for the heartbeat and each answer
  std::string keys;             ///< remote mode: the system's bus keys (default $SAFECASS_KEYS)
  bool insecure = false;        ///< remote mode: accept a coordinator not on this host (unencrypted)
  std::string tls;              ///< remote mode: mutual TLS (DIR with ca.pem, console.pem/.key)
  std::string commands;         ///< -c: commands separated by ';'
  std::string script;           ///< --script: one command per line ('#' starts a comment)
  bool json = false;            ///< one JSON object per output line
  bool allow_write = false;     ///< accept write operations
};

/// What one command line produced.
struct ConsoleReply {
  std::string out;    ///< result lines, each ending in '\n' (JSON objects with --json)
  std::string err;    ///< one line when the command failed: what went wrong and the usage
  bool ok = true;     ///< false: unknown command, wrong arguments, refused or failed write
  bool quit = false;  ///< `quit` was entered
};

struct ConsoleOptions {
  bool json = false;
  bool allow_write = false;
};

/// The commands that read and write one system, parsed and printed the same way whatever runs
/// them.
///
/// Lifecycle: open() loads the system (and scenario), builds it and processes the tick at t = 0
/// (simulated time then only moves with `watch`); or a backend made elsewhere (a live coordinator:
/// console_remote.hpp) is handed to the constructor. Then execute() any number of times from one
/// thread.
class Console {
public:
  /// A console whose commands `backend` runs.
  Console(std::unique_ptr<Backend> backend, ConsoleOptions options);

  /// Loads and builds the system. `system` may be empty when `scenario` names its system.
  /// Errors: Io/Parse/InvalidArgument with every diagnostic of the system or scenario, one per line.
  [[nodiscard]] static Expected<std::unique_ptr<Console>> open(const std::string& system, const std::string& scenario,
                                                               ConsoleOptions options);
  ~Console();
  Console(const Console&) = delete;
  Console& operator=(const Console&) = delete;

  /// Parses and runs one command. Empty and comment ('#') lines do nothing and succeed.
  ConsoleReply execute(std::string_view line);

  /// Completion candidates for the word `word` being typed after `before` (the line up to the
  /// start of that word): command words, then the names the command takes (components, machine
  /// addresses, events, filters, signals). Sorted, each starting with `word`.
  std::vector<std::string> complete(std::string_view before, std::string_view word) const;
  /// Whether the word after `before` is a file name (so a terminal may complete file names).
  bool completes_file(std::string_view before) const;

  /// One line describing the system, the simulated time (or the coordinator) and the write access.
  std::string banner() const;

private:
  ConsoleReply failure(std::string_view command, const std::string& message, std::string_view usage) const;
  std::string help(const std::vector<std::string>& args, ConsoleReply& reply) const;

  std::unique_ptr<Backend> backend_;
  ConsoleOptions options_;
};

/// The commands of `-c TEXT`: TEXT split at each ';' and line end ("a; b\nc" -> {"a", " b", "c"}).
[[nodiscard]] std::vector<std::string> split_commands(const std::string& text);

/// Runs the console; returns the exit code: 0, or 2 when the system cannot be loaded (or the
/// coordinator cannot be reached) or (with -c, --script or a non-terminal stdin) when any
/// command failed.
int run_console(const ConsoleArgs& args);

/// Adds the `console` subcommand to the `safecass` command; its callback stores the exit code.
void add_console_command(CLI::App& app, int& code);

}  // namespace safecass::tools
