// docs/scenario-format.md and the scenario reader agree. The reader lists the keys it accepts in
// one table (spec::scenario_keys()), which it also checks files against; this test checks the page
// against that table (each key has a row in the field table of its section, and no row names a key
// the reader refuses), finds a section for every step kind, compares the diagnostics the page shows
// with the reader's, and runs every complete example of the page (a ```json scenario block)
// against its system: each loads without a diagnostic and passes, and together they use every
// step kind.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/filters/registry.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::spec {
namespace {

const std::string kSourceDir = SAFECASS_SOURCE_DIR;
const std::string kDoc = "docs/scenario-format.md";

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

const std::string& doc() {
  static const std::string text = read_text(kSourceDir + "/" + kDoc);
  return text;
}

/// One heading of the page and its own text, up to the next heading of any level (a section's
/// subsections are sections of their own).
struct Section {
  std::string heading;
  std::string text;
};

/// The page's sections; lines in fenced blocks are text, never headings.
std::vector<Section> sections() {
  std::vector<Section> out;
  std::istringstream lines(doc());
  bool fenced = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (!fenced && line.rfind('#', 0) == 0) {
      out.push_back(Section{line, ""});
    } else if (!out.empty()) {
      out.back().text += line + "\n";
    }
  }
  return out;
}

/// What the heading of the section documenting `object` (a scenario_keys() object) contains.
std::string heading_of(std::string_view object) {
  if (object == "scenario") return "Top-level keys";
  if (object == "step") return "Steps";
  return "`" + std::string(object) + "`";
}

/// The sections whose heading contains `needle`.
std::vector<Section> sections_titled(const std::string& needle) {
  std::vector<Section> out;
  for (Section& s : sections()) {
    if (s.heading.find(needle) != std::string::npos) out.push_back(std::move(s));
  }
  return out;
}

/// The keys of the field table of a section: the first cells written `key` (rows "| `key` | ...").
std::vector<std::string> table_keys(const std::string& text) {
  static const std::regex row_pattern(R"(^\| `([^`]+)` \|)");
  std::vector<std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, row_pattern)) out.push_back(m[1]);
  }
  return out;
}

/// A complete example of the page: its text and the line of its opening fence.
struct Example {
  std::string text;
  int line = 0;
};

std::vector<Example> examples() {
  std::vector<Example> out;
  std::istringstream lines(doc());
  int number = 0;
  bool inside = false;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    if (!inside && line == "```json scenario") {
      inside = true;
      out.push_back(Example{"", number});
    } else if (inside && line.rfind("```", 0) == 0) {
      inside = false;
    } else if (inside) {
      out.back().text += line + "\n";
    }
  }
  return out;
}

/// The example written to a file of its own (the reader reads files), removed with this object.
struct ExampleFile {
  std::string path;
  ExampleFile(const Example& e, std::size_t index)
      : path((std::filesystem::path(::testing::TempDir()) /
              ("scenario_format_doc_" + std::to_string(::getpid()) + "_" + std::to_string(index) + ".json"))
                 .string()) {
    std::ofstream(path) << e.text;
  }
  ~ExampleFile() { std::remove(path.c_str()); }
  ExampleFile(const ExampleFile&) = delete;
  ExampleFile& operator=(const ExampleFile&) = delete;
};

/// The example's "system" as written: a path relative to the source root.
std::string system_of(const Example& e) {
  static const std::regex system_pattern(R"re("system"\s*:\s*"([^"]+)")re");
  std::smatch m;
  return std::regex_search(e.text, m, system_pattern) ? std::string(m[1]) : std::string();
}

std::string where(const Example& e) { return kDoc + ":" + std::to_string(e.line) + ": the example here"; }

/// A message that starts with "FILE:LINE:" of the example's file, as the page's "DOC:LINE:".
std::string in_doc(const std::string& message, const ExampleFile& file, const Example& e) {
  if (message.rfind(file.path + ":", 0) != 0) return message;
  const std::size_t at = file.path.size() + 1;
  const std::size_t colon = message.find(':', at);
  if (colon == std::string::npos) return message;
  const int line = std::atoi(message.substr(at, colon - at).c_str());
  return kDoc + ":" + std::to_string(e.line + line) + message.substr(colon);
}

std::string step_kinds_text(const std::set<std::string>& kinds) {
  std::string out;
  for (const std::string& k : kinds) out += (out.empty() ? "" : ", ") + k;
  return out;
}

/// The step kinds: the keys of a step but "at".
std::set<std::string> every_step_kind() {
  std::set<std::string> out;
  for (const ScenarioKeySet& set : scenario_keys()) {
    if (set.object != "step") continue;
    for (std::string_view k : set.keys) {
      if (k != "at") out.emplace(k);
    }
  }
  return out;
}

TEST(ScenarioFormatDoc, TheReadersKeyTableHasTheTopLevelAStepAndEveryStepKind) {
  std::set<std::string> objects;
  for (const ScenarioKeySet& set : scenario_keys()) objects.emplace(set.object);
  EXPECT_TRUE(objects.count("scenario"));
  EXPECT_TRUE(objects.count("step"));
  const std::set<std::string> kinds = every_step_kind();
  for (const auto kind : {ScenarioStep::Kind::Sample, ScenarioStep::Kind::Ramp, ScenarioStep::Kind::Generate,
                          ScenarioStep::Kind::Inject, ScenarioStep::Kind::Reset, ScenarioStep::Kind::Expect,
                          ScenarioStep::Kind::ExpectOutstanding, ScenarioStep::Kind::ExpectCause}) {
    EXPECT_TRUE(kinds.count(std::string(step_key(kind)))) << step_key(kind) << " is not a key of a step";
  }
}

TEST(ScenarioFormatDoc, DocumentsEveryKeyTheReaderAcceptsInTheTableOfItsSection) {
  ASSERT_FALSE(doc().empty()) << kDoc << " cannot be read";
  for (const ScenarioKeySet& set : scenario_keys()) {
    const std::vector<Section> found = sections_titled(heading_of(set.object));
    ASSERT_EQ(found.size(), 1u) << kDoc << ": one heading should contain '" << heading_of(set.object)
                                << "', the section of \"" << set.object << "\"";
    const std::vector<std::string> rows = table_keys(found[0].text);
    for (std::string_view key : set.keys) {
      EXPECT_THAT(rows, ::testing::Contains(std::string(key)))
          << kDoc << ": section '" << found[0].heading << "' has no row | `" << key << "` | for the key \"" << key
          << "\" that the reader accepts in \"" << set.object << "\"";
    }
  }
}

TEST(ScenarioFormatDoc, DocumentsNoKeyTheReaderRefuses) {
  for (const ScenarioKeySet& set : scenario_keys()) {
    for (const Section& s : sections_titled(heading_of(set.object))) {
      for (const std::string& row : table_keys(s.text)) {
        EXPECT_THAT(set.keys, ::testing::Contains(std::string_view(row)))
            << kDoc << ": section '" << s.heading << "' documents \"" << row << "\", which the reader refuses in \""
            << set.object << "\"";
      }
    }
  }
}

TEST(ScenarioFormatDoc, EveryStepKindHasItsSection) {
  for (const std::string& kind : every_step_kind()) {
    EXPECT_EQ(sections_titled("`" + kind + "`").size(), 1u)
        << kDoc << ": the step kind \"" << kind << "\" needs one section whose heading names `" << kind << "`";
  }
}

TEST(ScenarioFormatDoc, StatesTheReadersDefaultPeriod) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", Scenario{}.period);
  const std::vector<Section> top = sections_titled(heading_of("scenario"));
  ASSERT_EQ(top.size(), 1u);
  std::istringstream lines(top[0].text);
  std::string row;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| `period` |", 0) == 0) row = line;
  }
  EXPECT_THAT(row, ::testing::HasSubstr("`" + std::string(text) + "`"))
      << kDoc << ": the row of \"period\" should give the reader's default, " << text << " s";
}

TEST(ScenarioFormatDoc, EveryExampleLoadsWithoutADiagnosticRunsAndPasses) {
  const std::vector<Example> all = examples();
  ASSERT_GE(all.size(), 3u) << kDoc << ": its complete examples are the blocks that open with ```json scenario";
  FilterRegistry registry;
  register_builtin_filters(registry);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Example& e = all[i];
    SCOPED_TRACE(where(e));
    const std::string system = system_of(e);
    ASSERT_FALSE(system.empty()) << "the example names no \"system\"";
    EXPECT_TRUE(std::filesystem::path(system).is_relative()) << "\"system\" should be relative to the source root";
    const std::string system_path = std::filesystem::path(kSourceDir).append(system).string();
    ASSERT_TRUE(std::filesystem::is_regular_file(system_path))
        << "\"" << system << "\" is not a file of the source tree";
    const ExampleFile file(e, i);
    const ScenarioLoad load = load_scenario(file.path);
    for (const Diagnostic& d : load.diagnostics) ADD_FAILURE() << in_doc(format(d), file, e);
    // The system as the page says: relative to the source root, not to the example's file.
    auto runner = runner::ScenarioRunner::open(runner::ScenarioSource{file.path, system_path}, registry);
    if (!runner) {
      for (const Diagnostic& d : runner.error()) ADD_FAILURE() << in_doc(format(d), file, e);
      continue;
    }
    runner::RunOptions options;
    options.quiet = true;
    const runner::RunResult result = (*runner)->run(options);
    EXPECT_GT(result.checks, 0) << "an example checks something: it needs an expectation";
    for (const std::string& f : result.failures) ADD_FAILURE() << in_doc(f, file, e);
  }
}

/// The fenced blocks of a text, in order, without their fences.
std::vector<std::string> blocks(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream lines(text);
  bool inside = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("```", 0) == 0) {
      inside = !inside;
      if (inside) out.emplace_back();
    } else if (inside) {
      out.back() += line + "\n";
    }
  }
  return out;
}

TEST(ScenarioFormatDoc, TheDiagnosticsItShowsAreTheReadersOwn) {
  // "Before the run" shows a scenario with a mistake on each line, then what `safecass run` says
  // of it, run next to its system (examples/robodoc/): the same file must give the same lines.
  const std::vector<Section> found = sections_titled("Before the run");
  ASSERT_EQ(found.size(), 1u) << kDoc << ": one heading should contain 'Before the run'";
  const std::vector<std::string> shown = blocks(found[0].text);
  ASSERT_GE(shown.size(), 2u) << kDoc << ": 'Before the run' should show a scenario, then its diagnostics";
  std::string expected;
  std::istringstream lines(shown[1]);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("$ ", 0) != 0) expected += line + "\n";
  }
  const std::string name = expected.substr(0, expected.find(':'));
  ASSERT_FALSE(name.empty());
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / ("scenario_format_doc_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << shown[0];
  FilterRegistry registry;
  register_builtin_filters(registry);
  std::string actual;
  for (const Diagnostic& d : runner::check_scenario(path, registry, kSourceDir + "/examples/robodoc/robodoc.json")) {
    actual += format(d).substr(dir.string().size() + 1) + "\n";
  }
  std::filesystem::remove_all(dir);
  EXPECT_EQ(actual, expected) << kDoc << ": the diagnostics shown under 'Before the run' are not the reader's";
}

TEST(ScenarioFormatDoc, TheExamplesUseEveryStepKind) {
  std::set<std::string> used;
  const std::vector<Example> all = examples();
  for (std::size_t i = 0; i < all.size(); ++i) {
    const ExampleFile file(all[i], i);
    const ScenarioLoad load = load_scenario(file.path);
    const std::optional<Scenario>& read = load.scenario ? load.scenario : load.partial;
    if (!read) continue;
    for (const ScenarioStep& s : read->steps) used.emplace(step_key(s.kind));
  }
  std::set<std::string> missing;
  for (const std::string& kind : every_step_kind()) {
    if (!used.count(kind)) missing.insert(kind);
  }
  EXPECT_TRUE(missing.empty()) << kDoc << ": no complete example (```json scenario) uses " << step_kinds_text(missing);
}

}  // namespace
}  // namespace safecass::spec
