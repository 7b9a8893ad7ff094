#pragma once
/// @file params.hpp
/// Filter parameters and the manifest each filter type publishes (DESIGN §3): parameters with
/// type, default, range and a one-line doc; inputs; outputs. The JSON Schema and the console's
/// `filter info` are generated from manifests.

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "safecass/core/expected.hpp"

namespace safecass {

/// A parameter value as written in a specification.
using ParamValue = std::variant<double, bool, std::string, std::vector<std::string>, std::vector<double>>;

/// Parameters of one filter instance, by name.
using Params = std::map<std::string, ParamValue, std::less<>>;

enum class ParamType {
  Number,   ///< double, within [min, max]
  Integer,  ///< whole number, within [min, max]
  Bool,
  String,
  Choice,      ///< one of `choices`
  Signal,      ///< a signal name (`Component.signal`, or bare: a signal of the target component)
  SignalList,  ///< a list of signal names
  Event,       ///< an event name defined in the system
  NumberList,
};

std::string_view to_string(ParamType t) noexcept;

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Number;
  std::string doc;                          ///< one line
  std::optional<ParamValue> default_value;  ///< none: the parameter is required (unless `optional`)
  bool optional = false;                    ///< may be absent, with no default
  double min = -1e300;
  double max = 1e300;
  std::vector<std::string> choices;  ///< for Choice

  static ParamSpec number(std::string name, std::string doc, std::optional<double> def = std::nullopt,
                          double min = -1e300, double max = 1e300);
  static ParamSpec integer(std::string name, std::string doc, std::optional<double> def = std::nullopt,
                           double min = -1e300, double max = 1e300);
  static ParamSpec boolean(std::string name, std::string doc, bool def);
  static ParamSpec choice(std::string name, std::string doc, std::vector<std::string> choices, std::string def);
  static ParamSpec signal(std::string name, std::string doc, bool optional = false);
  static ParamSpec signals(std::string name, std::string doc, bool optional = false);
  static ParamSpec event(std::string name, std::string doc, std::optional<std::string> def = std::nullopt,
                         bool optional = false);
};

/// What a filter type reads, writes and accepts.
struct FilterManifest {
  std::string type;  ///< registry name, e.g. "Threshold"
  std::string doc;   ///< one line
  std::vector<ParamSpec> params;
  std::vector<std::string> inputs;   ///< names of the Signal/SignalList parameters read
  std::vector<std::string> outputs;  ///< names of the Signal parameters written
  bool generates_events = true;
  /// Without its first output parameter, the filter writes the signal named after the filter
  /// (default_output_name()), as the 2016 filters named their outputs themselves.
  bool default_output = false;
  /// Other names of parameters, as the 2016 files wrote them: {alias, parameter}
  /// (ChangeDetection's `event` is its `event_onset`).
  std::vector<std::pair<std::string, std::string>> aliases;

  const ParamSpec* find(std::string_view name) const noexcept;
  /// The parameter `name` stands for: itself, or the parameter it is an alias of.
  std::string_view canonical(std::string_view name) const noexcept;
};

/// The output a filter with `default_output` writes when none is given: a signal of the target
/// component named after the filter (without a leading "component." and with the other dots
/// made '_': filter "JR3.Derivative_2" of JR3 writes "JR3.Derivative_2", filter "rate" "JR3.rate").
std::string default_output_name(std::string_view filter, std::string_view component);

/// Checks `given` against `manifest` and fills in defaults: unknown names, wrong types,
/// out-of-range values and missing required parameters are errors naming the parameter.
/// `filter` names the filter instance in messages.
[[nodiscard]] Expected<Params> check_params(const FilterManifest& manifest, const Params& given,
                                            std::string_view filter);

}  // namespace safecass
