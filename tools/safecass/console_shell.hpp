#pragma once
// The part of `safecass console` that does not depend on where the system runs: the command table,
// the parser of command lines, TAB completion, usage and error lines, `help`, and the text and
// JSON helpers every printer uses. One Backend runs the parsed commands (console.cpp),
// over a SystemQuery: a system in this process in simulated time (LocalQuery) or a live
// coordinator through the middleware (RemoteClient, console_remote.cpp). Internal to tools/safecass.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "console.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/query.hpp"
#include "safecass/introspect/sample_text.hpp"
#include "safecass/json/write.hpp"

namespace safecass::tools {

// ---- text helpers --------------------------------------------------------------------------------

std::string_view trim(std::string_view s);
// Tables and JSON: the read model's one formatter and JSON writer (numbers and times:
// safecass/core/text.hpp, found in the enclosing namespace).
using introspect::columns;
using introspect::count_text;
using introspect::parse_number;
using introspect::parse_sample;
using introspect::parse_sample_file;
using introspect::parse_samples;
using Json = json::JsonObject;
inline std::string json_string(std::string_view s) { return json::json_string(s); }
inline std::string json_list(const std::vector<std::string>& items) { return json::json_string_array(items); }

// ---- words, numbers and samples ------------------------------------------------------------------

/// Splits a command line into words: blanks separate words, `[...]` is one word (a vector sample),
/// and '...' or "..." quote a word (the quotes are removed). Errors: an unterminated bracket or quote.
[[nodiscard]] Expected<std::vector<std::string>> tokenize(std::string_view line);
/// A whole number above 0.
std::optional<long> parse_count(std::string_view s);

// ---- the command table ---------------------------------------------------------------------------

/// What a command's argument names, for completion.
enum class Arg { None, Component, Address, Machine, Event, Filter, FilterOrType, Signal, File, Command };

enum class Id {
  StateList,
  /// A named read (introspect's NamedRead, found by the command's name): answered as JSON by
  /// SystemQuery::read() and shown by its formatter.
  Read,
  StateHistory,
  FilterList,
  FilterInfo,
  FilterInject,
  FilterDinject,
  FilterDinload,
  EventList,
  EventHistory,
  EventGenerate,
  EventBroadcast,
  ConnectionList,
  ServiceList,
  Explain,
  Watch,
  Reset,
  Time,
  Help,
  Quit,
};

struct CommandSpec {
  Id id;
  std::string_view name;  ///< one or two words
  std::string_view usage;
  std::string_view doc;
  bool writes;
  std::size_t min_args;
  std::size_t max_args;   ///< kMany: no limit
  std::vector<Arg> args;  ///< completion kind of each argument; the last one repeats
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

/// What a console works on: a system read and written through one SystemQuery.
struct Target {
  /// Keeps alive what the query reads (an in-process system); destroyed after the query.
  std::shared_ptr<void> owner;
  std::unique_ptr<introspect::SystemQuery> query;
  /// "system robodoc.json (5 components, scenario story.json), simulated time" or
  /// "coordinator robot on IceStorm 127.0.0.1:14061 (3 components), live": the banner's subject.
  std::string subject;
  /// What write access means here, for the banner ("writes allowed" when empty and allowed).
  std::string write_access;
  /// In-process: advances simulated time to the given time and returns the scenario's
  /// expectation failures found on the way. Empty for a live system, whose time runs by itself.
  std::function<std::vector<std::string>(Time)> advance;
};

/// The console's one backend: every command runs against `target.query`. Errors: as the query's
/// (a live coordinator that does not answer while the names are fetched: Io).
[[nodiscard]] Expected<std::unique_ptr<Backend>> make_backend(Target target, ConsoleOptions options);

}  // namespace safecass::tools
