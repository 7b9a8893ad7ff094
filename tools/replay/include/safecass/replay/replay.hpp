#pragma once
/// @file replay.hpp
/// `safecass replay`: recorded or field data fed through a system in simulated time
/// (docs/tools.md, "Replay").
///
/// The log is read twice, streaming both times: a first pass checks all of it (names, sizes,
/// times, numbers, actions) so that bad input is refused with where and why before anything runs
/// or is written; the second feeds it. At each tick of the replay's period, the samples and actions
/// whose time has come are applied in the log's order (a sample keeps its own time), then the
/// filters and component loops due run, exactly as `safecass run` does for a scenario; the
/// transitions are printed as `run` prints them. A recording replays through the system that made
/// it to the same transitions, byte for byte.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "safecass/filters/registry.hpp"
#include "safecass/record/file_limits.hpp"
#include "safecass/runner/scenario_runner.hpp"

namespace safecass::replay {

struct ReplayOptions {
  std::string system;          ///< the system file replayed (with --diff: SYSTEM_A, the reference)
  std::string input;           ///< the log
  std::string format;          ///< "recording", "csv", "bag", "rosbag2"; empty: from the file's first bytes
  std::string mapping;         ///< a bag: the ROS extension's mapping file
  std::optional<double> from;  ///< seconds: inputs before are not fed; the replay starts there
  std::optional<double> to;    ///< seconds: inputs after are not fed; the replay ends there
  std::optional<double>
      period;  ///< seconds per tick (default: the recording's, else the smallest component period, else 1 ms)
  bool json = false;
  /// After the replay, when each hazard was uncovered (`analyze now` judged at every tick:
  /// docs/analyze.md, "At run time").
  bool coverage = false;
  std::string record;         ///< the replay's own history (and inputs next to it)
  std::string record_inputs;  ///< the replay's own inputs recording ("-": none)
  FileLimits limits;
  std::FILE* out = stdout;
  std::FILE* err = stderr;
};

/// Replays `options.input` through `options.system`. Returns 0, or 2 for bad input (said on err
/// with where and why; nothing ran) or an incomplete history of the replay.
int run_replay(const ReplayOptions& options, const FilterRegistry& registry);

/// Replays the same log through `system_b` and `options.system` (A) in lockstep and prints, per
/// address, the intervals where their states differ with the first cause of each. Returns 0 when
/// they never differ, 1 when they do, 2 for bad input.
int run_replay_diff(const std::string& system_b, const ReplayOptions& options, const FilterRegistry& registry);

/// A replay driven step by step, for interactive tools (`safecass viewer --replay`): the system
/// is opened and the whole log checked exactly as run_replay() does (same errors, nothing runs on
/// bad input), then the inputs are fed tick by tick only as far as asked. Nothing is printed or
/// recorded; tools follow the runner's coordinator. Going back in time means opening a new
/// session (a coordinator cannot run backwards).
///
/// Lifecycle: open() (the first tick not processed yet) → advance_to() any number of times, each
/// target at or after the last → destroyed. Not thread-safe: one thread drives it.
class ReplaySession {
public:
  /// `registry` must outlive the session; options.json/record/out are ignored. Errors: Parse,
  /// with every line run_replay() prints for the same bad input ("file:line: reason"), one per
  /// line.
  [[nodiscard]] static Expected<std::unique_ptr<ReplaySession>> open(const ReplayOptions& options,
                                                                     const FilterRegistry& registry);
  ~ReplaySession();
  ReplaySession(const ReplaySession&) = delete;
  ReplaySession& operator=(const ReplaySession&) = delete;

  runner::ScenarioRunner& runner() noexcept;
  const runner::ScenarioRunner& runner() const noexcept;
  /// The first and the last tick of the replay (run_replay() runs exactly these), and the tick.
  Time start() const noexcept;
  Time end() const noexcept;
  Time period() const noexcept;
  /// The last tick processed; before the first, start() - period().
  Time now() const noexcept;
  /// Processes every tick up to and including min(t, end()), feeding the inputs due.
  void advance_to(Time t);
  /// Samples and actions fed so far.
  std::uint64_t samples() const noexcept;
  std::uint64_t actions() const noexcept;
  /// The log's notes (a torn last record, samples the recorder lost): run_replay()'s "note:" lines.
  std::vector<std::string> notes() const;

private:
  struct Impl;
  explicit ReplaySession(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::replay
