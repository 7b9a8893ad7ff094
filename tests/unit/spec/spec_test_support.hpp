#pragma once
// Shared helpers of the spec tests. Every test runs in the source root, so that the paths in
// diagnostics are the relative ones the golden files hold.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/spec/spec.hpp"

namespace safecass::spec {

/// Moves to the source root before any test runs (ctest does too; this covers running the
/// binary by hand).
class SourceRoot : public ::testing::Environment {
public:
  void SetUp() override { std::filesystem::current_path(SAFECASS_SOURCE_DIR); }
};
/// Registered once for the whole program (an inline variable), whichever of its files include this.
inline const auto* const kSourceRoot = ::testing::AddGlobalTestEnvironment(new SourceRoot);

inline const FilterRegistry& builtin_registry() { return builtin_filters(); }

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every diagnostic, formatted, one per line.
inline std::string formatted(const LoadResult& r) {
  std::string out;
  for (const Diagnostic& d : r.diagnostics) out += format(d) + "\n";
  return out;
}

/// Loads a text given inline as if it were the file `name`.
inline LoadResult load_text(std::string_view text, const std::string& name = "tests/data/inline.json") {
  return load_system_from_text(text, name, builtin_registry());
}

}  // namespace safecass::spec
