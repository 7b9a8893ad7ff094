// The one JSON writer of SAFECASS (json/write.hpp): what every tool writes goes through it, so its
// rules are checked here once.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"

namespace safecass::json {
namespace {

TEST(JsonWriter, AStringEscapesQuotesBackslashesAndEveryControlCharacter) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json_string("line\nnext\r\ttab"), "\"line\\nnext\\r\\ttab\"");
  EXPECT_EQ(json_string(std::string("\x01\x1b\x1f", 3)), "\"\\u0001\\u001b\\u001f\"");
  EXPECT_EQ(json_string(std::string("nul\0byte", 8)), "\"nul\\u0000byte\"");
  EXPECT_EQ(json_string("caf\xc3\xa9"), "\"caf\xc3\xa9\"") << "other bytes are copied (UTF-8 stays as it is)";
}

TEST(JsonWriter, EveryStringItWritesReadsBackAsTheSameText) {
  std::string all;
  for (int c = 1; c < 128; ++c) all += static_cast<char>(c);
  const JsonParse parsed = parse_json(json_string(all));
  ASSERT_TRUE(parsed.value) << parsed.error->message;
  ASSERT_TRUE(parsed.value->is_string());
  EXPECT_EQ(parsed.value->string, all);
}

TEST(JsonWriter, ANumberIsItsShortestTextAndNullWhenNotFinite) {
  EXPECT_EQ(json_number(30.0), "30");
  EXPECT_EQ(json_number(1.5), "1.5");
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(-2e-7), "-2e-07");
  EXPECT_EQ(json_number(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(json_number(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json_number(-std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json_number_array({1.0, std::nan(""), 2.5}), "[1,null,2.5]");
}

TEST(JsonWriter, SecondsHaveSixDecimalsAsInTheHistoryFile) {
  EXPECT_EQ(json_seconds(Time{std::chrono::microseconds(301000)}), "0.301000");
  EXPECT_EQ(json_seconds(Time{}), "0.000000");
}

TEST(JsonWriter, AnObjectKeepsItsMembersInOrderAndEscapesItsKeys) {
  const std::string text = JsonObject()
                               .str("a", "x")
                               .num("b", 1)
                               .integer("c", -3)
                               .boolean("d", true)
                               .null("e")
                               .opt("f", "")
                               .opt("g", "y")
                               .strings("h", {"p", "q"})
                               .raw("i", "[1]")
                               .str("k\"ey", "v")
                               .text();
  EXPECT_EQ(text, R"({"a":"x","b":1,"c":-3,"d":true,"e":null,"f":null,"g":"y","h":["p","q"],"i":[1],"k\"ey":"v"})");
  EXPECT_EQ(JsonObject().text(), "{}");
  EXPECT_EQ(JsonObject().str("a", "1").line_break().str("b", "2").text(), "{\"a\":\"1\",\n\"b\":\"2\"}");
}

TEST(JsonWriter, AnArrayIsCompactOrOneItemALine) {
  EXPECT_EQ(JsonArray().raw("1").str("x").text(), "[1,\"x\"]");
  EXPECT_TRUE(JsonArray().empty());
  EXPECT_EQ(JsonArray().text(), "[]");
  EXPECT_EQ(JsonArray(JsonArray::Layout::OnePerLine).raw("1").str("x").text(), "[\n1,\n\"x\"]");
  EXPECT_EQ(json_string_array({}), "[]");
}

}  // namespace
}  // namespace safecass::json
