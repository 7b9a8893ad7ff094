#pragma once
/// @file scenario.hpp
/// Scenarios (DESIGN §6): timed signal samples, ramps, events, injections, resets and expected
/// states that drive a system in simulated time. The file format, for users:
/// docs/scenario-format.md.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "safecass/spec/diagnostics.hpp"

namespace safecass::spec {

/// The values of one sample: a read-only view (one value for a scalar signal).
class SampleValues {
public:
  SampleValues() = default;
  SampleValues(const double* data, std::size_t size) noexcept : data_(data), size_(size) {}
  const double* data() const noexcept { return data_; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const double* begin() const noexcept { return data_; }
  const double* end() const noexcept { return data_ + size_; }
  double operator[](std::size_t i) const noexcept { return data_[i]; }
  std::vector<double> to_vector() const { return std::vector<double>(begin(), end()); }

private:
  const double* data_ = nullptr;
  std::size_t size_ = 0;
};

/// One sample of a `sample` step: a signal ("Component.signal") and its values. Views into the
/// SampleList that holds them.
struct Sample {
  std::string_view signal;
  SampleValues values;
};

/// The samples of one `sample` step, in file order, in one allocation: a large scenario is
/// mostly samples, and a list of strings and vectors per step took about eight times the text's
/// size (docs/spec-format.md, "Memory"). Iterating yields Sample (`for (const auto& [signal,
/// values] : step.samples)`).
class SampleList {
public:
  SampleList() = default;
  explicit SampleList(const std::vector<std::pair<std::string_view, std::vector<double>>>& samples);
  SampleList(std::initializer_list<std::pair<std::string_view, std::vector<double>>> samples);
  SampleList(const SampleList& other);
  SampleList& operator=(const SampleList& other);
  SampleList(SampleList&&) noexcept = default;
  SampleList& operator=(SampleList&&) noexcept = default;
  ~SampleList() = default;

  std::size_t size() const noexcept;
  bool empty() const noexcept { return size() == 0; }

  class const_iterator {
  public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = Sample;
    using difference_type = std::ptrdiff_t;
    using pointer = const Sample*;
    using reference = Sample;
    const_iterator() = default;
    Sample operator*() const noexcept;
    const_iterator& operator++() noexcept;
    const_iterator operator++(int) noexcept {
      const_iterator old = *this;
      ++*this;
      return old;
    }
    bool operator==(const const_iterator& o) const noexcept { return left_ == o.left_; }
    bool operator!=(const const_iterator& o) const noexcept { return left_ != o.left_; }

  private:
    friend class SampleList;
    const_iterator(const double* at, std::size_t left) noexcept : at_(at), left_(left) {}
    const double* at_ = nullptr;
    std::size_t left_ = 0;  ///< samples from this one to the end
  };
  const_iterator begin() const noexcept;
  const_iterator end() const noexcept { return const_iterator(nullptr, 0); }

private:
  /// Words (doubles) of the block: [(sample count, block words)][for each sample: (name length,
  /// value count), the name padded to whole words, the values]. Counts are two 32-bit numbers in
  /// one word (stored with memcpy); values are doubles.
  std::unique_ptr<double[]> block_;
};

/// What a step other than `sample` does: a ramp, generate, inject, reset or expectation. Kept
/// apart from ScenarioStep, which a large scenario has millions of (almost all samples).
struct StepAction {
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
  /// injections, a signal (`signal` above); the samples to inject.
  std::string filter;
  bool deep = false;
  std::vector<std::vector<double>> values;
  /// Expect*: address → expected state / outstanding event / root cause ("C.s_A:EVENT").
  std::vector<std::pair<std::string, std::string>> expectations;
};

struct ScenarioStep {
  enum class Kind : std::uint8_t { Sample, Ramp, Generate, Inject, Reset, Expect, ExpectOutstanding, ExpectCause };
  double at = 0.0;  ///< seconds
  /// Sample: signal → values, in file order.
  SampleList samples;
  /// Every other kind: what it does (never null for those; null for a `sample` step).
  std::shared_ptr<const StepAction> action;
  std::uint32_t index = 0;  ///< position in the file's step list (file order breaks ties)
  int line = 0;             ///< of the step's action value in the scenario file (Scenario::where)
  int column = 0;
  Kind kind = Kind::Sample;

  /// The JSON pointer of the step's action value: "/steps/INDEX/KEY" ("/steps/2/expect").
  std::string pointer() const;
};

/// The key of a step kind in the file ("sample", "expect_outstanding", ...).
std::string_view step_key(ScenarioStep::Kind kind) noexcept;

/// One object of a scenario file and the keys load_scenario() accepts in it.
struct ScenarioKeySet {
  /// "scenario" (the top level), "step" (a member of "steps"), or the key of a step kind whose
  /// value has fixed keys ("ramp", "generate", "inject", "reset").
  std::string_view object;
  std::vector<std::string_view> keys;  ///< in the order of the reader's messages
};

/// Every key of the scenario format, per object: the top level, a step ("at" and the key of every
/// step kind, in the order of ScenarioStep::Kind) and the value of each step kind with fixed
/// keys. The values of `sample` and of the expectations are objects of names (signals,
/// addresses), not of keys: they have no entry. load_scenario() reports every key that is not
/// here, and docs/scenario-format.md is tested against this table, so the three agree.
const std::vector<ScenarioKeySet>& scenario_keys();

struct Scenario {
  std::string path;       ///< the scenario file as given
  std::string system;     ///< the system file, resolved relative to the scenario file
  double period = 0.001;  ///< seconds per tick
  double duration = 0.0;  ///< seconds
  /// Sorted by time, file order within a time. A deque: a scenario of millions of steps grows
  /// without reallocating (and copying) them all.
  std::deque<ScenarioStep> steps;

  /// Where a step is: this file, the step's line and column.
  Position where(const ScenarioStep& step) const { return Position{path, step.line, step.column}; }
};

struct ScenarioLoad {
  std::optional<Scenario> scenario;     ///< present when there is no diagnostic
  std::vector<Diagnostic> diagnostics;  ///< every problem found, with line:col
  /// With diagnostics (and no syntax error): what could be read, the steps without a problem,
  /// so that their names can still be checked against the system in the same pass
  /// (runner::check_scenario): one run reports every problem of the file.
  std::optional<Scenario> partial;
};

/// Reads and checks a scenario file (format only; names are checked against the system when it
/// runs, or all at once by runner::check_scenario). An expectation after the duration is an
/// error: it would never be checked.
ScenarioLoad load_scenario(const std::string& path);
/// The same for a scenario's bytes already read: `path` names it in diagnostics and is what
/// "system" is relative to (the fuzzer, tools that hold the text). Consumes `text`.
ScenarioLoad load_scenario_text(std::string text, const std::string& path);

/// read_regular_file() (file.hpp) with its default limit, for callers that want a flag and a
/// message: false with the message ("cannot read file 'PATH': why") when it cannot be read.
bool read_file(const std::string& path, std::string& out, std::string& error);

}  // namespace safecass::spec
