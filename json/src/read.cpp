#include "safecass/json/read.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace safecass::json {

const JsonMember* JsonValue::find_member(std::string_view key) const noexcept {
  if (type != Type::Object) return nullptr;
  for (const JsonMember& m : object) {
    if (m.key == key) return &m;
  }
  return nullptr;
}

const JsonValue* JsonValue::find(std::string_view key) const noexcept {
  const JsonMember* m = find_member(key);
  return m == nullptr ? nullptr : &m->value;
}

std::string_view type_name(JsonValue::Type t) noexcept {
  switch (t) {
    case JsonValue::Type::Null: return "null";
    case JsonValue::Type::Bool: return "boolean";
    case JsonValue::Type::Number: return "number";
    case JsonValue::Type::String: return "string";
    case JsonValue::Type::Array: return "array";
    case JsonValue::Type::Object: return "object";
  }
  return "?";
}

std::string_view a_type_name(JsonValue::Type t) noexcept {
  switch (t) {
    case JsonValue::Type::Null: return "null";
    case JsonValue::Type::Bool: return "a boolean";
    case JsonValue::Type::Number: return "a number";
    case JsonValue::Type::String: return "a string";
    case JsonValue::Type::Array: return "an array";
    case JsonValue::Type::Object: return "an object";
  }
  return "a value";
}

namespace {

class Parser {
public:
  Parser(std::string_view text, int max_depth) : text_(text), max_depth_(max_depth) {}
  /// Hands the elements of the root object's first `key` list to `element` (parse_json_streaming).
  Parser(std::string_view text, int max_depth, std::string_view key, const JsonElementHandler& element)
      : text_(text), max_depth_(max_depth), stream_key_(key), element_(&element) {}

  JsonParse run() {
    JsonParse out;
    skip_space();
    if (failed_) return error_result();
    if (at_end()) {
      fail_here("empty document: expected a JSON value");
      return error_result();
    }
    JsonValue v;
    if (!value(v, 0)) return error_result();
    skip_space();
    if (failed_) return error_result();
    if (!at_end()) {
      fail_here("unexpected text after the JSON value");
      return error_result();
    }
    out.value = std::move(v);
    return out;
  }

private:
  JsonParse error_result() {
    JsonParse out;
    out.error = error_;
    return out;
  }
  bool at_end() const noexcept { return pos_ >= text_.size(); }
  char peek() const noexcept { return at_end() ? '\0' : text_[pos_]; }
  TextPosition here() const noexcept { return TextPosition{line_, static_cast<int>(pos_ - line_start_) + 1}; }
  void advance() noexcept {
    if (text_[pos_] == '\n') {
      ++line_;
      line_start_ = pos_ + 1;
    }
    ++pos_;
  }
  bool fail_at(TextPosition p, std::string message) {
    if (!failed_) {
      failed_ = true;
      error_ = JsonError{p, std::move(message)};
    }
    return false;
  }
  bool fail_here(std::string message) { return fail_at(here(), std::move(message)); }

  void skip_space() {
    while (!at_end()) {
      const char c = peek();
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        advance();
      } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
        while (!at_end() && peek() != '\n') advance();
      } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '*') {
        const TextPosition start = here();
        advance();
        advance();
        while (!at_end() && !(peek() == '*' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/')) advance();
        if (at_end()) {
          fail_at(start, "unterminated /* comment");
          return;
        }
        advance();
        advance();
      } else {
        return;
      }
    }
  }

  bool value(JsonValue& v, int depth) {
    if (depth > max_depth_) return fail_here("nesting deeper than " + std::to_string(max_depth_) + " levels");
    v.position = here();
    const char c = peek();
    switch (c) {
      case '{': return object(v, depth);
      case '[': return array(v, depth);
      case '"': v.type = JsonValue::Type::String; return string(v.string);
      case 't': return literal("true", v, JsonValue::Type::Bool, true);
      case 'f': return literal("false", v, JsonValue::Type::Bool, false);
      case 'n': return literal("null", v, JsonValue::Type::Null, false);
      default: break;
    }
    if (c == '-' || (c >= '0' && c <= '9')) return number(v);
    if (at_end()) return fail_here("unexpected end of file: expected a value");
    return fail_here(std::string("unexpected character '") + printable(c) + "': expected a value");
  }

  static std::string printable(char c) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned char>(c));
      return buf;
    }
    return std::string(1, c);
  }

  bool literal(std::string_view word, JsonValue& v, JsonValue::Type type, bool b) {
    if (text_.substr(pos_, word.size()) != word)
      return fail_here("invalid literal: expected '" + std::string(word) + "'");
    for (std::size_t i = 0; i < word.size(); ++i) advance();
    v.type = type;
    v.boolean = b;
    return true;
  }

  bool number(JsonValue& v) {
    const std::size_t start = pos_;
    const TextPosition p = here();
    if (peek() == '-') advance();
    if (peek() == '0') {
      advance();
    } else if (peek() >= '1' && peek() <= '9') {
      while (peek() >= '0' && peek() <= '9') advance();
    } else {
      return fail_at(p, "invalid number");
    }
    bool integral = true;
    if (peek() == '.') {
      integral = false;
      advance();
      if (!(peek() >= '0' && peek() <= '9')) return fail_at(p, "invalid number: digits expected after '.'");
      while (peek() >= '0' && peek() <= '9') advance();
    }
    if (peek() == 'e' || peek() == 'E') {
      integral = false;
      advance();
      if (peek() == '+' || peek() == '-') advance();
      if (!(peek() >= '0' && peek() <= '9')) return fail_at(p, "invalid number: digits expected in the exponent");
      while (peek() >= '0' && peek() <= '9') advance();
    }
    const std::string_view digits = text_.substr(start, pos_ - start);
    double d = 0.0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), d);
    if (ec == std::errc::result_out_of_range) {
      // Underflow (a negative exponent) is harmlessly zero; overflow is not a usable number.
      const std::size_t e = digits.find_first_of("eE");
      if (e == std::string_view::npos || e + 1 >= digits.size() || digits[e + 1] != '-') {
        return fail_at(
            p, "number " + std::string(digits.substr(0, 40)) + (digits.size() > 40 ? "..." : "") + " is out of range");
      }
      d = 0.0;
    } else if (ec != std::errc() || ptr != digits.data() + digits.size() || !std::isfinite(d)) {
      return fail_at(p, "invalid number");
    }
    v.type = JsonValue::Type::Number;
    v.number = d;
    v.integral = integral;
    return true;
  }

  static void append_utf8(std::string& out, std::uint32_t cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  bool hex4(std::uint32_t& out) {
    out = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = peek();
      std::uint32_t d = 0;
      if (c >= '0' && c <= '9')
        d = static_cast<std::uint32_t>(c - '0');
      else if (c >= 'a' && c <= 'f')
        d = static_cast<std::uint32_t>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F')
        d = static_cast<std::uint32_t>(c - 'A' + 10);
      else
        return fail_here("invalid \\u escape: four hex digits expected");
      out = out * 16 + d;
      advance();
    }
    return true;
  }

  bool string(std::string& out) {
    const TextPosition start = here();
    advance();  // opening quote
    for (;;) {
      if (at_end()) return fail_at(start, "unterminated string");
      const char c = peek();
      if (c == '"') {
        advance();
        return true;
      }
      if (c == '\n') return fail_at(start, "unterminated string (line break inside)");
      if (static_cast<unsigned char>(c) < 0x20) return fail_here("control character in string");
      if (c != '\\') {
        out += c;
        advance();
        continue;
      }
      advance();
      const char e = peek();
      if (at_end()) return fail_at(start, "unterminated string");
      advance();
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          std::uint32_t cp = 0;
          if (!hex4(cp)) return false;
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (peek() != '\\' || pos_ + 1 >= text_.size() || text_[pos_ + 1] != 'u') {
              return fail_here("invalid \\u escape: high surrogate without its low surrogate");
            }
            advance();
            advance();
            std::uint32_t low = 0;
            if (!hex4(low)) return false;
            if (low < 0xDC00 || low > 0xDFFF) return fail_here("invalid \\u escape: bad low surrogate");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            return fail_here("invalid \\u escape: lone low surrogate");
          }
          append_utf8(out, cp);
          break;
        }
        default: return fail_here(std::string("invalid escape '\\") + printable(e) + "'");
      }
    }
  }

  /// An array whose elements go to `element_` as they are parsed; `v` stays an empty array.
  bool streamed_array(JsonValue& v, int depth) {
    if (depth > max_depth_) return fail_here("nesting deeper than " + std::to_string(max_depth_) + " levels");
    v.type = JsonValue::Type::Array;
    return elements(depth, [&](std::size_t index, JsonValue&& item) { (*element_)(index, std::move(item)); });
  }

  bool array(JsonValue& v, int depth) {
    v.type = JsonValue::Type::Array;
    return elements(depth, [&](std::size_t, JsonValue&& item) { v.array.push_back(std::move(item)); });
  }

  /// The elements of the array at '[', each handed to `sink(index, item)` as soon as it is parsed.
  template <class Sink>
  bool elements(int depth, Sink&& sink) {
    advance();
    skip_space();
    if (failed_) return false;
    if (peek() == ']') {
      advance();
      return true;
    }
    for (std::size_t index = 0;; ++index) {
      JsonValue item;
      if (!value(item, depth + 1)) return false;
      sink(index, std::move(item));
      bool more = false;
      if (!separator(']', more)) return false;
      if (!more) return true;
    }
  }

  bool object(JsonValue& v, int depth) {
    v.type = JsonValue::Type::Object;
    advance();
    skip_space();
    if (failed_) return false;
    if (peek() == '}') {
      advance();
      return true;
    }
    for (;;) {
      if (peek() != '"') {
        return fail_here(at_end() ? "unexpected end of file: expected a member name"
                                  : "expected a member name in double quotes");
      }
      JsonMember m;
      m.key_position = here();
      if (!string(m.key)) return false;
      skip_space();
      if (failed_) return false;
      if (peek() != ':') return fail_here("expected ':' after member name \"" + m.key + "\"");
      advance();
      skip_space();
      if (failed_) return false;
      if (depth == 0 && element_ != nullptr && !streamed_ && m.key == stream_key_ && peek() == '[') {
        streamed_ = true;
        m.value.position = here();
        if (!streamed_array(m.value, depth + 1)) return false;
      } else if (!value(m.value, depth + 1)) {
        return false;
      }
      v.object.push_back(std::move(m));
      bool more = false;
      if (!separator('}', more)) return false;
      if (!more) return true;
    }
  }

  /// After an element of an array or a member of an object: a ',' and another one (`more`), or
  /// `close`, the end. A trailing comma is an error.
  bool separator(char close, bool& more) {
    auto closing = [close] { return std::string("'") + close + "'"; };  // for a message only
    skip_space();
    if (failed_) return false;
    if (peek() == ',') {
      advance();
      skip_space();
      if (failed_) return false;
      if (peek() == close) return fail_here("trailing comma before " + closing());
      more = true;
      return true;
    }
    if (peek() == close) {
      advance();
      more = false;
      return true;
    }
    return fail_here((at_end() ? "unexpected end of file: expected ',' or " : "expected ',' or ") + closing());
  }

  std::string_view text_;
  int max_depth_;
  std::string_view stream_key_;
  const JsonElementHandler* element_ = nullptr;
  bool streamed_ = false;  ///< the streamed list has been met (only the first one streams)
  std::size_t pos_ = 0;
  int line_ = 1;
  std::size_t line_start_ = 0;
  bool failed_ = false;
  JsonError error_;
};

}  // namespace

JsonParse parse_json(std::string_view text, int max_depth) { return Parser(text, max_depth).run(); }

JsonParse parse_json_streaming(std::string_view text, std::string_view key, const JsonElementHandler& element,
                               int max_depth) {
  return Parser(text, max_depth, key, element).run();
}

}  // namespace safecass::json
