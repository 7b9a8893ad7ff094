#pragma once
// `safecass viewer`: the live web view of a system (DESIGN §6), served by tools/viewer.

namespace CLI {
class App;
}

namespace safecass::tools {

/// Adds the `viewer` subcommand to the `safecass` command; its callback stores the exit code
/// (0 after a clean stop, 2 when the system cannot be loaded or the port cannot be bound).
void add_viewer_command(CLI::App& app, int& code);

}  // namespace safecass::tools
