#pragma once
// Entry points of the safecass subcommands.

namespace safecass::tools {

/// A small system (force sensor → controller → servo) driven in simulated time: shows detection,
/// propagation, explain(), dispatch() and recovery. Returns the process exit code.
int run_demo();

}  // namespace safecass::tools
