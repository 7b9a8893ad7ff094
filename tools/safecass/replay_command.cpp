// `safecass replay SYSTEM --input LOG ...` and `safecass replay --diff SYSTEM_B SYSTEM_A --input LOG`.

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "safecass/core/clock.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/replay/replay.hpp"

namespace safecass::tools {

namespace {
struct ReplayArgs {
  std::vector<std::string> systems;
  bool diff = false;
  replay::ReplayOptions options;
  double from = 0, to = 0, period = 0;
  std::uint64_t max_bytes = 0;
};

/// A number of seconds the replay's clock holds (core/clock.hpp, readable_seconds): finite and at
/// most 4e9 in magnitude. CLI11's own ranges let NaN through.
const CLI::Validator kSeconds(
    [](std::string& text) {
      double seconds = 0;
      if (!CLI::detail::lexical_cast(text, seconds) || !readable_seconds(seconds))
        return std::string("must be a number of seconds of at most 4e9 in magnitude, not ") + text;
      return std::string();
    },
    "SECONDS");
}  // namespace

void add_replay_command(CLI::App& app, int& code) {
  auto args = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand(
      "replay", "Feed a recorded or field log (SAFECASS recording, CSV, ROS 1 bag) through a system in simulated time");
  cmd->add_option("SYSTEM", args->systems, "the system file; with --diff: SYSTEM_B SYSTEM_A")->required();
  cmd->add_option("--input,-i", args->options.input, "the log: a SAFECASS input recording, a CSV file or a ROS 1 bag")
      ->required();
  cmd->add_flag(
      "--diff", args->diff,
      "replay through SYSTEM_B and SYSTEM_A and print, per address, where their states differ (exit 1 if they do)");
  cmd->add_flag("--coverage", args->options.coverage,
                "after the replay, print when each hazard was uncovered (`analyze now` at every tick)");
  auto* from = cmd->add_option("--from", args->from, "seconds: start the replay here (inputs before it are not fed)")
                   ->check(kSeconds);
  auto* to = cmd->add_option("--to", args->to, "seconds: end the replay here")->check(kSeconds);
  auto* period =
      cmd->add_option("--period", args->period,
                      "seconds per tick (default: the recording's, else the smallest component period, else 0.001)")
          ->check(kSeconds)
          ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", args->options.json, "one JSON object per line");
  cmd->add_option("--record", args->options.record,
                  "write the replay's history to this file (and its inputs next to it)");
  cmd->add_option("--record-inputs", args->options.record_inputs,
                  "record the replay's inputs to this file (\"-\": do not)");
  cmd->add_option("--max-bytes", args->max_bytes, "rotate the replay's recordings at this many bytes")
      ->check(CLI::Range(std::uint64_t{4096}, std::uint64_t{1} << 62));
  cmd->add_option("--format", args->options.format,
                  "recording, csv, bag (ROS 1) or rosbag2 (ROS 2) (default: from the file's first bytes)")
      ->check(CLI::IsMember({"recording", "csv", "bag", "rosbag2"}));
  cmd->add_option("--mapping", args->options.mapping,
                  "a ROS 1 or ROS 2 bag: the ROS extensions' mapping file (topics and field paths to signals)");
  cmd->callback([args, from, to, period, &code] {
    replay::ReplayOptions o = args->options;
    if (from->count() != 0) o.from = args->from;
    if (to->count() != 0) o.to = args->to;
    if (period->count() != 0) o.period = args->period;
    o.limits.max_bytes = args->max_bytes;
    if (o.from && o.to && *o.to < *o.from) {
      std::fprintf(stderr, "replay: --to %g is before --from %g\n", *o.to, *o.from);
      code = 2;
      return;
    }
    const FilterRegistry& registry = builtin_filters();
    if (args->diff) {
      if (args->systems.size() != 2) {
        std::fprintf(stderr, "replay --diff: two systems are needed: SYSTEM_B SYSTEM_A\n");
        code = 2;
        return;
      }
      if (!o.record.empty()) {
        std::fprintf(stderr, "replay --diff: --record is for a single replay\n");
        code = 2;
        return;
      }
      o.system = args->systems[1];
      code = replay::run_replay_diff(args->systems[0], o, registry);
      return;
    }
    if (args->systems.size() != 1) {
      std::fprintf(stderr, "replay: one SYSTEM (two only with --diff)\n");
      code = 2;
      return;
    }
    o.system = args->systems[0];
    code = replay::run_replay(o, registry);
  });
}

}  // namespace safecass::tools
