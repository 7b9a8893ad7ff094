#pragma once
/// @file sample_text.hpp
/// Samples written as text, as an operator types them for an injection (the console's `filter
/// inject`/`dinject`, a `filter dinload` file read by the console or sent to a live coordinator):
/// numbers separated by commas and/or blanks; a sample `1.5` or `[1,2,3]`. Injected values are
/// finite (the rule of every injection path, docs/filters.md): `nan`, `inf` and `-inf` are refused
/// with the word typed.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"

namespace safecass::introspect {

/// "1 sample", "3 samples": how a confirmation counts the samples of an injection.
std::string count_text(std::size_t n);
/// A number as typed ("+1", "2.5e-3", "nan"): nullopt when the whole text is not one.
std::optional<double> parse_number(std::string_view s);
/// Finite numbers separated by commas and/or blanks. Errors (Parse) name the offending text.
[[nodiscard]] Expected<std::vector<double>> parse_numbers(std::string_view text);
/// A sample: `1.5` (scalar) or `[1,2,3]` / `[1 2 3]` (vector) of finite numbers.
[[nodiscard]] Expected<std::vector<double>> parse_sample(std::string_view word);
/// Every word as a sample. Errors: the first word that is not one.
[[nodiscard]] Expected<std::vector<std::vector<double>>> parse_samples(const std::vector<std::string>& words);
/// The samples of a sample file: one per line, numbers separated by spaces or commas, '#' starts
/// a comment. Errors (Parse): "WHERE:LINE: what", or "WHERE: no samples".
[[nodiscard]] Expected<std::vector<std::vector<double>>> parse_sample_file(const std::string& where,
                                                                           std::string_view text);

}  // namespace safecass::introspect
