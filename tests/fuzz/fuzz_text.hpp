#pragma once
// What the fuzz targets share: whether a diagnostic's line and column point inside the input.

#include <cstddef>
#include <string_view>

namespace safecass {

/// True when (line, column), 1-based, is a place of `text` (the column may be one past a line's
/// end: a diagnostic at the end of a line or of the file).
inline bool inside(std::string_view text, int line, int column) {
  if (line < 1 || column < 1) return false;
  int current = 1;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size() && current < line; ++i) {
    if (text[i] == '\n') {
      ++current;
      start = i + 1;
    }
  }
  if (current != line) return false;
  const std::size_t end = text.find('\n', start);
  const std::size_t length = (end == std::string_view::npos ? text.size() : end) - start;
  return static_cast<std::size_t>(column) <= length + 1;
}

}  // namespace safecass
