#pragma once
// `safecass verify` (docs/verify.md).

#include <CLI/CLI.hpp>

#include <string>
#include <string_view>

#include "safecass/spec/load.hpp"

#include "safecass/verify/bus.hpp"
#include "safecass/verify/verify.hpp"

namespace safecass::tools {

/// Three decimals: the figures' precision in `verify --json` (megabytes, seconds).
std::string fixed3(double v);

/// Loads `path` into `loaded` for `command` ("verify"): its errors go to stderr, and nullptr
/// comes back when it has any.
const spec::SystemSpec* load_to_verify(const std::string& path, std::string_view command, spec::LoadResult& loaded);

/// Adds the `verify` subcommand; its exit code lands in `code`.
void add_verify_command(CLI::App& app, int& code);

/// Loads `system_path`, verifies it, prints one line per property (or, with `json`, one JSON
/// object per property and a summary). Returns 0 every reaction and invariant holds, 1 one is
/// violated, 2 bad input (errors in the specification, SPIN missing, an unknown property),
/// 3 one could not be decided within the limits.
int run_verify(const std::string& system_path, const verify::Options& options, bool json);

/// `safecass verify --bus`: loads `system_path` and model-checks the bus protocol for its
/// deployment; prints the patterns, each search and each property's verdict, and a violation's
/// trace. With `mutants`, runs every mutant of bus_mutants() instead and prints which property
/// catches it. Exit codes as run_verify (a mutant not caught is exit 1).
int run_verify_bus(const std::string& system_path, const verify::BusOptions& options, bool json, bool mutants);

}  // namespace safecass::tools
