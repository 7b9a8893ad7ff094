// The console's shared parser, completion and printers (console_shell.hpp) with a fake backend:
// what reaches a backend, what never does, and how its answers are printed.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "console.hpp"
#include "console_shell.hpp"
#include "safecass/introspect/local_query.hpp"

namespace safecass::tools {
namespace {

/// Records every command it is asked to run; fails with `error` when set.
struct Calls {
  std::vector<std::string> commands;  ///< "name|arg|arg..."
  std::vector<std::string> frames;    ///< "begin", "end ok", "end failed"
  std::string error;
};

class FakeBackend final : public Backend {
public:
  explicit FakeBackend(Calls& calls) : calls_(calls) {}
  std::string run(const CommandSpec& c, const std::vector<std::string>& args, Out& out) override {
    std::string call(c.name);
    for (const std::string& a : args) call += "|" + a;
    calls_.commands.push_back(call);
    if (calls_.error.empty()) out.line("ran " + call);
    return calls_.error;
  }
  std::vector<std::string> names(Arg kind) const override {
    switch (kind) {
      case Arg::Event: return {"EVT_B", "EVT_A", "/EVT_A"};
      case Arg::Machine: return {"ARM.s_A", "ARM.s_F"};
      case Arg::Component: return {"ARM"};
      default: return {};
    }
  }
  std::string banner() const override { return "fake"; }
  void begin() override { calls_.frames.emplace_back("begin"); }
  void end(Out& /*out*/, bool ok) override { calls_.frames.emplace_back(ok ? "end ok" : "end failed"); }

private:
  Calls& calls_;
};

std::unique_ptr<Console> fake_console(Calls& calls, bool allow_write, bool json = false) {
  return std::make_unique<Console>(std::make_unique<FakeBackend>(calls), ConsoleOptions{json, allow_write});
}

TEST(ConsoleShell, ACommandReachesTheBackendWithItsWordsParsedQuotedAndBracketed) {
  Calls calls;
  auto console = fake_console(calls, true);
  const ConsoleReply r = console->execute("  filter inject force_limit [1, 2 3] 'a b' 4  ");
  EXPECT_TRUE(r.ok) << r.err;
  ASSERT_EQ(calls.commands.size(), 1u);
  EXPECT_EQ(calls.commands[0], "filter inject|force_limit|[1, 2 3]|a b|4");
  EXPECT_EQ(r.out, "ran filter inject|force_limit|[1, 2 3]|a b|4\n");
  EXPECT_EQ(calls.frames, (std::vector<std::string>{"begin", "end ok"}));
}

TEST(ConsoleShell, AWriteOnAReadOnlyConsoleIsRefusedBeforeTheBackend) {
  Calls calls;
  auto console = fake_console(calls, false);
  for (const char* line : {"event generate EVT_A ARM.s_A", "event broadcast EVT_B", "reset ARM", "filter inject f 1",
                           "filter dinject ARM.x 1", "filter dinload ARM.x file.txt"}) {
    const ConsoleReply r = console->execute(line);
    EXPECT_FALSE(r.ok) << line;
    EXPECT_NE(r.err.find("refused: this console is read-only"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(calls.commands.empty());
  EXPECT_TRUE(console->execute("state list").ok) << "reads still reach the backend";
  EXPECT_EQ(calls.commands, (std::vector<std::string>{"state list"}));
}

TEST(ConsoleShell, BadCommandLinesAreUsageLinesThatNeverReachTheBackend) {
  Calls calls;
  auto console = fake_console(calls, true);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"frobnicate", "unknown command 'frobnicate' (usage: help [COMMAND])"},
      {"state",
       "state: needs a subcommand (usage: state list [COMPONENT] | state summary | state history [ADDRESS] [N])"},
      {"state lst", "state: unknown subcommand 'lst'"},
      {"explain", "explain: missing arguments (usage: explain ADDRESS)"},
      {"event generate A B C", "event generate: too many arguments (usage: event generate EVENT TARGET)"},
      {"filter inject f [1,2", "'[' without ']'"},
      {"explain 'ARM", "unterminated '"},
  };
  for (const auto& [line, error] : cases) {
    const ConsoleReply r = console->execute(line);
    EXPECT_FALSE(r.ok) << line;
    EXPECT_TRUE(r.out.empty()) << line;
    EXPECT_NE(r.err.find(error), std::string::npos) << line << ": " << r.err;
  }
  EXPECT_TRUE(calls.commands.empty());
  EXPECT_TRUE(calls.frames.empty());
  EXPECT_TRUE(console->execute("   ").ok);
  EXPECT_TRUE(console->execute("# a comment").ok);
  EXPECT_TRUE(calls.commands.empty());
}

TEST(ConsoleShell, ABackendErrorIsPrintedWithTheCommandAndItsUsageInTextAndJson) {
  Calls calls;
  calls.error = "event generate refused: the request does not carry coordinator 'robot''s token";
  auto text = fake_console(calls, true);
  ConsoleReply r = text->execute("event generate EVT_A ARM.s_A");
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(r.err, "event generate: " + calls.error + " (usage: event generate EVENT TARGET)\n");
  EXPECT_EQ(calls.frames.back(), "end failed");

  auto json = fake_console(calls, true, true);
  r = json->execute("event generate EVT_A ARM.s_A");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.err,
            "{\"ok\":false,\"command\":\"event generate\",\"error\":\"event generate refused: the request does "
            "not carry coordinator 'robot''s token\",\"usage\":\"event generate EVENT TARGET\"}\n");
}

TEST(ConsoleShell, EveryNamedReadCommandHasItsReadAndNoneWrites) {
  std::size_t reads = 0;
  for (const CommandSpec& c : commands()) {
    if (c.id != Id::Read) continue;
    ++reads;
    EXPECT_NE(introspect::find_read(c.name), nullptr) << c.name << ": no NamedRead of that name in kReads";
    EXPECT_FALSE(c.writes) << c.name << ": a named read is read-only";
  }
  EXPECT_GE(reads, 1u);  // state summary
}

TEST(ConsoleShell, HelpAndQuitAreAnsweredWithoutTheBackend) {
  Calls calls;
  auto console = fake_console(calls, false);
  const ConsoleReply help = console->execute("help");
  EXPECT_TRUE(help.ok);
  EXPECT_NE(help.out.find("watch [SECONDS]"), std::string::npos);
  EXPECT_NE(help.out.find("Read-only: write commands need --allow-write."), std::string::npos);
  EXPECT_EQ(console->execute("help explain").out,
            "usage: explain ADDRESS\n  every active condition at ADDRESS with its root cause and the path it took\n");
  EXPECT_FALSE(console->execute("help nothing").ok);
  EXPECT_TRUE(console->execute("exit").quit);
  EXPECT_TRUE(console->execute("quit").quit);
  EXPECT_TRUE(calls.commands.empty());
  EXPECT_EQ(console->banner(), "fake");
}

TEST(ConsoleShell, CompletionOffersCommandWordsThenTheBackendsNamesForEachArgument) {
  Calls calls;
  auto console = fake_console(calls, true);
  EXPECT_EQ(console->complete("", "st"), (std::vector<std::string>{"state"}));
  EXPECT_EQ(console->complete("event ", "g"), (std::vector<std::string>{"generate"}));
  EXPECT_EQ(console->complete("event generate ", "EVT"), (std::vector<std::string>{"EVT_A", "EVT_B"}));
  EXPECT_EQ(console->complete("event generate EVT_A ", ""), (std::vector<std::string>{"ARM.s_A", "ARM.s_F"}));
  EXPECT_TRUE(console->complete("event generate EVT_A ARM.s_A ", "").empty()) << "no third argument";
  EXPECT_EQ(console->complete("state list ", "A"), (std::vector<std::string>{"ARM"}));
  EXPECT_EQ(console->complete("help ", "ser"), (std::vector<std::string>{"service"}));
  EXPECT_TRUE(console->completes_file("filter dinload ARM.x "));
  EXPECT_FALSE(console->completes_file("filter dinload "));
  EXPECT_TRUE(calls.commands.empty()) << "completion runs no command";
}

TEST(ConsoleShell, ExplanationsPrintOneLineEachWithEveryFieldInJsonAndSayWhenThereIsNone) {
  Explanation e;
  e.machine = "CONTROL.s_R.ForceData";
  e.event = "EVT_SERVICE_FAILURE";
  e.level = State::Error;
  e.severity = 200;
  e.mirror = true;
  e.count = 3;
  e.root.event = "EVT_FORCE_ERROR";
  e.root.origin = "JR3.s_A";
  e.path = {"JR3.s_A", "JR3.s_S.ForceData", "CONTROL.s_R.ForceData"};
  e.root.time = seconds_to_time(0.1);
  e.hazard = "H-3";
  e.root.filter = "force_limit";
  e.root.signal = "JR3.ForceNorm";
  e.root.value = 35.0;
  e.root.sample_time = seconds_to_time(0.1);
  const introspect::ExplainAnswer answer{"CONTROL", State::Error, {e}};
  EXPECT_EQ(introspect::explain_text(answer, introspect::TimeFormat{}),
            "CONTROL.s_R.ForceData: Error EVT_SERVICE_FAILURE (severity 200) <- JR3.s_A:EVT_FORCE_ERROR since "
            "0.100000 s [hazard H-3] [filter force_limit, JR3.ForceNorm = 35 at 0.100000 s] path JR3.s_A -> "
            "JR3.s_S.ForceData -> CONTROL.s_R.ForceData\n")
      << "one line with the root, its time, hazard, filter data and path; simulated times in seconds";
  const std::string json = introspect::explain_json(answer);
  EXPECT_NE(json.find("\"count\":3"), std::string::npos) << json;
  EXPECT_NE(json.find("\"root_origin\":\"JR3.s_A\""), std::string::npos) << json;
  EXPECT_EQ(introspect::explain_text(introspect::ExplainAnswer{"JR3", State::Normal, {}}, introspect::TimeFormat{}),
            "JR3 is Normal: no active condition\n");
}

TEST(ConsoleShell, ASampleFileIsReadLineByLineAndItsErrorsNameTheLine) {
  auto good = parse_sample_file("f.txt", "# force\n1, 2 3\n\n4 # trailing\n");
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_EQ(*good, (std::vector<std::vector<double>>{{1, 2, 3}, {4}}));
  auto bad = parse_sample_file("f.txt", "1\n2 x\n");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "f.txt:2: 'x' is not a number");
  auto empty = parse_sample_file("f.txt", "# nothing\n");
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().message, "f.txt: no samples");
}

}  // namespace
}  // namespace safecass::tools
