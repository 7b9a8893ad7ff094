#pragma once
/// @file scenario.hpp
/// Scenarios (DESIGN §6): timed signal samples, ramps, events, injections, resets and expected
/// states that drive a system in simulated time.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "safecass/spec/diagnostics.hpp"

namespace safecass::spec {

struct ScenarioStep {
  enum class Kind { Sample, Ramp, Generate, Inject, Reset, Expect, ExpectOutstanding, ExpectCause };
  Kind kind = Kind::Sample;
  double at = 0.0;          ///< seconds
  std::size_t index = 0;    ///< position in the file's step list (file order breaks ties)
  Position where;           ///< of the step's action value
  std::string pointer;      ///< JSON pointer of the step's action value

  /// Sample: signal → values (one value for a scalar).
  std::vector<std::pair<std::string, std::vector<double>>> samples;
  /// Ramp: signal, from, to, until (seconds).
  std::string signal;
  double from = 0.0;
  double to = 0.0;
  double until = 0.0;
  /// Generate: event and target address. Reset: target and reason.
  std::string event;
  std::string target;
  std::string reason;
  /// Inject: a filter (shallow: its private input; deep: its first input signal) or, for deep
  /// injections, a signal; the samples to inject.
  std::string filter;
  bool deep = false;
  std::vector<std::vector<double>> values;
  /// Expect*: address → expected state / outstanding event / root cause ("C.s_A:EVENT").
  std::vector<std::pair<std::string, std::string>> expectations;
};

struct Scenario {
  std::string path;        ///< the scenario file as given
  std::string system;      ///< the system file, resolved relative to the scenario file
  double period = 0.001;   ///< seconds per tick
  double duration = 0.0;   ///< seconds
  std::vector<ScenarioStep> steps;  ///< sorted by time, file order within a time
};

struct ScenarioLoad {
  std::optional<Scenario> scenario;
  std::vector<Diagnostic> diagnostics;  ///< every problem found, with line:col
};

/// Reads and checks a scenario file (format only; names are checked against the system when it runs).
ScenarioLoad load_scenario(const std::string& path);

/// read_regular_file() (file.hpp) with its default limit, for callers that want a flag and a
/// message: false with the message ("cannot read file 'PATH': why") when it cannot be read.
bool read_file(const std::string& path, std::string& out, std::string& error);

}  // namespace safecass::spec
