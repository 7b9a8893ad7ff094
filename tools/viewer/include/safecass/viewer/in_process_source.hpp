#pragma once
/// @file in_process_source.hpp
/// A ViewSource that runs a system in this process, driven by an optional scenario, in real time:
/// the simulated clock follows the wall clock times `speed`. When the scenario's duration has
/// passed the system keeps running (ticks with no more steps, as ScenarioRunner::advance_to
/// does), so a person can look at it and, with write access, act on it.
///
/// Lifecycle: open() loads and builds the system and processes the tick at t = 0; then poll()
/// advances time. Every member must be called from one thread (see ViewSource).

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

struct InProcessOptions {
  std::string system;    ///< system file; may be empty when the scenario names one
  std::string scenario;  ///< optional scenario file (its "system" is used unless `system` is set)
  double speed = 1.0;    ///< simulated seconds per wall-clock second, in (0, 1000]
  /// Expectation failures of the scenario are printed here, one line each (null: not printed).
  std::FILE* log = stderr;
  /// The filter types of the system file (an application's own included); it must outlive the
  /// source. Null: the built-in types.
  const FilterRegistry* registry = nullptr;
};

class InProcessSource final : public ViewSource {
public:
  /// Loads and builds the system (and scenario) and processes the tick at t = 0.
  /// Errors: InvalidArgument (no system, bad speed), Io/Parse/InvalidArgument with every
  /// diagnostic of the files, one per line.
  [[nodiscard]] static Expected<std::unique_ptr<InProcessSource>> open(const InProcessOptions& options);
  ~InProcessSource() override;
  InProcessSource(const InProcessSource&) = delete;
  InProcessSource& operator=(const InProcessSource&) = delete;

  void poll() override;
  SystemView view() const override;
  double now() const override;
  bool running() const override;
  std::vector<std::string> take_records() override;
  introspect::CoverageNow coverage() const override;
  [[nodiscard]] Expected<std::vector<Explanation>> explain(std::string_view address) const override;
  [[nodiscard]] Expected<std::string> apply(const introspect::Action& action) override;

  /// Advances the simulated clock to `t` (seconds) at once, ignoring the wall clock; later polls
  /// continue from there. For tests.
  void advance_to(double t);
  /// The coordinator that holds the system (tests read it directly).
  const Coordinator& coordinator() const noexcept;

private:
  struct Impl;
  explicit InProcessSource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::viewer
