// A short, deterministic fuzz run that is part of `make test`: thousands of mutated versions of
// the good specifications (byte flips, insertions, deletions, truncations, spliced tokens) and
// every value of a component replaced by every other JSON type. The loader must never crash or
// throw, every diagnostic must point inside its file, and whatever loads without errors must
// instantiate. The long run uses the libFuzzer target (tests/fuzz/, docs/spec-format.md).

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

const std::vector<std::string> kSeeds = {
    "tests/data/good_specs/robodoc.json", "tests/data/good_specs/jr3.json", "tests/data/good_specs/parts/control.json",
    "tests/data/good_specs/legacy_2016/jr3.json", "tests/data/good_specs/legacy_2016/system.json"};

const std::vector<std::string> kTokens = {"{",
                                          "}",
                                          "[",
                                          "]",
                                          "\"",
                                          ",",
                                          ":",
                                          "null",
                                          "true",
                                          "0",
                                          "-1",
                                          "1e999",
                                          "1e-999",
                                          "256",
                                          "\"\"",
                                          "[]",
                                          "{}",
                                          "//",
                                          "/*",
                                          "*/",
                                          "\\u",
                                          "\\ud800",
                                          "\xff",
                                          "\xc3",
                                          "\xed\xa0\x80",
                                          std::string(1, '\0'),
                                          "\"include\": \"robodoc.json\"",
                                          "\"pipeline\": []",
                                          "\"class_name\": \"Range\"",
                                          "\"event_onset\": \"EVT_STALE\"",
                                          "\"s_P\"",
                                          "\"JR3.Force\"",
                                          "\"N2E\", \"E2N\"",
                                          "\"size\": 4097",
                                          "\"size\": 3"};

std::string mutate(const std::string& text, std::mt19937& rng) {
  std::string s = text;
  const auto pick = [&](std::size_t n) { return n == 0 ? std::size_t{0} : static_cast<std::size_t>(rng() % n); };
  const int rounds = 1 + static_cast<int>(rng() % 4);
  for (int k = 0; k < rounds; ++k) {
    const std::size_t at = pick(s.size() + 1);
    switch (rng() % 6) {
      case 0:  // flip a byte
        if (!s.empty()) s[pick(s.size())] = static_cast<char>(rng() & 0xff);
        break;
      case 1:  // insert a byte
        s.insert(at, 1, static_cast<char>(rng() & 0xff));
        break;
      case 2:  // insert a token
        s.insert(at, kTokens[pick(kTokens.size())]);
        break;
      case 3:  // delete a range
        s.erase(at, 1 + pick(16));
        break;
      case 4:  // truncate
        s.resize(at);
        break;
      default: {  // duplicate a chunk elsewhere
        const std::size_t from = pick(s.size() + 1);
        const std::string chunk = s.substr(from, 1 + pick(40));
        s.insert(pick(s.size() + 1), chunk);
      }
    }
  }
  return s;
}

/// Lengths of the lines of a text (bytes, without the newline).
std::vector<std::size_t> line_lengths(const std::string& text) {
  std::vector<std::size_t> out{0};
  for (const char c : text) {
    if (c == '\n')
      out.push_back(0);
    else
      ++out.back();
  }
  return out;
}

class Checker {
public:
  /// Loads `text` as `name`; checks the invariants; returns whether it loaded without errors.
  bool check(const std::string& text, const std::string& name) {
    LoadResult r;
    EXPECT_NO_THROW(r = load_system_from_text(text, name, builtin_registry()));
    EXPECT_EQ(r.system.has_value(), r.ok());
    for (const Diagnostic& d : r.diagnostics) {
      EXPECT_EQ(d.message.find("internal error"), std::string::npos) << d.message;
      EXPECT_FALSE(d.message.empty());
      EXPECT_TRUE(d.pointer.empty() || d.pointer[0] == '/') << d.pointer;
      const std::vector<std::size_t>& lines = d.where.file == name ? line_lengths(text) : file_lines(d.where.file);
      const bool inside =
          d.where.line >= 1 && static_cast<std::size_t>(d.where.line) <= lines.size() && d.where.column >= 1 &&
          static_cast<std::size_t>(d.where.column) <= lines[static_cast<std::size_t>(d.where.line) - 1] + 1;
      EXPECT_TRUE(inside) << format(d);
      if (!inside) return false;
    }
    if (r.system) {
      Coordinator co("fuzz");
      Monitor monitor(co, builtin_registry(), 4);
      const auto made = instantiate(*r.system, co, monitor);
      EXPECT_TRUE(made) << "loaded without errors but does not instantiate: " << made.error().message << "\n" << text;
      ++loaded_;
    }
    return r.ok();
  }
  int loaded() const { return loaded_; }

private:
  const std::vector<std::size_t>& file_lines(const std::string& path) {
    auto it = cache_.find(path);
    if (it == cache_.end()) it = cache_.emplace(path, line_lengths(read_text(path))).first;
    return it->second;
  }
  std::map<std::string, std::vector<std::size_t>> cache_;
  int loaded_ = 0;
};

TEST(SpecSmokeFuzz, MutatedGoodSpecsNeverCrashAndAlwaysPointInsideTheText) {
  std::mt19937 rng(20160516);  // fixed: the run is the same every time
  Checker checker;
  constexpr int kRuns = 10000;
  for (int i = 0; i < kRuns; ++i) {
    const std::string& seed = kSeeds[static_cast<std::size_t>(i) % kSeeds.size()];
    static std::map<std::string, std::string> texts;
    if (texts.count(seed) == 0) texts[seed] = read_text(seed);
    checker.check(mutate(texts[seed], rng), seed);
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_GT(checker.loaded(), 0);  // some mutants are still valid specs
}

/// Writes a json::JsonValue back as text (for the type-substitution run).
void write(const json::JsonValue& v, std::string& out) {
  switch (v.type) {
    case json::JsonValue::Type::Null: out += "null"; return;
    case json::JsonValue::Type::Bool: out += v.boolean ? "true" : "false"; return;
    case json::JsonValue::Type::Number: out += std::to_string(v.number); return;
    case json::JsonValue::Type::String: out += json::json_string(v.string); return;
    case json::JsonValue::Type::Array:
      out += "[";
      for (std::size_t i = 0; i < v.array.size(); ++i) {
        if (i) out += ", ";
        write(v.array[i], out);
      }
      out += "]";
      return;
    case json::JsonValue::Type::Object:
      out += "{";
      for (std::size_t i = 0; i < v.object.size(); ++i) {
        if (i) out += ", ";
        out += json::json_string(v.object[i].key) + ": ";
        write(v.object[i].value, out);
      }
      out += "}";
      return;
  }
}

void collect(json::JsonValue& v, std::vector<json::JsonValue*>& out) {
  out.push_back(&v);
  for (json::JsonValue& item : v.array) collect(item, out);
  for (json::JsonMember& m : v.object) collect(m.value, out);
}

TEST(SpecSmokeFuzz, EveryValueReplacedByEveryOtherTypeIsReportedNotCrashed) {
  const std::vector<std::string> replacements = {"null",    "0",  "-1",  "1e300", "2.5", "\"\"",
                                                 "\"x.y\"", "[]", "[1]", "{}",    "true"};
  Checker checker;
  for (const std::string& seed :
       {std::string("tests/data/good_specs/jr3.json"), std::string("tests/data/good_specs/robodoc.json")}) {
    const json::JsonParse parsed = json::parse_json(read_text(seed));
    ASSERT_TRUE(parsed.value);
    std::vector<json::JsonValue*> nodes;
    json::JsonValue copy = *parsed.value;
    collect(copy, nodes);
    for (std::size_t n = 1; n < nodes.size(); ++n) {
      for (const std::string& replacement : replacements) {
        json::JsonValue doc = *parsed.value;
        std::vector<json::JsonValue*> targets;
        collect(doc, targets);
        *targets[n] = *json::parse_json(replacement).value;
        std::string text;
        write(doc, text);
        checker.check(text, seed);
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
}

}  // namespace
}  // namespace safecass::spec
