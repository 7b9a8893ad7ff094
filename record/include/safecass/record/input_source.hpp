#pragma once
/// @file input_source.hpp
/// A log of a system's inputs read back as a stream (what `safecass replay` feeds through a
/// system): a SAFECASS input recording (input_log.hpp), a CSV file, a ROS 1 bag or a ROS 2 bag
/// (safecass/replay/). Each is read as a stream of items in time order; memory does not grow with
/// the file's data (a ROS 1 bag holds the index of its mapped topics' messages, 24 bytes each).
///
/// bind() resolves the names the log uses against the replayed system first; then next() yields
/// samples (already bound to their Signal) and actions. A problem in the log ends the stream with
/// InputItem::Kind::Error and error() = "file:line[:col]: reason" (a recording: "file: record N
/// (byte B): reason"; a bag: "file: message N: reason"). C++17, so that the ROS 1 extension can
/// implement it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/record/input_log.hpp"

namespace safecass {

struct InputItem {
  enum class Kind : std::uint8_t { Sample, Action, End, Error };
  Kind kind = Kind::End;
  Time time{};
  Signal* signal = nullptr;                    ///< Sample: the bound signal
  const double* values = nullptr;              ///< Sample: signal->size() values, valid until the next next()
  const introspect::Action* action = nullptr;  ///< Action
};

class InputSource {
public:
  virtual ~InputSource() = default;
  /// Resolves the log's signal names against `monitor` (input signals only: a filter's output is
  /// computed by the replayed system, never fed). Errors: Parse, with where and why.
  [[nodiscard]] virtual Expected<void> bind(Monitor& monitor) = 0;
  virtual InputItem next() = 0;
  /// After InputItem::Kind::Error.
  virtual const std::string& error() const = 0;
  /// The recorded run's tick period and first tick, when the log says.
  virtual std::optional<Time> period() const { return std::nullopt; }
  virtual std::optional<Time> start() const { return std::nullopt; }
  /// After InputItem::Kind::End: the recorded run's last tick, when the log says.
  virtual std::optional<Time> end() const { return std::nullopt; }
  /// Things a person should know that are not errors (a torn last record, samples the recorder
  /// lost), after the stream ended.
  virtual std::vector<std::string> notes() const { return {}; }
  /// Samples read so far.
  virtual std::uint64_t samples() const = 0;
  /// Where the last item was read: "file:line" (CSV), "file: record N" (a recording),
  /// "file: message N" (a bag).
  virtual std::string where() const = 0;
};

/// The signals a log may feed: every signal of `monitor` that no filter writes.
std::vector<std::string> input_signal_names(const Monitor& monitor);
/// Resolves `name` to an input signal of `monitor`, or says why not ("no signal 'X' in the
/// system; did you mean 'Y'?", "signal 'X' is computed by filter F; ...").
[[nodiscard]] Expected<Signal*> find_input_signal(Monitor& monitor, const std::string& name);

}  // namespace safecass
