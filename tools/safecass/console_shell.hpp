#pragma once
// The part of `safecass console` that does not depend on where the system runs: the command table,
// the parser of command lines, TAB completion, usage and error lines, `help`, and the text and
// JSON helpers every printer uses. A console::Backend runs the parsed commands: the in-process
// one (console.cpp) against a system in simulated time, the remote one (console_remote.cpp)
// against a live coordinator through the middleware. Internal to tools/safecass.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "console.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"

namespace safecass::tools::console {

// ---- text helpers --------------------------------------------------------------------------------

std::string_view trim(std::string_view s);
/// "%.6f" seconds: "0.301000".
std::string seconds_text(Time t);
/// "%.9g": "1.5", "30".
std::string number_text(double v);
/// A JSON number, or null for NaN and infinities.
std::string json_number(double v);
std::string json_string(std::string_view s);
std::string json_list(const std::vector<std::string>& items);

/// One JSON object, built field by field: Json().str("a", "x").num("b", 1).text() == {"a":"x","b":1}.
class Json {
public:
  Json& raw(std::string_view key, std::string_view value);
  Json& str(std::string_view key, std::string_view value) { return raw(key, json_string(value)); }
  Json& num(std::string_view key, double value) { return raw(key, json_number(value)); }
  Json& integer(std::string_view key, long long value) { return raw(key, std::to_string(value)); }
  Json& boolean(std::string_view key, bool value) { return raw(key, value ? "true" : "false"); }
  /// A string, or null when empty.
  Json& opt(std::string_view key, std::string_view value) { return value.empty() ? raw(key, "null") : str(key, value); }
  std::string text() const { return text_ + "}"; }

private:
  std::string text_ = "{";
  bool first_ = true;
};

/// Left-aligned columns, two spaces apart; the last column is not padded.
std::string columns(const std::vector<std::vector<std::string>>& rows);

// ---- words, numbers and samples ------------------------------------------------------------------

/// Splits a command line into words: blanks separate words, `[...]` is one word (a vector sample),
/// and '...' or "..." quote a word (the quotes are removed). Errors: an unterminated bracket or quote.
Expected<std::vector<std::string>> tokenize(std::string_view line);
std::optional<double> parse_number(std::string_view s);
/// The values of injected samples: numbers separated by commas and/or blanks. Errors name the
/// offending text: not a number, or not finite (`nan`, `inf`, `-inf`: injected values must be
/// finite, the rule of every injection path, docs/filters.md).
Expected<std::vector<double>> parse_numbers(std::string_view text);
/// A sample: `1.5` (scalar) or `[1,2,3]` / `[1 2 3]` (vector) of finite numbers.
Expected<std::vector<double>> parse_sample(std::string_view word);
/// Every word as a sample. Errors: the first word that is not one.
Expected<std::vector<std::vector<double>>> parse_samples(const std::vector<std::string>& words);
/// A whole number above 0.
std::optional<long> parse_count(std::string_view s);
/// The samples of a `filter dinload` file: one per line, numbers separated by spaces or commas,
/// '#' starts a comment. Errors: "FILE:LINE: what", or "FILE: no samples".
Expected<std::vector<std::vector<double>>> parse_sample_file(const std::string& file, std::string_view text);
/// "1 sample", "3 samples".
std::string count_text(std::size_t n);

// ---- the command table ---------------------------------------------------------------------------

/// What a command's argument names, for completion.
enum class Arg { None, Component, Address, Machine, Event, Filter, FilterOrType, Signal, File, Command };

enum class Id {
  StateList, StateHistory, FilterList, FilterInfo, FilterInject, FilterDinject, FilterDinload, EventList,
  EventHistory, EventGenerate, EventBroadcast, ConnectionList, ServiceList, Explain, Watch, Reset, Time,
  Help, Quit,
};

struct CommandSpec {
  Id id;
  std::string_view name;   ///< one or two words
  std::string_view usage;
  std::string_view doc;
  bool writes;
  std::size_t min_args;
  std::size_t max_args;    ///< kMany: no limit
  std::vector<Arg> args;   ///< completion kind of each argument; the last one repeats
};

inline constexpr std::size_t kMany = static_cast<std::size_t>(-1);
inline constexpr long kDefaultHistory = 20;
inline constexpr double kMaxWatchSeconds = 3600.0;

const std::vector<CommandSpec>& commands();
/// The command named `name` ("state list", "explain"; "exit" is "quit"), or null.
const CommandSpec* find_command(std::string_view name);

// ---- what a backend writes to --------------------------------------------------------------------

struct Out {
  ConsoleReply reply;
  void line(std::string text) { reply.out += std::move(text) + "\n"; }
};

/// The confirmation line of a write command: `text`, or with --json `json` plus ok, command and
/// (when known) the time `t` in seconds.
void write_done(Out& out, bool json_output, const CommandSpec& c, Json json, const std::string& text,
                std::optional<double> t);

/// The lines of `explain ADDRESS`: one per active condition (to_string(Explanation)), or one JSON
/// object each. `with_counts`: the explanations carry count/first/last (in-process). With none,
/// one line "ADDRESS is STATE: no active condition" (STATE may be empty: "ADDRESS: no active ...").
void print_explanations(const std::vector<Explanation>& all, const std::string& address, std::string_view state,
                        bool json_output, bool with_counts, Out& out);

/// Runs the commands of one console. Thread-safety: one thread at a time, like the Console.
class Backend {
public:
  virtual ~Backend() = default;
  /// Runs one command whose words were parsed and counted and whose write access was checked
  /// (help and quit never reach a backend). Returns an error message (printed with the usage),
  /// or empty on success.
  virtual std::string run(const CommandSpec& c, const std::vector<std::string>& args, Out& out) = 0;
  /// The names an argument of kind `kind` can take, for completion (unsorted, duplicates allowed).
  virtual std::vector<std::string> names(Arg kind) const = 0;
  /// One line: what the console is connected to and whether it may write.
  virtual std::string banner() const = 0;
  /// Called before and after each command: `ok` false when it failed.
  virtual void begin() {}
  virtual void end(Out& /*out*/, bool /*ok*/) {}
};

}  // namespace safecass::tools::console
