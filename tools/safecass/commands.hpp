#pragma once
// Entry points of the safecass subcommands.

#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace safecass::tools {

/// A small system (force sensor → controller → servo) driven in simulated time: shows detection,
/// propagation, explain(), dispatch() and recovery. Returns the process exit code.
int run_demo();

struct RunArgs {
  std::string system;
  std::string scenario;
  bool json = false;
  std::string record;
  std::string record_inputs;    ///< --record-inputs FILE ("-": none; default next to --record)
  std::uint64_t max_bytes = 0;  ///< --max-bytes: rotate the recordings at this size
  // Multi-process runs (middleware_commands.hpp): one coordinator of the system, in real time.
  std::string coordinator;      ///< --coordinator: run only this coordinator's components
  std::string ice;              ///< --ice HOST:PORT: join the system through IceStorm
  double duration = 0.0;        ///< --duration SECONDS (0: the scenario's, or until SIGINT/SIGTERM)
  bool allow_write = false;     ///< --allow-write: serve write operations to holders of the token
  std::string token_file;       ///< --token-file: where to write the token
  std::string read_token_file;  ///< --read-token-file: reads need the credential written there
  std::string keys;             ///< --keys DIR: the system's bus keys (default $SAFECASS_KEYS)
  int lost_after_ms = 0;        ///< --lost-after MS: a silent provider is lost (0: 3 heartbeats)
  bool insecure = false;        ///< --insecure: accept a non-loopback endpoint without encryption
  std::string tls;              ///< --tls DIR: mutual TLS with the system's CA and this coordinator's certificate
  std::string listen;           ///< --listen HOST: the address this process serves on (default 127.0.0.1)
};
/// `safecass run`: 0 passed, 1 an expectation failed, 2 invalid input.
int run_run(const RunArgs& args);

struct TestArgs {
  std::vector<std::string> scenarios;
  std::string junit;
};
/// `safecass test`: 0 all passed, 1 some failed, 2 invalid input.
int run_test(const TestArgs& args);

/// Adds `safecass replay` (replay_command.cpp); its callback stores the exit code in `code`.
void add_replay_command(CLI::App& app, int& code);

/// Adds `safecass analyze` (analyze.cpp, docs/analyze.md): exit 0 no error-severity gap, 1 one
/// exists (with --strict: or a warning), 2 invalid input.
void add_analyze_command(CLI::App& app, int& code);

struct TraceArgs {
  std::string system;
  std::vector<std::string> scenarios;
  std::string html;     ///< --html FILE: the report
  std::string csv;      ///< --csv FILE: one row per hazard × event × filter
  std::string verify;   ///< --verify FILE: the output of `safecass verify --json`
  bool json = false;    ///< the matrix as JSON on stdout instead of text
  bool strict = false;  ///< a gap of warning severity fails too
};
/// Writes `text` to `path` (replacing it); false, with "safecass COMMAND: cannot write 'PATH'" on
/// stderr, when it cannot.
bool write_output(const char* command, const std::string& path, const std::string& text);

/// A report's date: now in UTC, or SOURCE_DATE_EPOCH when set (reproducible builds).
std::string report_date();

/// `safecass trace` (docs/trace.md): 0 no error-severity gap, 1 one exists (with --strict: or a
/// warning), 2 invalid input or a file that cannot be written.
int run_trace(const TraceArgs& args);

}  // namespace safecass::tools
