#pragma once
// Small text helpers of the spec module: suggestions, JSON pointers, UTF-8, number formatting.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/json/read.hpp"
#include "safecass/spec/diagnostics.hpp"

namespace safecass::spec {

/// Levenshtein distance, case-insensitive (ASCII).
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidate nearest to `word`, if it is near enough to be a likely typo.
std::optional<std::string> nearest(std::string_view word, const std::vector<std::string>& candidates);

// did_you_mean(): safecass/spec/diagnostics.hpp.

/// `pointer` + "/" + the escaped token (RFC 6901: ~ -> ~0, / -> ~1).
std::string pointer_join(const std::string& pointer, std::string_view token);
std::string pointer_join(const std::string& pointer, std::size_t index);

/// Position of the first byte that is not valid UTF-8 (overlong forms, surrogates and code
/// points above U+10FFFF are invalid), and that byte.
struct Utf8Error {
  json::TextPosition position;
  unsigned char byte = 0;
};
std::optional<Utf8Error> check_utf8(std::string_view text);

/// %g-like, shortest form that reads back the same ("30", "0.001", "1e+300").
std::string number_text(double value);

/// "an object", "a string", ...: a JSON value's type as an error names it (json::a_type_name).
inline std::string a_type(json::JsonValue::Type t) { return std::string(json::a_type_name(t)); }

/// "a", "b" and "c" -> "a, b or c".
std::string join_or(const std::vector<std::string>& words);
/// "a", "b" and "c" -> "a, b, c".
std::string join_list(const std::vector<std::string>& words);

/// Quotes a name for a message: 'name'. Control characters and long names are shortened.
std::string quote_name(std::string_view name);

/// A name that can be a component, interface, signal or coordinator name: non-empty, no dots,
/// no white space or control characters.
bool simple_name(std::string_view name) noexcept;
/// Non-empty, no white space or control characters (events, filters).
bool token_name(std::string_view name) noexcept;

}  // namespace safecass::spec
