// `safecass console`: what does not depend on where the system runs — the command table, the
// parser, completion, usage lines, `help` — and the Console that drives a backend with them.

#include "console_shell.hpp"

#include "safecass/json/read.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace safecass::tools {

// ---- text helpers --------------------------------------------------------------------------------

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

// ---- words, numbers and samples -----------------------------------------------------------------

/// Splits a command line into words: blanks separate words, `[...]` is one word (a vector sample),
/// and '...' or "..." quote a word (the quotes are removed). Errors: an unterminated bracket or quote.
[[nodiscard]] Expected<std::vector<std::string>> tokenize(std::string_view line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
      ++i;
      continue;
    }
    std::string word;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r' && line[i] != '\n') {
      const char d = line[i];
      if (d == '[') {
        const auto close = line.find(']', i);
        if (close == std::string_view::npos) return fail(ErrorCode::Parse, "'[' without ']'");
        word.append(line.substr(i, close - i + 1));
        i = close + 1;
      } else if (d == '"' || d == '\'') {
        const auto close = line.find(d, i + 1);
        if (close == std::string_view::npos) return fail(ErrorCode::Parse, std::string("unterminated ") + d);
        word.append(line.substr(i + 1, close - i - 1));
        i = close + 1;
      } else {
        word += d;
        ++i;
      }
    }
    words.push_back(std::move(word));
  }
  return words;
}

std::optional<long> parse_count(std::string_view s) {
  long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v <= 0) return std::nullopt;
  return v;
}

// ---- the command table ---------------------------------------------------------------------------

const std::vector<CommandSpec>& commands() {
  static const std::vector<CommandSpec> table = {
      // One entry: id, name, usage; doc; writes, min and max arguments, their kinds.
      // clang-format off
      {Id::StateList, "state list", "state list [COMPONENT]",
       "every component and state machine with its state and outstanding event",
       false, 0, 1, {Arg::Component}},
      {Id::Read, "state summary", "state summary",
       "the system at a glance: its state, how many components are Normal, Warning and Error, and those that "
       "are not Normal with their outstanding event",
       false, 0, 0, {}},
      {Id::Read, "analyze now", "analyze now",
       "which hazards the system cannot detect now: an onset whose every filter is disabled, injected, without a "
       "sample yet or fed by a stale signal, or raised in a process whose coordinator is lost (docs/analyze.md)",
       false, 0, 0, {}},
      {Id::StateHistory, "state history", "state history [ADDRESS] [N]",
       "the last N records (default 20) of a machine, a component or the whole system",
       false, 0, 2, {Arg::Address, Arg::None}},
      {Id::FilterList, "filter list", "filter list",
       "every filter: type, target, execution, detection, enabled, detected, signals",
       false, 0, 0, {}},
      {Id::FilterInfo, "filter info", "filter info NAME",
       "a filter's manifest (parameters with type, value, default, range and doc; inputs; outputs) and its "
       "current enabled/detected state; NAME may also be a filter type",
       false, 1, 1, {Arg::FilterOrType}},
      {Id::FilterInject, "filter inject", "filter inject NAME SAMPLE...",
       "shallow fault injection: queue samples into one filter's private input, seen by that filter alone on "
       "its next runs (SAMPLE: 1.5, or [1,2,3] for a vector)",
       true, 2, kMany, {Arg::Filter, Arg::None}},
      {Id::FilterDinject, "filter dinject", "filter dinject SIGNAL SAMPLE...",
       "deep fault injection: write samples into a signal's history buffer at the current time; every "
       "consumer sees them",
       true, 2, kMany, {Arg::Signal, Arg::None}},
      {Id::FilterDinload, "filter dinload", "filter dinload SIGNAL FILE",
       "deep-inject every sample of a text file: one sample per line, numbers separated by spaces or commas "
       "('#' starts a comment)",
       true, 2, 2, {Arg::Signal, Arg::File}},
      {Id::EventList, "event list", "event list",
       "every event with its severity, transitions, counterpart, hazard and description",
       false, 0, 0, {}},
      {Id::EventHistory, "event history", "event history [N]",
       "the last N events processed, ignored or masked by any machine (default 20)",
       false, 0, 1, {Arg::None}},
      {Id::EventGenerate, "event generate", "event generate EVENT TARGET",
       "process EVENT on machine TARGET (C.s_F, C.s_A, C.s_P.p or C.s_R.r) and propagate it",
       true, 2, 2, {Arg::Event, Arg::Machine}},
      {Id::EventBroadcast, "event broadcast", "event broadcast EVENT",
       "process a broadcast event (severity 251-255) on s_A of every component",
       true, 1, 1, {Arg::Event}},
      {Id::ConnectionList, "connection list", "connection list",
       "every connection: the client's required interface and state, the provider's service and state",
       false, 0, 0, {}},
      {Id::ServiceList, "service list", "service list",
       "every provided interface with its service state and dependency formula",
       false, 0, 0, {}},
      {Id::Explain, "explain", "explain ADDRESS",
       "every active condition at ADDRESS with its root cause and the path it took",
       false, 1, 1, {Arg::Address}},
      {Id::Watch, "watch", "watch [SECONDS]",
       "advance simulated time by SECONDS (default 1), running the scenario and the system and printing each "
       "transition as it happens (against a live coordinator: print its records for SECONDS, as the bus "
       "pushes them)",
       false, 0, 1, {Arg::None}},
      {Id::Reset, "reset", "reset TARGET [REASON]",
       "clear every condition (latched ones too) of a machine, a component or SYSTEM, recording the reason",
       true, 1, kMany, {Arg::Address, Arg::None}},
      {Id::Time, "time", "time",
       "the current simulated time (in-process only)",
       false, 0, 0, {}},
      {Id::Help, "help", "help [COMMAND]",
       "list the commands, or show one command's usage",
       false, 0, 2, {Arg::Command, Arg::Command}},
      {Id::Quit, "quit", "quit",
       "leave the console (also: exit, or end of input)",
       false, 0, 0, {}},
      // clang-format on
  };
  return table;
}

const CommandSpec* find_command(std::string_view name) {
  if (name == "exit") name = "quit";
  for (const CommandSpec& c : commands()) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

namespace {

constexpr std::string_view kGroups[] = {"state", "filter", "event", "connection", "service", "analyze"};

bool is_group(std::string_view word) {
  return std::find(std::begin(kGroups), std::end(kGroups), word) != std::end(kGroups);
}

/// "state list [COMPONENT] | state history [ADDRESS] [N]".
std::string group_usage(std::string_view group) {
  std::string out;
  for (const CommandSpec& c : commands()) {
    if (c.name.substr(0, c.name.find(' ')) == group && c.name.find(' ') != std::string_view::npos) {
      out += (out.empty() ? "" : " | ") + std::string(c.usage);
    }
  }
  return out;
}

std::vector<std::string> top_words() {
  std::set<std::string> words{"exit"};
  for (const CommandSpec& c : commands()) words.emplace(c.name.substr(0, c.name.find(' ')));
  return {words.begin(), words.end()};
}

std::vector<std::string> sub_words(std::string_view group) {
  std::vector<std::string> words;
  for (const CommandSpec& c : commands()) {
    const auto space = c.name.find(' ');
    if (space != std::string_view::npos && c.name.substr(0, space) == group)
      words.emplace_back(c.name.substr(space + 1));
  }
  return words;
}

}  // namespace

// ---- shared printers -----------------------------------------------------------------------------

namespace {

/// The command and argument position the word after `before` belongs to.
struct Context {
  const CommandSpec* command = nullptr;
  std::vector<std::string> words;
  std::size_t arg = 0;  ///< index of the argument being typed
  bool ok = false;
};

Context context(std::string_view before) {
  Context ctx;
  auto words = tokenize(before);
  if (!words) return ctx;
  ctx.words = std::move(*words);
  ctx.ok = true;
  if (ctx.words.empty()) return ctx;
  if (is_group(ctx.words[0])) {
    if (ctx.words.size() < 2) return ctx;
    ctx.command = find_command(ctx.words[0] + " " + ctx.words[1]);
    ctx.arg = ctx.words.size() - 2;
  } else {
    ctx.command = find_command(ctx.words[0]);
    ctx.arg = ctx.words.size() - 1;
  }
  return ctx;
}

Arg arg_kind(const CommandSpec& c, std::size_t arg) {
  if (c.args.empty() || arg >= c.max_args) return Arg::None;
  return arg < c.args.size() ? c.args[arg] : c.args.back();
}

}  // namespace

Console::Console(std::unique_ptr<Backend> backend, ConsoleOptions options)
    : backend_(std::move(backend)), options_(options) {}
Console::~Console() = default;

/// A failed command: one line on stderr saying what went wrong and how the command is used.
ConsoleReply Console::failure(std::string_view command, const std::string& message, std::string_view usage) const {
  ConsoleReply r;
  r.ok = false;
  if (options_.json) {
    r.err = Json().boolean("ok", false).opt("command", command).str("error", message).str("usage", usage).text() + "\n";
  } else {
    r.err = (command.empty() ? std::string() : std::string(command) + ": ") + message +
            " (usage: " + std::string(usage) + ")\n";
  }
  return r;
}

ConsoleReply Console::execute(std::string_view line) {
  line = trim(line);
  if (line.empty() || line.front() == '#') return {};
  auto words = tokenize(line);
  if (!words) return failure("", words.error().message, "help [COMMAND]");
  std::vector<std::string>& w = *words;
  const CommandSpec* command = nullptr;
  std::size_t first_arg = 1;
  if (is_group(w[0])) {
    if (w.size() < 2) return failure(w[0], "needs a subcommand", group_usage(w[0]));
    command = find_command(w[0] + " " + w[1]);
    if (command == nullptr) return failure(w[0], "unknown subcommand '" + w[1] + "'", group_usage(w[0]));
    first_arg = 2;
  } else {
    command = find_command(w[0]);
    if (command == nullptr) return failure("", "unknown command '" + w[0] + "'", "help [COMMAND]");
  }
  const std::vector<std::string> args(w.begin() + static_cast<std::ptrdiff_t>(first_arg), w.end());
  if (args.size() < command->min_args || (command->max_args != kMany && args.size() > command->max_args)) {
    return failure(command->name, args.size() < command->min_args ? "missing arguments" : "too many arguments",
                   command->usage);
  }
  if (command->writes && !options_.allow_write) {
    return failure(
        command->name,
        "refused: this console is read-only; start it with --allow-write to inject, generate, broadcast or reset",
        command->usage);
  }
  ConsoleReply reply;
  if (command->id == Id::Quit) {
    reply.quit = true;
    return reply;
  }
  if (command->id == Id::Help) {
    const std::string error = help(args, reply);
    return error.empty() ? reply : failure(command->name, error, command->usage);
  }
  backend_->begin();
  Out out;
  const std::string error = backend_->run(*command, args, out);
  backend_->end(out, error.empty());
  if (!error.empty()) return failure(command->name, error, command->usage);
  return std::move(out.reply);
}

std::string Console::help(const std::vector<std::string>& args, ConsoleReply& reply) const {
  Out out;
  std::vector<const CommandSpec*> selected;
  std::string asked;
  for (const std::string& a : args) asked += (asked.empty() ? "" : " ") + a;
  for (const CommandSpec& c : commands()) {
    const bool in_group = args.size() == 1 && is_group(args[0]) && c.name.substr(0, c.name.find(' ')) == args[0];
    if (args.empty() || in_group || c.name == asked || (asked == "exit" && c.id == Id::Quit)) selected.push_back(&c);
  }
  if (selected.empty()) return "no command '" + asked + "'";
  std::vector<std::vector<std::string>> rows;
  for (const CommandSpec* c : selected) {
    const std::string doc = std::string(c->doc) + (c->writes ? " [write: needs --allow-write]" : "");
    if (options_.json) {
      out.line(
          Json().str("command", c->name).str("usage", c->usage).str("doc", c->doc).boolean("writes", c->writes).text());
    } else if (selected.size() == 1) {
      out.line("usage: " + std::string(c->usage));
      out.line("  " + doc);
    } else {
      rows.push_back({std::string(c->usage), doc});
    }
  }
  if (!rows.empty()) {
    out.reply.out += columns(rows);
    if (args.empty()) {
      out.line("ADDRESS: SYSTEM, C, C.s_F, C.s_A, C.s_P.p, C.s_R.r, C.s_S.p. TAB completes commands and names.");
      out.line(options_.allow_write ? "Write commands are allowed (--allow-write)."
                                    : "Read-only: write commands need --allow-write.");
    }
  }
  reply = std::move(out.reply);
  return {};
}

std::vector<std::string> Console::complete(std::string_view before, std::string_view word) const {
  const Context ctx = context(before);
  if (!ctx.ok) return {};
  std::vector<std::string> candidates;
  if (ctx.words.empty()) {
    candidates = top_words();
  } else if (ctx.words.size() == 1 && is_group(ctx.words[0])) {
    candidates = sub_words(ctx.words[0]);
  } else if (ctx.command != nullptr && ctx.command->id == Id::Help) {
    if (ctx.arg == 0)
      candidates = top_words();
    else if (ctx.arg == 1 && is_group(ctx.words[1]))
      candidates = sub_words(ctx.words[1]);
  } else if (ctx.command != nullptr) {
    const Arg kind = arg_kind(*ctx.command, ctx.arg);
    candidates = kind == Arg::Command ? top_words() : backend_->names(kind);
  }
  std::vector<std::string> out;
  for (std::string& c : candidates) {
    if (c.compare(0, word.size(), word) == 0) out.push_back(std::move(c));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool Console::completes_file(std::string_view before) const {
  const Context ctx = context(before);
  return ctx.command != nullptr && arg_kind(*ctx.command, ctx.arg) == Arg::File;
}

std::string Console::banner() const { return backend_->banner(); }

}  // namespace safecass::tools
