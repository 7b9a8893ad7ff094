#pragma once
/// @file command.hpp
/// Running the external tools the analyses call (SPIN and the C compiler for `verify`, SCRAM for
/// `analyze`): a shell command's output and status, and a working directory for their files.

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "safecass/core/expected.hpp"

namespace safecass::verify {

/// A command's output (stdout and stderr together) and exit status.
struct CommandResult {
  int status = -1;
  std::string output;
};

/// Runs `command` with /bin/sh in `dir`. Errors: Io (cannot start it).
[[nodiscard]] Expected<CommandResult> run_command(const std::string& dir, const std::string& command);

/// What one of SPIN's random simulations printed, given with its seed: its "@ ..." lines (the
/// callee may take them); returning false stops the runs (verify's and the bus model's simulations).
using SimulationRun = std::function<bool(unsigned seed, std::vector<std::string>& lines)>;

/// Single-quotes a word for /bin/sh.
std::string shell_quote(const std::string& word);

/// A working directory for an external tool's files: `given` (created if missing, kept), or when
/// `given` is empty a fresh private one (mkdtemp of `prefix`XXXXXX under $TMPDIR or /tmp), removed
/// by the destructor.
class WorkDir {
public:
  [[nodiscard]] static Expected<WorkDir> create(const std::string& given,
                                                const std::string& prefix = "safecass-verify-");
  WorkDir(WorkDir&& other) noexcept;
  WorkDir& operator=(WorkDir&&) = delete;
  WorkDir(const WorkDir&) = delete;
  ~WorkDir();
  const std::string& path() const { return path_; }

private:
  WorkDir(std::string path, bool owned) : path_(std::move(path)), owned_(owned) {}
  std::string path_;
  bool owned_ = false;
};

}  // namespace safecass::verify
