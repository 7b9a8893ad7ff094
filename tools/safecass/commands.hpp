#pragma once
// Entry points of the safecass subcommands.

#include <string>
#include <vector>

namespace safecass::tools {

/// A small system (force sensor → controller → servo) driven in simulated time: shows detection,
/// propagation, explain(), dispatch() and recovery. Returns the process exit code.
int run_demo();

struct RunArgs {
  std::string system;
  std::string scenario;
  bool json = false;
  std::string record;
};
/// `safecass run`: 0 passed, 1 an expectation failed, 2 invalid input.
int run_run(const RunArgs& args);

struct TestArgs {
  std::vector<std::string> scenarios;
  std::string junit;
};
/// `safecass test`: 0 all passed, 1 some failed, 2 invalid input.
int run_test(const TestArgs& args);

}  // namespace safecass::tools
