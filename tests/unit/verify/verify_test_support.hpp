#pragma once
// What the verify tests share: every test runs in the source root.

#include <gtest/gtest.h>

#include <filesystem>

namespace safecass::test {

/// Moves to the source root before any test runs (ctest does too; this covers running the binary
/// by hand).
class SourceRoot : public ::testing::Environment {
public:
  void SetUp() override { std::filesystem::current_path(SAFECASS_SOURCE_DIR); }
};
/// Registered once for the whole program (an inline variable), whichever of its files include this.
inline const auto* const kSourceRoot = ::testing::AddGlobalTestEnvironment(new SourceRoot);

}  // namespace safecass::test
