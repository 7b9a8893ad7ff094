#pragma once
/// @file text_map.hpp
/// A hash map keyed by text that is looked up by a view of the text: finding a name read from a
/// spec or a message makes no std::string.

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>

namespace safecass {

/// Hashes std::string and std::string_view alike (transparent).
struct TextHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view text) const noexcept { return std::hash<std::string_view>{}(text); }
};

/// Values by name; `find(std::string_view)` makes no string.
template <class V>
using TextMap = std::unordered_map<std::string, V, TextHash, std::equal_to<>>;

}  // namespace safecass
