// The corpus of bad specifications: each file in tests/data/bad_specs/ holds one kind of mistake;
// its diagnostics must equal, byte for byte, the golden file next to it (name.json.expected).
// Run with SAFECASS_UPDATE_GOLDEN=1 to rewrite the golden files (then review the diff).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

constexpr const char* kCorpus = "tests/data/bad_specs";

/// The cases: every *.json directly in the corpus directory (included/ holds helpers).
std::vector<std::string> cases() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SAFECASS_SOURCE_DIR) + "/" + kCorpus, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == ".json") out.push_back(entry.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool updating() {
  const char* v = std::getenv("SAFECASS_UPDATE_GOLDEN");
  return v != nullptr && std::string(v) == "1";
}

class BadSpec : public ::testing::TestWithParam<std::string> {};

TEST_P(BadSpec, DiagnosticsMatchTheGoldenFile) {
  const std::string path = std::string(kCorpus) + "/" + GetParam();
  const LoadResult r = load_system(path, builtin_registry());
  const std::string actual = formatted(r);
  const std::string golden = path + ".expected";
  if (updating()) {
    std::ofstream(golden, std::ios::binary) << actual;
    GTEST_SKIP() << "rewrote " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << golden << " is missing; run with SAFECASS_UPDATE_GOLDEN=1";
  EXPECT_EQ(actual, read_text(golden));
  EXPECT_FALSE(r.diagnostics.empty()) << "a bad spec must produce a diagnostic";
  EXPECT_EQ(r.system.has_value(), r.ok());
  for (const Diagnostic& d : r.diagnostics) {
    EXPECT_FALSE(d.where.file.empty());
    EXPECT_EQ(d.where.file.find(SAFECASS_SOURCE_DIR), std::string::npos) << "paths stay relative";
  }
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param.substr(0, info.param.find('.'));
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadSpec, ::testing::ValuesIn(cases()), test_name);

TEST(BadSpecCorpus, HoldsAtLeast25CasesEachWithItsGoldenFile) {
  const std::vector<std::string> all = cases();
  EXPECT_GE(all.size(), 25u);
  for (const std::string& c : all) {
    EXPECT_TRUE(std::filesystem::exists(std::string(kCorpus) + "/" + c + ".expected")) << c;
  }
}

}  // namespace
}  // namespace safecass::spec
