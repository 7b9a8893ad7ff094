#include "safecass/introspect/sample_text.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

namespace safecass::introspect {

std::string count_text(std::size_t n) { return std::to_string(n) + (n == 1 ? " sample" : " samples"); }

std::optional<double> parse_number(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return v;
}

namespace {
/// Injected values are finite (the Monitor's rule, docs/filters.md): said here with the word typed.
std::string not_finite(std::string_view word) {
  return "'" + std::string(word) + "' is not a finite number: injected values must be finite";
}
}  // namespace

[[nodiscard]] Expected<std::vector<double>> parse_numbers(std::string_view text) {
  std::vector<double> values;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == ',' || text[i] == ' ' || text[i] == '\t' || text[i] == '\r') {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && text[j] != ',' && text[j] != ' ' && text[j] != '\t' && text[j] != '\r') ++j;
    const auto v = parse_number(text.substr(i, j - i));
    if (!v) return fail(ErrorCode::Parse, "'" + std::string(text.substr(i, j - i)) + "' is not a number");
    if (!std::isfinite(*v)) return fail(ErrorCode::Parse, not_finite(text.substr(i, j - i)));
    values.push_back(*v);
    i = j;
  }
  return values;
}

[[nodiscard]] Expected<std::vector<double>> parse_sample(std::string_view word) {
  if (!word.empty() && word.front() == '[') {
    if (word.back() != ']') return fail(ErrorCode::Parse, "'" + std::string(word) + "': a vector sample ends with ']'");
    auto values = parse_numbers(word.substr(1, word.size() - 2));
    if (!values) return values;
    if (values->empty()) return fail(ErrorCode::Parse, "'[]': a vector sample needs at least one value");
    return values;
  }
  const auto v = parse_number(word);
  if (!v) return fail(ErrorCode::Parse, "'" + std::string(word) + "' is not a number or a vector sample [a,b,...]");
  if (!std::isfinite(*v)) return fail(ErrorCode::Parse, not_finite(word));
  return std::vector<double>{*v};
}

[[nodiscard]] Expected<std::vector<std::vector<double>>> parse_samples(const std::vector<std::string>& words) {
  std::vector<std::vector<double>> samples;
  for (const std::string& w : words) {
    auto s = parse_sample(w);
    if (!s) return tl::unexpected(s.error());
    samples.push_back(std::move(*s));
  }
  return samples;
}

[[nodiscard]] Expected<std::vector<std::vector<double>>> parse_sample_file(const std::string& where,
                                                                           std::string_view text) {
  std::vector<std::vector<double>> samples;
  std::istringstream lines{std::string(text)};
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    const std::string_view body = std::string_view(line).substr(0, line.find('#'));
    auto values = parse_numbers(body);
    if (!values) return fail(ErrorCode::Parse, where + ":" + std::to_string(number) + ": " + values.error().message);
    if (values->empty()) continue;  // a blank line or a comment
    samples.push_back(std::move(*values));
  }
  if (samples.empty()) return fail(ErrorCode::Parse, where + ": no samples");
  return samples;
}

}  // namespace safecass::introspect
