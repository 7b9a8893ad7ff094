#pragma once
/// @file write.hpp
/// The one JSON writer of SAFECASS: one string escaper and an object/array builder. Every tool and
/// module that writes JSON (history lines, console --json, the viewer's messages, diagnostics, the
/// schema) writes it through these functions; nothing concatenates JSON by hand.
///
/// Numbers: `%.9g`-style shortest text for doubles (json_number), null for NaN and infinities
/// (JSON has neither). Seconds: fixed with six decimals (json_seconds), the history-file format.
/// Thread-safety: free functions are pure; a JsonObject/JsonArray is used by one thread.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/clock.hpp"

namespace safecass::json {

/// Appends `text` to `out` as a JSON string (quotes included): `"` `\` and control characters
/// are escaped (\n, \r, \t by name, the others as \u00XX); every other byte is copied.
void append_json_string(std::string& out, std::string_view text);
/// `text` as a JSON string (quotes included).
std::string json_string(std::string_view text);
/// A number (shortest round text, at most 9 significant digits), or null when not finite.
std::string json_number(double v);
/// Seconds with six decimals: "0.301000" (the history-file format of times).
std::string json_seconds(Time t);
/// ["a","b"].
std::string json_string_array(const std::vector<std::string>& items);
/// [1,2.5] (null for non-finite numbers).
std::string json_number_array(const std::vector<double>& items);

/// One JSON object, built member by member:
/// JsonObject().str("a", "x").num("b", 1).text() == {"a":"x","b":1}.
class JsonObject {
public:
  /// A member whose value is already JSON text (an array, an object, a literal).
  JsonObject& raw(std::string_view key, std::string_view json);
  JsonObject& str(std::string_view key, std::string_view value);
  JsonObject& num(std::string_view key, double value) { return raw(key, json_number(value)); }
  JsonObject& integer(std::string_view key, long long value) { return raw(key, std::to_string(value)); }
  JsonObject& boolean(std::string_view key, bool value) { return raw(key, value ? "true" : "false"); }
  JsonObject& seconds(std::string_view key, Time t) { return raw(key, json_seconds(t)); }
  JsonObject& null(std::string_view key) { return raw(key, "null"); }
  /// A string, or null when empty.
  JsonObject& opt(std::string_view key, std::string_view value) { return value.empty() ? null(key) : str(key, value); }
  JsonObject& strings(std::string_view key, const std::vector<std::string>& items) {
    return raw(key, json_string_array(items));
  }
  /// The next member starts a new line (a file that diffs well: one large member a line).
  JsonObject& line_break() {
    break_ = true;
    return *this;
  }
  /// The object's text.
  std::string text() const { return text_ + "}"; }

private:
  void key(std::string_view key);
  std::string text_ = "{";
  bool break_ = false;
};

/// One JSON array of JSON texts: JsonArray().raw("1").raw("\"x\"").text() == [1,"x"].
class JsonArray {
public:
  /// Compact, or each item on a line of its own: [\n1,\n"x"] (golden files that diff well).
  enum class Layout : std::uint8_t { Compact, OnePerLine };
  explicit JsonArray(Layout layout = Layout::Compact) : layout_(layout) {}
  JsonArray& raw(std::string_view json);
  JsonArray& str(std::string_view value);
  bool empty() const noexcept { return text_.size() == 1; }
  std::string text() const { return text_ + "]"; }

private:
  void next();
  std::string text_ = "[";
  Layout layout_ = Layout::Compact;
};

}  // namespace safecass::json
