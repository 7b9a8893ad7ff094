// The position-keeping JSON reader: values, positions, comments, escapes, and errors with positions.

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "safecass/json/read.hpp"

namespace safecass::json {
namespace {

JsonValue parse_ok(std::string_view text) {
  JsonParse p = parse_json(text);
  EXPECT_FALSE(p.error) << (p.error ? p.error->message : "");
  return p.value ? *p.value : JsonValue{};
}

JsonError parse_error(std::string_view text, int max_depth = 64) {
  JsonParse p = parse_json(text, max_depth);
  EXPECT_FALSE(p.value);
  EXPECT_TRUE(p.error);
  return p.error ? *p.error : JsonError{};
}

TEST(JsonReader, ReadsEveryKindOfValue) {
  const JsonValue v =
      parse_ok(R"({"s": "x", "n": -1.5e2, "i": 42, "t": true, "f": false, "z": null, "a": [1, "2"], "o": {}})");
  ASSERT_TRUE(v.is_object());
  EXPECT_EQ(v.find("s")->string, "x");
  EXPECT_DOUBLE_EQ(v.find("n")->number, -150.0);
  EXPECT_FALSE(v.find("n")->integral);
  EXPECT_TRUE(v.find("i")->integral);
  EXPECT_TRUE(v.find("t")->boolean);
  EXPECT_TRUE(v.find("f")->is_bool());
  EXPECT_TRUE(v.find("z")->is_null());
  EXPECT_EQ(v.find("a")->array.size(), 2u);
  EXPECT_TRUE(v.find("o")->is_object());
  EXPECT_EQ(v.find("missing"), nullptr);
}

TEST(JsonReader, KeepsTheLineAndColumnOfEveryValueAndKey) {
  const JsonValue v = parse_ok("{\n  \"a\": 1,\n  \"b\": [true,\n        \"x\"]\n}");
  EXPECT_EQ(v.position.line, 1);
  EXPECT_EQ(v.position.column, 1);
  const JsonMember* b = v.find_member("b");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->key_position.line, 3);
  EXPECT_EQ(b->key_position.column, 3);
  EXPECT_EQ(b->value.position.line, 3);
  EXPECT_EQ(b->value.position.column, 8);
  EXPECT_EQ(b->value.array[1].position.line, 4);
  EXPECT_EQ(b->value.array[1].position.column, 9);
  EXPECT_EQ(v.find("a")->position.column, 8);
}

TEST(JsonReader, ColumnsCountBytes) {
  const JsonValue v = parse_ok("{\"\xC2\xB0\": 1, \"b\": 2}");
  EXPECT_EQ(v.find_member("b")->key_position.column, 11);  // 10 if it counted characters
}

TEST(JsonReader, AcceptsLineAndBlockComments) {
  const JsonValue v = parse_ok("// head\n{ /* a\n b */ \"a\": 1 // tail\n, \"b\": /**/ 2 }\n// end");
  EXPECT_DOUBLE_EQ(v.find("a")->number, 1.0);
  EXPECT_EQ(v.find("b")->position.line, 4);
}

TEST(JsonReader, DecodesEscapesAndSurrogatePairs) {
  const JsonValue v = parse_ok(R"(["\"\\\/\b\f\n\r\t", "\u00e9\u20ac", "\ud83d\ude00"])");
  EXPECT_EQ(v.array[0].string, "\"\\/\b\f\n\r\t");
  EXPECT_EQ(v.array[1].string, "\xC3\xA9\xE2\x82\xAC");
  EXPECT_EQ(v.array[2].string, "\xF0\x9F\x98\x80");
}

TEST(JsonReader, KeepsDuplicateKeysForValidationToReport) {
  const JsonValue v = parse_ok(R"({"a": 1, "a": 2})");
  ASSERT_EQ(v.object.size(), 2u);
  EXPECT_DOUBLE_EQ(v.find("a")->number, 1.0);  // find() gives the first
}

TEST(JsonReader, ReportsSyntaxErrorsWithTheirPosition) {
  const JsonError e = parse_error("{\n  \"a\": 1\n  \"b\": 2\n}");
  EXPECT_EQ(e.position.line, 3);
  EXPECT_EQ(e.position.column, 3);
  EXPECT_EQ(e.message, "expected ',' or '}'");
}

TEST(JsonReader, ReportsBadEscapesAndUnterminatedStrings) {
  EXPECT_EQ(parse_error(R"(["\q"])").message, "invalid escape '\\q'");
  EXPECT_EQ(parse_error(R"(["\u12"])").message, "invalid \\u escape: four hex digits expected");
  EXPECT_EQ(parse_error(R"(["\udc00"])").message, "invalid \\u escape: lone low surrogate");
  EXPECT_EQ(parse_error(R"(["\ud800x"])").message, "invalid \\u escape: high surrogate without its low surrogate");
  const JsonError e = parse_error("[\"abc");
  EXPECT_EQ(e.message, "unterminated string");
  EXPECT_EQ(e.position.column, 2);
  EXPECT_EQ(parse_error("[\"a\nb\"]").message, "unterminated string (line break inside)");
  EXPECT_EQ(parse_error("[\"a\tb\"]").message, "control character in string");
}

TEST(JsonReader, ReportsTrailingCommasAndTrailingGarbage) {
  EXPECT_EQ(parse_error("[1, 2,]").message, "trailing comma before ']'");
  EXPECT_EQ(parse_error("{\"a\": 1,}").message, "trailing comma before '}'");
  const JsonError e = parse_error("{}\n}");
  EXPECT_EQ(e.message, "unexpected text after the JSON value");
  EXPECT_EQ(e.position.line, 2);
}

TEST(JsonReader, ReportsEmptyInput) {
  EXPECT_EQ(parse_error("").message, "empty document: expected a JSON value");
  EXPECT_EQ(parse_error("  // only a comment\n").message, "empty document: expected a JSON value");
  EXPECT_EQ(parse_error("/* unterminated").message, "unterminated /* comment");
}

TEST(JsonReader, LimitsNestingDepth) {
  const std::string deep = std::string(100, '[') + std::string(100, ']');
  const JsonError e = parse_error(deep);
  EXPECT_EQ(e.message, "nesting deeper than 64 levels");
  EXPECT_EQ(e.position.column, 66);
  const std::string ok = std::string(64, '[') + std::string(64, ']');
  EXPECT_TRUE(parse_json(ok).value);
  EXPECT_FALSE(parse_json(std::string(100000, '[')).value);  // no stack overflow
}

TEST(JsonReader, RejectsNumbersTooLargeAndAcceptsTinyOnes) {
  EXPECT_EQ(parse_error("[1e999]").message, "number 1e999 is out of range");
  EXPECT_EQ(parse_error("[-1e400]").message, "number -1e400 is out of range");
  const JsonValue tiny = parse_ok("[1e-999]");
  EXPECT_DOUBLE_EQ(tiny.array[0].number, 0.0);
  const JsonValue big = parse_ok("[123456789012345678901234567890]");
  EXPECT_GT(big.array[0].number, 1e29);
  EXPECT_EQ(parse_error("[01]").message, "expected ',' or ']'");
  EXPECT_EQ(parse_error("[1.]").message, "invalid number: digits expected after '.'");
  EXPECT_EQ(parse_error("[-]").message, "invalid number");
  EXPECT_EQ(parse_error("[NaN]").message, "unexpected character 'N': expected a value");
}

TEST(JsonReader, ReportsBadLiteralsAndControlBytes) {
  EXPECT_EQ(parse_error("[tru]").message, "invalid literal: expected 'true'");
  EXPECT_EQ(parse_error(std::string("[\0]", 3)).message, "unexpected character '\\x00': expected a value");
}

TEST(JsonReader, NamesTheTypeOfAValueAsJsonDoes) {
  EXPECT_EQ(type_name(JsonValue::Type::Object), "object");
  EXPECT_EQ(type_name(JsonValue::Type::Bool), "boolean");
}

TEST(JsonReader, StreamsTheElementsOfOneListOfTheRootObjectAndKeepsTheRestAsATree) {
  std::vector<std::pair<std::size_t, JsonValue>> seen;
  const JsonParse p = parse_json_streaming(
      "{ \"a\": [9],\n  \"steps\": [ {\"x\": [1, 2]},\n 3 ],\n \"steps\": [4], \"o\": { \"steps\": [5] } }", "steps",
      [&](std::size_t index, JsonValue&& element) { seen.emplace_back(index, std::move(element)); });
  ASSERT_FALSE(p.error) << p.error->message;
  ASSERT_EQ(seen.size(), 2u) << "the first root member called steps only, not nested lists";
  EXPECT_EQ(seen[0].first, 0u);
  EXPECT_EQ(seen[0].second.find("x")->array.size(), 2u);
  EXPECT_EQ(seen[1].first, 1u);
  EXPECT_EQ(seen[1].second.number, 3.0);
  EXPECT_EQ(seen[1].second.position.line, 3);
  EXPECT_EQ(seen[1].second.position.column, 2);
  const JsonValue& root = *p.value;
  const JsonValue* steps = root.find("steps");
  ASSERT_TRUE(steps != nullptr && steps->is_array());
  EXPECT_TRUE(steps->array.empty()) << "its elements were handed over, not kept";
  EXPECT_EQ(steps->position.line, 2);
  EXPECT_EQ(steps->position.column, 12);
  EXPECT_EQ(root.object[2].value.array.size(), 1u) << "a second member of the same name stays in the tree";
  EXPECT_EQ(root.find("o")->find("steps")->array.size(), 1u);
  EXPECT_EQ(root.find("a")->array.size(), 1u);

  // Errors are as parse_json's, with their positions; the elements before them were handed.
  seen.clear();
  const JsonParse bad = parse_json_streaming("{\"steps\": [1, 2,]}", "steps", [&](std::size_t index, JsonValue&& e) {
    seen.emplace_back(index, std::move(e));
  });
  ASSERT_TRUE(bad.error);
  EXPECT_EQ(bad.error->message, "trailing comma before ']'");
  EXPECT_EQ(bad.error->position.column, 17);
  EXPECT_EQ(seen.size(), 2u);
  EXPECT_EQ(parse_json_streaming(
                "{\"steps\": [[[1]]]}", "steps", [](std::size_t, JsonValue&&) {}, 2)
                .error->message,
            "nesting deeper than 2 levels");
}

}  // namespace
}  // namespace safecass::json
