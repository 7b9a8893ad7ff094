#pragma once
/// @file read.hpp
/// The one JSON reader of SAFECASS (the writer is write.hpp; both form the json module, below spec
/// and introspect). It keeps the line and column of every value and key, accepts `//` and `/* */`
/// comments (as the 2016 specifications do), and never crashes on any input: malformed text,
/// deep nesting, huge numbers and invalid UTF-8 escapes all give an error with a position.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace safecass::json {

/// 1-based line and column (columns count bytes).
struct TextPosition {
  int line = 0;
  int column = 0;
};

struct JsonMember;

struct JsonValue {
  enum class Type : std::uint8_t { Null, Bool, Number, String, Array, Object };
  Type type = Type::Null;
  bool boolean = false;
  double number = 0.0;
  bool integral = false;  ///< written without fraction or exponent
  std::string string;
  std::vector<JsonValue> array;
  std::vector<JsonMember> object;  ///< in file order; duplicates kept (validation reports them)
  TextPosition position;

  bool is_null() const noexcept { return type == Type::Null; }
  bool is_bool() const noexcept { return type == Type::Bool; }
  bool is_number() const noexcept { return type == Type::Number; }
  bool is_string() const noexcept { return type == Type::String; }
  bool is_array() const noexcept { return type == Type::Array; }
  bool is_object() const noexcept { return type == Type::Object; }
  /// The first member called `key`, or nullptr (also when this is not an object).
  const JsonValue* find(std::string_view key) const noexcept;
  const JsonMember* find_member(std::string_view key) const noexcept;
};

struct JsonMember {
  std::string key;
  TextPosition key_position;
  JsonValue value;
};

/// "object", "array", "string", "number", "boolean", "null".
std::string_view type_name(JsonValue::Type t) noexcept;
/// The same with its article, for messages: "null", "a boolean", "a number", "a string", "an
/// array", "an object".
std::string_view a_type_name(JsonValue::Type t) noexcept;

struct JsonError {
  TextPosition position;
  std::string message;
};

struct JsonParse {
  std::optional<JsonValue> value;
  std::optional<JsonError> error;
};

/// Parses one JSON document (comments allowed). Nesting deeper than `max_depth` is an error.
JsonParse parse_json(std::string_view text, int max_depth = 64);

/// Receives one element of a streamed array: its index and its value (which it may keep).
using JsonElementHandler = std::function<void(std::size_t index, JsonValue&& element)>;

/// Parses like parse_json(), but the elements of one large list are handed to `element` one at a
/// time, as each is parsed, instead of being kept in the tree: the list that is the value of the
/// first member called `key` of the root object. In the result, that member's value is an empty
/// array at the list's position. A document's tree takes many times its text's size; a scenario
/// of millions of steps is read this way (scenario.hpp). Errors are as parse_json()'s; elements
/// before the error have been handed already (a caller that keeps them discards them on error).
JsonParse parse_json_streaming(std::string_view text, std::string_view key, const JsonElementHandler& element,
                               int max_depth = 64);

}  // namespace safecass::json
