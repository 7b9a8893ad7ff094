#pragma once
// The commands that use the middleware: `safecass run SYSTEM --coordinator NAME [--ice HOST:PORT]`
// (one coordinator of a system, in real time, joined to the others through IceStorm) and
// `safecass supervisor --ice HOST:PORT`.

#include "commands.hpp"

namespace CLI {
class App;
}

namespace safecass::tools {

/// Adds --coordinator, --ice, --duration, --allow-write and --token-file to `safecass run`.
void add_middleware_options(CLI::App& run, RunArgs& args);
/// `safecass run --coordinator`: 0 ok, 1 an expectation failed, 2 invalid input or I/O error.
int run_coordinator(const RunArgs& args);
/// Adds the `supervisor` subcommand; its callback stores the exit code.
void add_supervisor_command(CLI::App& app, int& code);
/// Adds the `keys` subcommand (the bus keys of a system, keys.hpp).
void add_keys_command(CLI::App& app, int& code);

}  // namespace safecass::tools
