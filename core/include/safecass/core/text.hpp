#pragma once
/// @file text.hpp
/// The one policy for numbers and times in text, used by every module and tool (explanations,
/// the read model's formatter, the JSON writer, filter and ROS messages, trace and replay):
/// - a number: at most nine significant digits, "nan", "inf" and "-inf" by name ("30", "1.5",
///   "0.333333333");
/// - a time: seconds with six decimals, the history file's ("0.301000").
/// A live system's wall-clock time (ISO 8601) is the read model's (introspect/format.hpp); a
/// specification's diagnostics quote a number exactly as it reads back (spec's own text helpers).

#include <string>

#include "safecass/core/clock.hpp"

namespace safecass {

/// At most nine significant digits: "30", "1.5", "0.333333333", "1e+300"; "nan", "inf", "-inf".
std::string number_text(double v);
/// Seconds with six decimals: "0.301000", "12.000000".
std::string seconds_text(Time t);

}  // namespace safecass
