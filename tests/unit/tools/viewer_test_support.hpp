#pragma once
// What the viewer's tests share: robodoc's files and terse reads of the JSON that the viewer sends.

#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "safecass/json/read.hpp"

namespace safecass::test {

inline const std::string kSystem = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";
inline const std::string kStory = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/story.json";

/// `text` as JSON; a test failure when it is not.
inline json::JsonValue parse(const std::string& text) {
  json::JsonParse p = json::parse_json(text, 64);
  EXPECT_TRUE(p.value.has_value()) << text;
  return p.value ? *p.value : json::JsonValue{};
}

/// The string member `key` of `object`, or a text that says it is missing.
inline std::string str(const json::JsonValue& object, std::string_view key) {
  const json::JsonValue* v = object.find(key);
  return v != nullptr && v->is_string() ? v->string : "<" + std::string(key) + " missing>";
}

}  // namespace safecass::test
