// The read model's text of numbers and times (introspect/format.hpp), which every tool prints, and
// the named reads (introspect/local_query.hpp) a live coordinator answers through one request.

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/json/read.hpp"

namespace safecass::introspect {
namespace {

TEST(SecondsText, HasSixDecimalsAsInTheHistoryFile) {
  EXPECT_EQ(seconds_text(Time{std::chrono::seconds(12)}), "12.000000");
  EXPECT_EQ(seconds_text(Time{std::chrono::microseconds(301000)}), "0.301000");
}

TEST(NumberText, HasAtMostNineSignificantDigitsAndNamesNonFiniteValues) {
  EXPECT_EQ(number_text(30.0), "30");
  EXPECT_EQ(number_text(1.0 / 3.0), "0.333333333");
  EXPECT_EQ(number_text(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(number_text(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(MarkupText, EscapesTheFiveMarkupCharactersAndCopiesEveryOtherByte) {
  EXPECT_EQ(markup_text("a<b>&\"c'd"), "a&lt;b&gt;&amp;&quot;c&#39;d");
  EXPECT_EQ(markup_text("JR3.s_A \xc2\xb0 \n"), "JR3.s_A \xc2\xb0 \n");
  EXPECT_EQ(markup_text(""), "");
}

StateSummary robodoc_in_trouble() {
  StateSummary s;
  s.system = State::Error;
  s.normal = 3;
  s.warning = 1;
  s.error = 1;
  s.not_normal = {{"BMM", State::Warning, "EVT_BONE_MOTION"}, {"JR3", State::Error, ""}};
  return s;
}

TEST(StateSummary, ItsTextCountsTheComponentsByStateAndListsThoseNotNormal) {
  EXPECT_EQ(state_summary_text(robodoc_in_trouble()),
            "SYSTEM Error: 5 components, 3 Normal, 1 Warning, 1 Error\n"
            "  BMM  Warning  EVT_BONE_MOTION\n"
            "  JR3  Error    -\n");
  EXPECT_EQ(state_summary_text(StateSummary{State::Normal, 1, 0, 0, {}}),
            "SYSTEM Normal: 1 component, 1 Normal, 0 Warning, 0 Error\n");
}

TEST(StateSummary, ItsJsonIsOneLineThatReadsBackToTheSameValue) {
  const std::string json = state_summary_json(robodoc_in_trouble());
  EXPECT_EQ(json, R"({"system":"Error","normal":3,"warning":1,"error":1,"not_normal":[)"
                  R"({"component":"BMM","state":"Warning","outstanding":"EVT_BONE_MOTION"},)"
                  R"({"component":"JR3","state":"Error","outstanding":null}]})"
                  "\n");
  auto back = state_summary_from_json(json);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, robodoc_in_trouble());
}

TEST(StateSummary, AnAnswerThatIsNotASummaryIsAParseErrorThatSaysSo) {
  for (const char* bad :
       {"", "[]", R"({"system":"Fine","normal":1,"warning":0,"error":0,"not_normal":[]})",
        R"({"system":"Normal","normal":-1,"warning":0,"error":0,"not_normal":[]})",
        R"({"system":"Normal","normal":123456789012345678901234567890,"warning":0,"error":0,"not_normal":[]})",
        R"({"system":"Normal","normal":1,"warning":0,"error":0,"not_normal":[{"state":"Error"}]})"}) {
    auto parsed = state_summary_from_json(bad);
    ASSERT_FALSE(parsed) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::Parse) << bad;
    EXPECT_NE(parsed.error().message.find("state summary"), std::string::npos) << bad;
  }
}

TEST(NamedRead, AReadIsFoundByItsConsoleCommandAndAnUnknownOneIsNotFound) {
  ASSERT_NE(find_read("state summary"), nullptr);
  EXPECT_EQ(find_read("state gossip"), nullptr);
  auto unknown = read_text("state gossip", "{}");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::NotFound);
  auto text = read_text("state summary", state_summary_json(robodoc_in_trouble()));
  ASSERT_TRUE(text) << text.error().message;
  EXPECT_EQ(*text, state_summary_text(robodoc_in_trouble()));
}

}  // namespace
}  // namespace safecass::introspect

namespace safecass::introspect {
namespace {

/// One entry of every kind, with and without a root cause (a sample, a non-finite value).
std::vector<HistoryEntry> every_kind_of_entry() {
  std::vector<HistoryEntry> out;
  HistoryEntry e;
  e.seq = 7;
  e.time = std::chrono::microseconds(301000);
  e.kind = RecordKind::Event;
  e.outcome = Outcome::Raised;
  e.component = "JR3";
  e.machine = "JR3.s_A";
  e.event = "EVT_FORCE_ERROR";
  e.to = State::Error;
  e.level = State::Error;
  e.severity = 200;
  ResolvedRoot root;
  root.event = "EVT_FORCE_ERROR";
  root.origin = "JR3.s_A";
  root.time = e.time;
  root.filter = "force_limit";
  root.signal = "JR3.ForceNorm";
  root.value = std::numeric_limits<double>::infinity();
  root.sample_time = std::chrono::microseconds(300000);
  root.injected = true;
  e.root = root;
  out.push_back(e);
  HistoryEntry t = e;
  t.kind = RecordKind::Transition;
  t.outcome = Outcome::None;
  t.level = State::Normal;
  t.severity = 0;
  t.mirror = true;
  out.push_back(t);
  HistoryEntry c;
  c.kind = RecordKind::ComponentTransition;
  c.component = "JR3";
  c.from = State::Error;
  c.to = State::Normal;
  out.push_back(c);
  HistoryEntry r;
  r.kind = RecordKind::Reset;
  r.machine = "JR3.s_A";
  r.text = "console: cleared";
  out.push_back(r);
  HistoryEntry i;
  i.kind = RecordKind::Injection;
  i.machine = "JR3.s_A";
  i.text = "deep injection into signal JR3.Fz: 50";
  out.push_back(i);
  return out;
}

TEST(HistoryRead, EveryEntryReadsBackFromItsHistoryLineAsItWas) {
  for (const HistoryEntry& e : every_kind_of_entry()) {
    const std::string line = history_json(e);
    const json::JsonParse parsed = json::parse_json(line);
    ASSERT_FALSE(parsed.error) << line;
    auto back = history_entry_from_json(*parsed.value);
    ASSERT_TRUE(back) << line << ": " << back.error().message;
    EXPECT_EQ(*back, e) << line;
    EXPECT_EQ(history_json(*back), line);
  }
}

TEST(HistoryRead, ALineWithAWrongFieldSaysWhichAndWhy) {
  const auto error_of = [](std::string_view line) {
    const json::JsonParse parsed = json::parse_json(line);
    if (parsed.error) return std::string("(not JSON)");
    auto e = history_entry_from_json(*parsed.value);
    return e ? std::string("(read)") : e.error().message;
  };
  EXPECT_EQ(error_of(R"({"t":1,"kind":"transition","machine":"A.s_A","from":"Normal","to":"Bad"})"),
            R"("to" must be Normal, Warning or Error, not "Bad")");
  EXPECT_EQ(error_of(R"({"t":1,"kind":"transition","from":"Normal","to":"Error"})"),
            R"(missing "machine" (a transition record names its state machine))");
  EXPECT_EQ(error_of(R"({"t":1,"kind":"event","machine":"A.s_A","from":"Normal","to":"Error","outcome":"won"})"),
            R"(unknown outcome "won" (expected raised, override, joined, masked, cleared or ignored))");
  EXPECT_EQ(error_of(R"({"t":1,"kind":"reset","machine":"A.s_A","from":"Error","to":"Normal","root":{"event":3}})"),
            R"(in "root": "event" must be a string, not number)");
  EXPECT_EQ(error_of(R"({"kind":"reset"})"), R"(missing "t")");
  EXPECT_EQ(error_of(R"([1])"), "expected a JSON object (one record per line), not array");
}

TEST(HistoryRead, ATimeBeyondWhatADoubleKeepsToTheMicrosecondIsRefused) {
  // Found by history_fuzz: a root cause at t = 5555555550.5000055 s read back, but written and read
  // again it moved by a microsecond: a double holds no microseconds that far. A line's times
  // (the record's, its root's and its sample's) are refused beyond 4e9 s; nothing is lost below.
  const auto error_of = [](std::string_view line) {
    const json::JsonParse parsed = json::parse_json(line);
    auto e = history_entry_from_json(*parsed.value);
    return e ? std::string("(read)") : e.error().message;
  };
  const std::string head = R"({"kind":"reset","machine":"A.s_A","from":"Error","to":"Normal",)";
  EXPECT_EQ(error_of(head + R"("t":5555555550.500005})"),
            R"("t" must be a time in seconds of at most 4e9 in magnitude (about 126 years))");
  EXPECT_EQ(error_of(head + R"("t":1e300})"),
            R"("t" must be a time in seconds of at most 4e9 in magnitude (about 126 years))");
  EXPECT_EQ(error_of(head + R"("t":1,"root":{"event":"E","origin":"A.s_A","t":5555555550.500005555550}})"),
            R"(in "root": "t" must be a time in seconds of at most 4e9 in magnitude (about 126 years))");
  EXPECT_EQ(error_of(head + R"("t":1,"root":{"event":"E","origin":"A.s_A","t":1,"sample_t":-4e10}})"),
            R"(in "root": "sample_t" must be a time in seconds of at most 4e9 in magnitude (about 126 years))");
  EXPECT_EQ(error_of(head + R"("t":3999999999.999999})"), "(read)");
}

TEST(HistoryRead, ANanRootValueReadsBackAsNanAndWritesTheSameLineAgain) {
  // Found by history_fuzz, whose round trip compared entries with ==, which no NaN satisfies: a
  // root's value is NaN when a filter judged a non-finite sample (EVT_INVALID_SAMPLE). It is
  // written "nan", read back as NaN, and the line is the same when written again.
  const std::string line =
      R"({"seq":1,"t":0.1,"kind":"event","outcome":"raised","ct":"JR3","machine":"JR3.s_F","from":"Normal",)"
      R"("to":"Error","severity":225,"root":{"event":"EVT_INVALID_SAMPLE","origin":"JR3.s_F","signal":"JR3.Force",)"
      R"("value":"nan"}})";
  const json::JsonParse parsed = json::parse_json(line);
  auto first = history_entry_from_json(*parsed.value);
  ASSERT_TRUE(first.has_value()) << first.error().message;
  const std::string written = history_json(*first);
  EXPECT_NE(written.find(R"("value":"nan")"), std::string::npos) << written;
  const json::JsonParse again = json::parse_json(written);
  auto second = history_entry_from_json(*again.value);
  ASSERT_TRUE(second.has_value()) << second.error().message;
  EXPECT_EQ(history_json(*second), written);
}

}  // namespace
}  // namespace safecass::introspect
