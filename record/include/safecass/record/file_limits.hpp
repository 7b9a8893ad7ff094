#pragma once
/// @file file_limits.hpp
/// How big a recorder's file may grow: with `max_bytes`, the file is rotated instead of filling
/// the disk (PATH -> PATH.1 -> ... -> PATH.keep, the oldest deleted), each segment readable alone.

#include <cstdint>

namespace safecass {

struct FileLimits {
  std::uint64_t max_bytes = 0;  ///< per file (segment); 0: no limit, never rotated
  unsigned keep = 3;            ///< rotated segments kept next to the current file
};

}  // namespace safecass
