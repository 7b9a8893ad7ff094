// `safecass validate` and `safecass schema` (tools/safecass/validate.cpp): output and exit codes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "safecass/json/read.hpp"
#include "spec_commands.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

using ::testing::HasSubstr;

TEST(SpecValidateCommand, GoodSystemExitsZero) {
  ::testing::internal::CaptureStdout();
  const int code = run_validate({"tests/data/good_specs/robodoc.json"}, false);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
  EXPECT_EQ(out, "0 errors, 0 warnings\n");
}

TEST(SpecValidateCommand, ErrorsExitOneAndPrintEveryDiagnostic) {
  ::testing::internal::CaptureStdout();
  const int code =
      run_validate({"tests/data/bad_specs/unknown_key.json", "tests/data/bad_specs/needs_reset.json"}, false);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 1);
  EXPECT_EQ(out, read_text("tests/data/bad_specs/unknown_key.json.expected") +
                     read_text("tests/data/bad_specs/needs_reset.json.expected") + "1 error, 1 warning\n");
}

TEST(SpecValidateCommand, WarningsAloneExitZero) {
  ::testing::internal::CaptureStdout();
  const int code = run_validate({"tests/data/bad_specs/needs_reset.json"}, false);
  ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
}

TEST(SpecValidateCommand, UnreadableFileExitsTwo) {
  ::testing::internal::CaptureStdout();
  const int code = run_validate({"tests/data/no_such.json", "tests/data/good_specs/robodoc.json"}, false);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 2);
  EXPECT_THAT(out, HasSubstr("tests/data/no_such.json: error: cannot read file 'tests/data/no_such.json'"));
}

TEST(SpecValidateCommand, JsonOutputIsOneObjectPerLineThenASummary) {
  ::testing::internal::CaptureStdout();
  const int code = run_validate({"tests/data/bad_specs/unknown_key.json"}, true);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 1);
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t nl; (nl = out.find('\n', start)) != std::string::npos; start = nl + 1)
    lines.push_back(out.substr(start, nl - start));
  ASSERT_EQ(lines.size(), 2u);
  const json::JsonParse first = json::parse_json(lines[0]);
  ASSERT_TRUE(first.value);
  EXPECT_EQ(first.value->find("line")->number, 4);
  EXPECT_EQ(first.value->find("severity")->string, "error");
  EXPECT_EQ(lines[1], R"({"files":["tests/data/bad_specs/unknown_key.json"],"errors":1,"warnings":0})");
}

TEST(SpecSchemaCommand, PrintsTheSchema) {
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(run_schema(), 0);
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), json_schema(builtin_registry()));
}

}  // namespace
}  // namespace safecass::spec
