// `safecass timeline`: history → model (golden file), malformed lines, empty history, determinism,
// and the page being one self-contained file.
//
// The golden model is tests/data/timeline/small.expected.json. After an intended change of the
// model, regenerate it with SAFECASS_UPDATE_GOLDEN=1 ./build/bin/test_tools and review the diff.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "safecass/introspect/format.hpp"
#include "safecass/json/read.hpp"
#include "safecass/timeline/timeline.hpp"

namespace safecass::tools {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

/// Every test runs in the source root (ctest does too; this covers running the binary by hand).
class SourceRoot : public ::testing::Environment {
public:
  void SetUp() override { std::filesystem::current_path(SAFECASS_SOURCE_DIR); }
};
const auto* const kRoot = ::testing::AddGlobalTestEnvironment(new SourceRoot);

constexpr const char* kSmall = "tests/data/timeline/small.jsonl";
constexpr const char* kSmallModel = "tests/data/timeline/small.expected.json";

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<timeline::HistoryRecord> parse_ok(std::string_view text) {
  timeline::HistoryParse p = timeline::parse_history(text);
  for (const timeline::HistoryError& e : p.errors) ADD_FAILURE() << "line " << e.line << ": " << e.message;
  return std::move(p.records);
}

/// The text of the <script type="application/json" id="ID"> element of a page.
std::string script_data(const std::string& page, const std::string& id) {
  const std::string open = "<script type=\"application/json\" id=\"" + id + "\">";
  const auto begin = page.find(open);
  if (begin == std::string::npos) return "(no element " + id + ")";
  const auto end = page.find("</script>", begin);
  return page.substr(begin + open.size(), end - begin - open.size());
}

/// A directory of this test's own: ctest runs each case as its own process, several at once, and
/// a case removes its directory when it ends.
std::filesystem::path temp_dir() {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = std::filesystem::temp_directory_path() /
                   ("safecass_timeline_test_" + std::to_string(::getpid()) + "_" + test->name());
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(Timeline, GoldenHistoryGivesTheExpectedLanesBarsAndMarkers) {
  const std::string model = timeline::timeline_model_json(parse_ok(read_text(kSmall)));
  if (std::getenv("SAFECASS_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(kSmallModel, std::ios::binary) << model << '\n';
  }
  EXPECT_EQ(model + '\n', read_text(kSmallModel));
}

TEST(Timeline, RecordsTakenFromMemoryDrawTheSamePageAsTheirHistoryLines) {
  // A live coordinator's history and a trace's run are drawn from their records (records_of),
  // with no JSON text in between: the same model as the history file of those records.
  std::vector<introspect::HistoryEntry> entries;
  for (const timeline::HistoryRecord& r : parse_ok(read_text(kSmall))) {
    if (!r.overflow) entries.push_back(r.entry);
  }
  ASSERT_GT(entries.size(), 10u);
  std::string lines;
  for (const introspect::HistoryEntry& e : entries) lines += introspect::history_json(e) + "\n";
  const std::vector<timeline::HistoryRecord> from_text = parse_ok(lines);
  const std::vector<timeline::HistoryRecord> from_memory = timeline::records_of(entries);
  EXPECT_EQ(timeline::timeline_model_json(from_memory), timeline::timeline_model_json(from_text));
  // The page embeds each record as its history line (the file's numbers, not their shortest form).
  const std::string page = timeline::render_timeline_page(from_memory, "t");
  for (const introspect::HistoryEntry& e : entries) EXPECT_THAT(page, HasSubstr(introspect::history_json(e)));
}

TEST(Timeline, ModelIsValidJsonWithOneLanePerMachineAndOnePerComponent) {
  const auto parsed = json::parse_json(timeline::timeline_model_json(parse_ok(read_text(kSmall))));
  ASSERT_TRUE(parsed.value) << parsed.error->message;
  const json::JsonValue& groups = *parsed.value->find("groups");
  ASSERT_EQ(groups.array.size(), 2u);
  // Components in order of first appearance; inside one, the extended state first, then s_F, s_A, s_P, s_R.
  EXPECT_EQ(groups.array[0].find("component")->string, "JR3");
  const auto& jr3 = groups.array[0].find("lanes")->array;
  ASSERT_EQ(jr3.size(), 3u);
  EXPECT_EQ(jr3[0].find("address")->string, "JR3");
  EXPECT_EQ(jr3[0].find("kind")->string, "component");
  EXPECT_EQ(jr3[1].find("address")->string, "JR3.s_F");
  EXPECT_EQ(jr3[2].find("address")->string, "JR3.s_A");
  const auto& control = groups.array[1].find("lanes")->array;
  ASSERT_EQ(control.size(), 3u);
  EXPECT_EQ(control[1].find("address")->string, "CONTROL.s_A");
  EXPECT_EQ(control[2].find("address")->string, "CONTROL.s_R.ForceData");
  EXPECT_EQ(parsed.value->find("transitions")->number, 12.0);
}

TEST(Timeline, MarkerTooltipsGiveTheEventRootCauseSampleAndReason) {
  const std::string model = timeline::timeline_model_json(parse_ok(read_text(kSmall)));
  EXPECT_THAT(model, HasSubstr("Ignored completion /EVT_FORCE_ERROR\\nJR3.s_A, t = 0.35 s (history line 14)"));
  EXPECT_THAT(model, HasSubstr("root cause JR3.s_A:EVT_FORCE_ERROR at 0.2 s\\n"
                               "filter force_limit, JR3.ForceNorm = 50 (sample at 0.2 s), injected sample"));
  EXPECT_THAT(model, HasSubstr("reason: latched: needs reset"));
  EXPECT_THAT(model, HasSubstr("Fault injection\\nJR3.s_A, t = 0.2 s (history line 5)\\n"
                               "shallow injection into filter force_limit: 50 50"));
  EXPECT_THAT(model, HasSubstr("{\"kind\":\"masked\",\"t\":0.3,\"line\":13,\"event\":\"EVT_DRIFT\""));
  EXPECT_THAT(model, HasSubstr("{\"kind\":\"reset\",\"t\":0.4,\"line\":16"));
  // A reset, not an event, ended JR3.s_A's Error: the Normal bar after it says so.
  EXPECT_THAT(model, HasSubstr("Normal\\n0.4 s to the end of the history\\nentered by a reset (history line 19)\\n"
                               "reason: operator: force sensor checked\\nclears root cause JR3.s_A:EVT_FORCE_ERROR"));
}

TEST(Timeline, OverflowLineBecomesAWarningBandBetweenItsNeighbours) {
  const auto records = parse_ok(read_text(kSmall));
  const std::string model = timeline::timeline_model_json(records);
  EXPECT_THAT(model, HasSubstr("{\"line\":12,\"dropped\":3,\"from\":0.2,\"to\":0.3,"));
  const std::string page = timeline::render_timeline_page(records, "small.jsonl");
  EXPECT_THAT(page, HasSubstr("History line 12: the recorder dropped 3 records between 0.2 s and 0.3 s"));
}

TEST(Timeline, PageEmbedsTheModelAndEveryHistoryLineAsAJsonArray) {
  const auto records = parse_ok(read_text(kSmall));
  const std::string page = timeline::render_timeline_page(records, "small.jsonl");
  EXPECT_EQ(script_data(page, "timeline-model"), timeline::timeline_model_json(records));
  const auto history = json::parse_json(script_data(page, "timeline-history"));
  ASSERT_TRUE(history.value) << history.error->message;
  ASSERT_TRUE(history.value->is_array());
  ASSERT_EQ(history.value->array.size(), 27u);
  EXPECT_EQ(history.value->array[11].find("kind")->string, "overflow");
  EXPECT_EQ(history.value->array[13].find("text")->string, "latched: needs reset");
  EXPECT_THAT(page, HasSubstr("<title>SAFECASS timeline: small.jsonl</title>"));
  EXPECT_THAT(page, HasSubstr("27 records, 12 transitions, 6 lanes in 2 components, from 0 s to 0.55 s."));
}

TEST(Timeline, PageIsOneSelfContainedFileWithInlineStyleAndScript) {
  const std::string page = timeline::render_timeline_page(parse_ok(read_text(kSmall)), "small.jsonl");
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_THAT(page, HasSubstr("</html>"));
  EXPECT_THAT(page, HasSubstr("<style>"));
  EXPECT_THAT(page, HasSubstr("function render()"));
  EXPECT_THAT(page, Not(HasSubstr("{{")));  // every placeholder filled
  EXPECT_THAT(page, Not(HasSubstr("<link")));
  EXPECT_THAT(page, Not(HasSubstr(" src=")));
  EXPECT_THAT(page, Not(HasSubstr("@import")));
  EXPECT_THAT(page, Not(HasSubstr("https:")));
  EXPECT_THAT(page, Not(HasSubstr("fetch(")));
  EXPECT_THAT(page, Not(HasSubstr("XMLHttpRequest")));
}

TEST(Timeline, TextFromTheHistoryCannotBreakOutOfThePage) {
  const std::string line =
      R"({"t":0.1,"kind":"injection","machine":"X.s_A","text":"</script><script>alert(1)</script>"})";
  const std::string page = timeline::render_timeline_page(parse_ok(line), "<b>.jsonl");
  EXPECT_THAT(page, Not(HasSubstr("<script>alert")));
  EXPECT_THAT(page, Not(HasSubstr("<b>.jsonl")));
  EXPECT_THAT(page, HasSubstr("&lt;b&gt;.jsonl"));
  EXPECT_THAT(page, HasSubstr("\\u003c/script\\u003e\\u003cscript\\u003ealert(1)"));
}

TEST(Timeline, MalformedLinesAreErrorsNamingTheirLineNumbers) {
  const std::string text =
      "{\"t\":0.1,\"kind\":\"transition\",\"machine\":\"A.s_A\",\"from\":\"Normal\",\"to\":\"Error\"}\n"  // 1 good
      "{\"t\":0.2,\"kind\":\"transition\"\n"                                                              // 2 truncated
      "[1,2]\n"                                                                           // 3 not an object
      "{\"t\":0.3,\"kind\":\"heartbeat\"}\n"                                              // 4 unknown kind
      "{\"kind\":\"reset\",\"machine\":\"A.s_A\",\"from\":\"Error\",\"to\":\"Error\"}\n"  // 5 no time
      "{\"t\":0.4,\"kind\":\"transition\",\"machine\":\"A.s_A\",\"from\":\"Error\",\"to\":\"Red\"}\n"  // 6 bad state
      "\n"                                                                                             // 7 empty
      "{\"t\":0.05,\"kind\":\"injection\",\"machine\":\"A.s_A\"}\n"  // 8 time goes back
      "{\"kind\":\"overflow\",\"dropped\":-2}\n"                     // 9 bad count
      "{\"t\":0.5,\"kind\":\"event\",\"outcome\":\"vanished\",\"machine\":\"A.s_A\",\"from\":\"Error\",\"to\":"
      "\"Error\"}\n"
      "{\"t\":0.6,\"kind\":\"transition\",\"from\":\"Error\",\"to\":\"Normal\"}\n"  // 11 no machine
      "{\"t\":0.7,\"kind\":\"event\",\"outcome\":\"masked\",\"machine\":\"A.s_A\",\"from\":\"Error\",\"to\":\"Error\","
      "\"root\":3}";
  const timeline::HistoryParse p = timeline::parse_history(text);
  ASSERT_EQ(p.errors.size(), 11u);
  const std::vector<std::pair<int, std::string>> expected{
      {2, "invalid JSON at column"},
      {3, "expected a JSON object (one record per line), not array"},
      {4, "unknown record kind \"heartbeat\""},
      {5, "missing \"t\""},
      {6, "\"to\" must be Normal, Warning or Error, not \"Red\""},
      {7, "empty line"},
      {8, "time 0.05 s is earlier than the previous record's (0.1 s)"},
      {9, "\"dropped\" must be a whole number of records, not -2"},
      {10, "unknown outcome \"vanished\""},
      {11, "missing \"machine\""},
      {12, "\"root\" must be an object, not number"},
  };
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(p.errors[i].line, expected[i].first);
    EXPECT_THAT(p.errors[i].message, HasSubstr(expected[i].second)) << "line " << expected[i].first;
  }
  ASSERT_EQ(p.records.size(), 1u);
  EXPECT_EQ(p.records[0].line, 1);
}

TEST(Timeline, TornLastLineOfAKilledProcessIsSetAsideAndEveryCompleteRecordIsKept) {
  const std::string good = read_text(kSmall);
  const timeline::HistoryParse complete = timeline::parse_history(good);
  const timeline::HistoryParse p = timeline::parse_history(good + "{\"seq\":99,\"t\":0.6,\"ki");
  EXPECT_TRUE(p.errors.empty());
  ASSERT_TRUE(p.torn.has_value());
  EXPECT_EQ(p.torn->line, 28);
  EXPECT_THAT(p.torn->message, HasSubstr("invalid JSON at column 19: unterminated string"));
  EXPECT_EQ(p.records.size(), complete.records.size());
  EXPECT_EQ(timeline::timeline_model_json(p.records), timeline::timeline_model_json(complete.records));
}

TEST(Timeline, AMalformedLineThatIsNotTheLastIsStillAnErrorWhenTheLastIsTorn) {
  const timeline::HistoryParse p = timeline::parse_history(
      "{\"t\":0.1,\"kind\":\"reset\",\"machine\":\"A.s_A\",\"from\":\"Normal\",\"to\":\"Normal\"}\n"
      "{\"t\":0.2,\"kind\":\"res\n"  // cut short, but a line follows: an error, not a torn line
      "{\"t\":0.3,\"kind\":\"reset\",\"machine\":\"A.s_A\",\"from\":\"Normal\",\"to\":\"Normal\"}\n"
      "{\"t\":0.4,\"ki");
  ASSERT_EQ(p.errors.size(), 1u);
  EXPECT_EQ(p.errors[0].line, 2);
  ASSERT_TRUE(p.torn.has_value());
  EXPECT_EQ(p.torn->line, 4);
  EXPECT_EQ(p.records.size(), 2u);
}

TEST(Timeline, ALastLineWithoutNewlineThatIsCompleteIsARecordAndABadOneAnError) {
  const timeline::HistoryParse good = timeline::parse_history(
      "{\"t\":0.1,\"kind\":\"reset\",\"machine\":\"A.s_A\",\"from\":\"Normal\",\"to\":\"Normal\"}");
  EXPECT_TRUE(good.errors.empty());
  EXPECT_FALSE(good.torn.has_value());
  EXPECT_EQ(good.records.size(), 1u);
  const timeline::HistoryParse bad = timeline::parse_history("{\"t\":0.1,\"kind\":\"heartbeat\"}");
  ASSERT_EQ(bad.errors.size(), 1u) << "valid JSON is not torn: a wrong record stays an error";
  EXPECT_FALSE(bad.torn.has_value());
}

TEST(Timeline, CommandDrawsAHistoryWithATornLastLineAndWarnsOnceNamingFileAndLine) {
  const auto dir = temp_dir();
  const auto history = dir / "killed.jsonl";
  const std::string good = read_text(kSmall);
  std::ofstream(history, std::ios::binary) << good << "{\"seq\":99,\"t\":0.6,\"kind\":\"trans";
  const auto page = dir / "killed.html";
  ::testing::internal::CaptureStderr();
  const int code = timeline::run_timeline(history.string(), page.string());
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 0);
  EXPECT_THAT(err, HasSubstr(history.string() + ":28: warning: the last line is torn"));
  EXPECT_THAT(err, HasSubstr("drawing the 27 complete records before it"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  const std::string html = read_text(page.string());
  EXPECT_THAT(html, HasSubstr("History line 28 is torn"));
  const timeline::HistoryParse complete = timeline::parse_history(good);
  EXPECT_EQ(script_data(html, "timeline-model"),
            script_data(timeline::render_timeline_page(complete.records, "killed.jsonl"), "timeline-model"))
      << "every complete record is drawn";
  std::filesystem::remove_all(dir);
}

TEST(Timeline, CommandExitsTwoWithFileAndLineForABadHistoryAndWritesNoPage) {
  const auto dir = temp_dir();
  const auto history = dir / "bad.jsonl";
  std::ofstream(history)
      << "{\"t\":0.1,\"kind\":\"reset\",\"machine\":\"A.s_A\",\"from\":\"Normal\",\"to\":\"Normal\"}\n"
         "not json\n";
  const auto page = dir / "bad.html";
  ::testing::internal::CaptureStderr();
  const int code = timeline::run_timeline(history.string(), page.string());
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 2);
  EXPECT_THAT(err, HasSubstr(history.string() + ":2: error: invalid JSON at column 1"));
  EXPECT_FALSE(std::filesystem::exists(page));
  std::filesystem::remove_all(dir);
}

TEST(Timeline, CommandExitsTwoWhenTheHistoryCannotBeReadOrThePageCannotBeWritten) {
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(timeline::run_timeline("tests/data/timeline/no-such-history.jsonl", "/dev/null"), 2);
  EXPECT_EQ(timeline::run_timeline(kSmall, "tests/data/timeline/no-such-dir/page.html"), 2);
  EXPECT_EQ(timeline::run_timeline("/dev/zero", "/dev/null"), 2);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(err, HasSubstr("cannot read file '/dev/zero': not a regular file (a character device)"));
  EXPECT_THAT(err, HasSubstr("history: cannot read file 'tests/data/timeline/no-such-history.jsonl': no such file"));
  EXPECT_THAT(err, HasSubstr("cannot write 'tests/data/timeline/no-such-dir/page.html'"));
}

TEST(Timeline, EmptyHistoryGivesAValidPageSayingNoTransitions) {
  const timeline::HistoryParse p = timeline::parse_history("");
  EXPECT_TRUE(p.errors.empty());
  EXPECT_TRUE(p.records.empty());
  const std::string page = timeline::render_timeline_page(p.records, "empty.jsonl");
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_THAT(page, HasSubstr("</html>"));
  EXPECT_THAT(page, HasSubstr("The history is empty: no transitions."));
  EXPECT_EQ(script_data(page, "timeline-history"), "[]");
  const auto model = json::parse_json(script_data(page, "timeline-model"));
  ASSERT_TRUE(model.value) << model.error->message;
  EXPECT_EQ(model.value->find("transitions")->number, 0.0);
  EXPECT_TRUE(model.value->find("groups")->array.empty());
}

TEST(Timeline, HistoryWithRecordsButNoTransitionSaysSo) {
  const auto records = parse_ok(
      R"({"t":1.5,"kind":"event","outcome":"ignored","machine":"A.s_A","event":"/E","from":"Normal","to":"Normal","text":"not active"})");
  EXPECT_THAT(timeline::render_timeline_page(records, "h"),
              HasSubstr("1 record, no transitions, 2 lanes in 1 component"));
}

TEST(Timeline, TwoRendersOfTheSameHistoryAreByteIdentical) {
  const auto dir = temp_dir();
  const auto a = dir / "a.html";
  const auto b = dir / "b.html";
  ASSERT_EQ(timeline::run_timeline(kSmall, a.string()), 0);
  ASSERT_EQ(timeline::run_timeline(kSmall, b.string()), 0);
  const std::string first = read_text(a.string());
  EXPECT_FALSE(first.empty());
  EXPECT_EQ(first, read_text(b.string()));
  EXPECT_EQ(first, timeline::render_timeline_page(parse_ok(read_text(kSmall)), "small.jsonl"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace safecass::tools
