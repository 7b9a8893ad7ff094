#pragma once
// What the verify tests share: every test runs in the source root, and the built-in filters.

#include <gtest/gtest.h>

#include <filesystem>

#include "safecass/filters/registry.hpp"

namespace safecass::test {

/// Moves to the source root before any test runs (ctest does too; this covers running the binary
/// by hand).
class SourceRoot : public ::testing::Environment {
public:
  void SetUp() override { std::filesystem::current_path(SAFECASS_SOURCE_DIR); }
};
/// Registered once for the whole program (an inline variable), whichever of its files include this.
inline const auto* const kSourceRoot = ::testing::AddGlobalTestEnvironment(new SourceRoot);

/// The built-in filters.
inline const FilterRegistry& registry() {
  static const FilterRegistry r = [] {
    FilterRegistry x;
    register_builtin_filters(x);
    return x;
  }();
  return r;
}

}  // namespace safecass::test
