// The `safecass` command: one entry point, one subcommand per tool.
// Exit codes: 0 ok, 1 a check failed, 2 usage or I/O error.

#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"SAFECASS: safety architecture for component-based robot systems"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "safecass 0.1.0");

  auto* demo = app.add_subcommand("demo", "Run the built-in demonstration of the core model");
  demo->callback([] { std::exit(safecass::tools::run_demo()); });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  return 0;
}
