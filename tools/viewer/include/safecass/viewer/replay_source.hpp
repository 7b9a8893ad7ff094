#pragma once
/// @file replay_source.hpp
/// A ViewSource over a recorded input log (`safecass viewer --replay LOG --system S`): the log is
/// fed through the system in simulated time by the replay module (safecass/replay/replay.hpp,
/// the code of `safecass replay`), and the page moves through it with a time slider: play,
/// pause, speed, seek and run on to the next transition. The states shown at a time are the
/// states the replay (and so, for a recording, the recorded run) had at that time.
///
/// Read-only: the recording is what happened, so generate, inject and reset are refused. Going
/// back in time replays the log again from its start (a coordinator cannot run backwards); going
/// forward feeds on. Either way at most a bounded number of ticks is processed per poll, so the
/// server's event loop never stalls; ReplayView::busy says while it catches up.
///
/// Lifecycle: open() checks the log as `safecass replay` does (bad input: file:line and the
/// reason, and no source) and processes the first tick; the replay is paused there. Every member
/// must be called from one thread (see ViewSource).

#include <memory>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

struct ReplaySourceOptions {
  std::string system;   ///< the system file the log is fed through
  std::string input;    ///< the log: a SAFECASS input recording, a CSV file or a ROS 1 bag
  std::string format;   ///< "recording", "csv", "bag", "rosbag2"; empty: from the file's first bytes
  std::string mapping;  ///< a bag: the ROS extension's mapping file
  double speed = 1.0;   ///< recording seconds per wall-clock second while playing, in (0, 1000]
  /// The filter types of the system file (an application's own included); it must outlive the
  /// source. Null: the built-in types.
  const FilterRegistry* registry = nullptr;
};

class ReplaySource final : public ViewSource {
public:
  /// Errors: InvalidArgument (no system, bad speed), Parse with every problem of the files, one
  /// per line ("file:line: reason").
  [[nodiscard]] static Expected<std::unique_ptr<ReplaySource>> open(const ReplaySourceOptions& options);
  ~ReplaySource() override;
  ReplaySource(const ReplaySource&) = delete;
  ReplaySource& operator=(const ReplaySource&) = delete;

  void poll() override;
  SystemView view() const override;
  double now() const override;
  bool running() const override;
  std::vector<std::string> take_records() override;
  introspect::CoverageNow coverage() const override;
  [[nodiscard]] Expected<std::vector<Explanation>> explain(std::string_view address) const override;
  /// Refused: a replay is read-only.
  [[nodiscard]] Expected<std::string> apply(const introspect::Action& action) override;

  std::optional<ReplayView> replay() const override;
  [[nodiscard]] Expected<std::string> control(const ReplayControl& control) override;
  std::uint64_t generation() const override;

  /// Polls until the replay is idle (a seek or a next has arrived): for tests.
  void settle();

private:
  struct Impl;
  explicit ReplaySource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::viewer
