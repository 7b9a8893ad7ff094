#include "spin.hpp"

#include <sys/wait.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace safecass::verify {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& word) {
  std::string out = "'";
  for (char c : word) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

[[nodiscard]] Expected<CommandResult> run_command(const std::string& dir, const std::string& command) {
  const std::string line = "cd " + shell_quote(dir) + " && { " + command + "; } 2>&1";
  FILE* pipe = ::popen(line.c_str(), "r");
  if (pipe == nullptr) return fail(ErrorCode::Io, "cannot run '" + command + "'");
  CommandResult r;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

Expected<WorkDir> WorkDir::create(const std::string& given, const std::string& prefix) {
  std::error_code ec;
  if (!given.empty()) {
    fs::create_directories(given, ec);
    if (ec) return fail(ErrorCode::Io, "cannot create directory '" + given + "': " + ec.message());
    return WorkDir(given, false);
  }
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/" + prefix + "XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr)
    return fail(ErrorCode::Io, "cannot create a temporary directory in " + pattern);
  return WorkDir(pattern, true);
}

WorkDir::WorkDir(WorkDir&& other) noexcept : path_(std::move(other.path_)), owned_(other.owned_) {
  other.owned_ = false;
}

WorkDir::~WorkDir() {
  if (!owned_) return;
  std::error_code ec;
  fs::remove_all(path_, ec);
}

[[nodiscard]] Expected<std::string> spin_version(const std::string& spin) {
  auto r = run_command("/", shell_quote(spin) + " -V");
  if (!r || r->status != 0 || r->output.find("Spin Version") == std::string::npos) {
    return fail(ErrorCode::Io,
                "cannot run SPIN ('" + spin + " -V'): install the Debian package 'spin' (scripts/install-deps.sh)");
  }
  std::string v = r->output;
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  return v;
}

[[nodiscard]] Expected<void> compiler_check(const std::string& cc) {
  auto r = run_command("/", shell_quote(cc) + " --version");
  if (!r || r->status != 0) {
    return fail(ErrorCode::Io,
                "cannot run the C compiler '" + cc + "' that builds SPIN's verifiers: install build-essential");
  }
  return {};
}

namespace {

std::uint64_t number_before(const std::string& text, const std::string& marker) {
  const auto at = text.find(marker);
  if (at == std::string::npos) return 0;
  std::size_t start = text.rfind('\n', at);
  start = start == std::string::npos ? 0 : start + 1;
  return std::strtoull(text.c_str() + start, nullptr, 10);
}

double double_before(const std::string& text, const std::string& marker) {
  const auto at = text.find(marker);
  if (at == std::string::npos) return 0.0;
  std::size_t start = text.rfind('\n', at);
  start = start == std::string::npos ? 0 : start + 1;
  return std::strtod(text.c_str() + start, nullptr);
}

/// The "@ ..." lines of SPIN's output (trail replay or simulation), with the cycle marker.
std::vector<std::string> marked_lines(const std::string& output, bool* cycle, std::size_t* cycle_start) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < output.size()) {
    std::size_t end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    std::string line = output.substr(start, end - start);
    start = end + 1;
    if (line.find("START OF CYCLE") != std::string::npos && cycle != nullptr) {
      *cycle = true;
      *cycle_start = out.size();
      continue;
    }
    const auto at = line.find("@ ");
    if (at == std::string::npos) continue;
    // SPIN indents a process's output; nothing else precedes the marker.
    if (line.find_first_not_of(" \t") != at) continue;
    out.push_back(line.substr(at + 2));
  }
  return out;
}

bool write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  return static_cast<bool>(f);
}

}  // namespace

[[nodiscard]] Expected<std::string> compile(const std::string& dir, const std::string& name, const std::string& model,
                                            const PanOptions& options) {
  const std::string pml = name + ".pml";
  if (!write_file(dir + "/" + pml, model)) return fail(ErrorCode::Io, "cannot write '" + dir + "/" + pml + "'");
  auto gen = run_command(dir, shell_quote(options.spin) + " -a " + shell_quote(pml));
  if (!gen) return tl::unexpected(gen.error());
  if (gen->status != 0) return fail(ErrorCode::Io, "SPIN rejected the generated model " + pml + ":\n" + gen->output);
  // Safety: breadth-first (shortest trail), no cycle detection. LTL: depth-first with cycles.
  // COLLAPSE compresses each state; MEMLIM stops the search at the bound instead of swapping.
  // The verifier is small and runs briefly: no optimisation, the compilation is what costs.
  std::string flags = std::string(options.optimise ? "-O1" : "-O0") +
                      " -w -DMEMLIM=" + std::to_string(options.memory_mb) + " -DCOLLAPSE -DVECTORSZ=4096";
  if (!options.ltl) flags += options.shortest ? " -DSAFETY -DBFS" : " -DSAFETY";
  const std::string binary = "pan_" + name;
  auto cc = run_command(dir, shell_quote(options.cc) + " " + flags + " -o " + shell_quote(binary) + " pan.c");
  if (!cc) return tl::unexpected(cc.error());
  if (cc->status != 0)
    return fail(ErrorCode::Io, "the C compiler failed on SPIN's verifier for " + pml + ":\n" + cc->output);
  return binary;
}

[[nodiscard]] Expected<PanResult> check_claim(const std::string& dir, const std::string& name,
                                              const std::string& binary, const std::string& claim,
                                              const PanOptions& options) {
  std::error_code ec;
  const std::string trail = dir + "/" + name + ".pml.trail";
  fs::remove(trail, ec);
  const std::string which = claim.empty() ? std::string() : " -N " + shell_quote(claim);
  std::string run = "./" + shell_quote(binary) + " -n" + which + " -w" + std::to_string(options.hash_bits);
  if (options.ltl) run += " -a -m1000000";
  if (!options.ltl && !options.shortest) run += " -m200000";
  auto pan = run_command(dir, run);
  if (!pan) return tl::unexpected(pan.error());
  PanResult r;
  r.output = pan->output;
  r.states = number_before(r.output, "states, stored");
  r.memory_mb = double_before(r.output, "total actual memory usage");
  const bool limit = r.output.find("MEMLIM") != std::string::npos ||
                     r.output.find("out of memory") != std::string::npos ||
                     r.output.find("max search depth too small") != std::string::npos;
  const bool errors = r.output.find("errors: 0") == std::string::npos && r.output.find("errors:") != std::string::npos;
  if (limit) {
    r.outcome = PanResult::Outcome::MemoryLimit;
  } else if (r.output.find("errors:") == std::string::npos) {
    r.outcome = PanResult::Outcome::Failed;
    return r;
  } else if (errors) {
    r.outcome = PanResult::Outcome::Violated;
  } else {
    r.outcome = PanResult::Outcome::Holds;
  }
  if (r.outcome == PanResult::Outcome::Violated && fs::exists(trail, ec)) {
    auto replay = run_command(dir, "./" + shell_quote(binary) + " -r -S -n" + which);
    if (!replay) return tl::unexpected(replay.error());
    r.trail = marked_lines(replay->output, &r.cycle, &r.cycle_start);
  }
  return r;
}

[[nodiscard]] Expected<void> simulate_model(const std::string& dir, const std::string& model, unsigned first_seed,
                                            unsigned runs, std::size_t steps, const std::string& spin,
                                            const std::string& cc, const SimulationRun& each) {
  const std::string pml = "simulation.pml";
  const std::string pre = "simulation.pre";
  if (!write_file(dir + "/" + pml, model)) return fail(ErrorCode::Io, "cannot write '" + dir + "/" + pml + "'");
  auto cpp = run_command(dir, shell_quote(cc) + " -std=gnu99 -E -x c " + shell_quote(pml) + " > " + shell_quote(pre));
  if (!cpp) return tl::unexpected(cpp.error());
  if (cpp->status != 0) return fail(ErrorCode::Io, "the C preprocessor failed on " + pml + ":\n" + cpp->output);
  for (unsigned seed = first_seed; seed - first_seed < runs; ++seed) {
    auto r = run_command(dir, shell_quote(spin) + " -Pcat -n" + std::to_string(seed) + " -u" + std::to_string(steps) +
                                  " " + shell_quote(pre));
    if (!r) return tl::unexpected(r.error());
    if (r->output.find("error") != std::string::npos && r->output.find("@ ") == std::string::npos) {
      return fail(ErrorCode::Io, "SPIN's simulation failed:\n" + r->output);
    }
    std::vector<std::string> lines = marked_lines(r->output, nullptr, nullptr);
    if (!each(seed, lines)) break;
  }
  return {};
}

}  // namespace safecass::verify
