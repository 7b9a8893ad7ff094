#include "safecass/json/write.hpp"

#include "safecass/core/text.hpp"

#include <cmath>

#include <fmt/format.h>

namespace safecass::json {

void append_json_string(std::string& out, std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default: {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20) {
          out += "\\u00";
          out += kHex[u >> 4];
          out += kHex[u & 0xf];
        } else {
          out += c;
        }
      }
    }
  }
  out += '"';
}

std::string json_string(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  append_json_string(out, text);
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return number_text(v);
}

std::string json_seconds(Time t) { return seconds_text(t); }

std::string json_string_array(const std::vector<std::string>& items) {
  JsonArray a;
  for (const std::string& s : items) a.str(s);
  return a.text();
}

std::string json_number_array(const std::vector<double>& items) {
  JsonArray a;
  for (const double v : items) a.raw(json_number(v));
  return a.text();
}

void JsonObject::key(std::string_view key) {
  if (text_.size() > 1) text_ += ',';
  if (break_) {
    text_ += '\n';
    break_ = false;
  }
  append_json_string(text_, key);
  text_ += ':';
}

JsonObject& JsonObject::raw(std::string_view key, std::string_view json) {
  this->key(key);
  text_ += json;
  return *this;
}

JsonObject& JsonObject::str(std::string_view key, std::string_view value) {
  this->key(key);
  append_json_string(text_, value);
  return *this;
}

void JsonArray::next() {
  if (text_.size() > 1) text_ += ',';
  if (layout_ == Layout::OnePerLine) text_ += '\n';
}

JsonArray& JsonArray::raw(std::string_view json) {
  next();
  text_ += json;
  return *this;
}

JsonArray& JsonArray::str(std::string_view value) {
  next();
  append_json_string(text_, value);
  return *this;
}

}  // namespace safecass::json
