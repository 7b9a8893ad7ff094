// history_entry_from_json(): a history-file line (history_json()'s) read back into a HistoryEntry.

#include <algorithm>
#include <limits>
#include <optional>
#include <string>

#include "safecass/introspect/format.hpp"

namespace safecass::introspect {

namespace {

using json::JsonValue;

/// Reads the fields of one object; the first problem is kept as the message.
class FieldReader {
public:
  explicit FieldReader(const JsonValue& object) : object_(object) {}

  const std::optional<std::string>& error() const { return error_; }

  std::string string(std::string_view key, bool required) {
    const JsonValue* v = find(key, required);
    if (v == nullptr) return {};
    if (!v->is_string()) {
      fail_type(key, "a string", *v);
      return {};
    }
    return v->string;
  }

  std::optional<double> number(std::string_view key, bool required) {
    const JsonValue* v = find(key, required);
    if (v == nullptr) return std::nullopt;
    if (!v->is_number()) {
      fail_type(key, "a number", *v);
      return std::nullopt;
    }
    return v->number;
  }

  /// A time in seconds: a number of at most kMaxReadSeconds in magnitude, where the file's
  /// microseconds still read back as they were written (beyond, a double cannot hold them).
  std::optional<Time> time(std::string_view key, bool required) {
    const std::optional<double> seconds = number(key, required);
    if (!seconds) return std::nullopt;
    if (!readable_seconds(*seconds)) {
      fail("\"" + std::string(key) + "\" must be a time in seconds of at most 4e9 in magnitude (about 126 years)");
      return std::nullopt;
    }
    return read_seconds(*seconds);
  }

  bool boolean(std::string_view key) {
    const JsonValue* v = find(key, false);
    if (v == nullptr) return false;
    if (!v->is_bool()) {
      fail_type(key, "true or false", *v);
      return false;
    }
    return v->boolean;
  }

  /// "Normal", "Warning" or "Error", spelled as history_json() writes them.
  State state(std::string_view key, bool required) {
    const std::string s = string(key, required);
    for (State st : {State::Normal, State::Warning, State::Error}) {
      if (s == to_string(st)) return st;
    }
    if (!s.empty()) fail("\"" + std::string(key) + "\" must be Normal, Warning or Error, not \"" + s + "\"");
    return State::Normal;
  }

  void fail(std::string message) {
    if (!error_) error_ = std::move(message);
  }

private:
  const JsonValue* find(std::string_view key, bool required) {
    const JsonValue* v = object_.find(key);
    if (v == nullptr && required) fail("missing \"" + std::string(key) + "\"");
    return v;
  }
  void fail_type(std::string_view key, std::string_view what, const JsonValue& v) {
    fail("\"" + std::string(key) + "\" must be " + std::string(what) + ", not " + std::string(json::type_name(v.type)));
  }

  const JsonValue& object_;
  std::optional<std::string> error_;
};

/// A root's sample value: a number, or "nan", "inf", "-inf" (how history_json() writes one that
/// raised EVT_INVALID_SAMPLE).
double sample_value(const JsonValue& root, FieldReader& f) {
  const JsonValue* value = root.find("value");
  if (value != nullptr && value->is_string()) {
    if (value->string == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (value->string == "inf") return std::numeric_limits<double>::infinity();
    if (value->string == "-inf") return -std::numeric_limits<double>::infinity();
  }
  return f.number("value", false).value_or(0.0);
}

void read_root(const JsonValue& v, HistoryEntry& e, FieldReader& f) {
  const JsonValue* root = v.find("root");
  if (root == nullptr) return;
  if (!root->is_object()) {
    f.fail("\"root\" must be an object, not " + std::string(json::type_name(root->type)));
    return;
  }
  FieldReader rf(*root);
  ResolvedRoot& r = e.root.emplace();
  r.event = rf.string("event", true);
  r.origin = rf.string("origin", true);
  r.time = rf.time("t", false).value_or(Time{0});
  r.filter = rf.string("filter", false);
  r.signal = rf.string("signal", false);
  r.value = sample_value(*root, rf);
  r.sample_time = rf.time("sample_t", false).value_or(Time{0});
  r.injected = rf.boolean("injected");
  if (rf.error()) f.fail("in \"root\": " + *rf.error());
}

/// What a record of its kind must name; empty when it does.
std::string missing_names(const HistoryEntry& e) {
  switch (e.kind) {
    case RecordKind::Event:
    case RecordKind::Transition:
      if (!e.machine.empty()) return {};
      return std::string("missing \"machine\" (a ") + (e.kind == RecordKind::Event ? "event" : "transition") +
             " record names its state machine)";
    case RecordKind::ComponentTransition:
      if (!e.component.empty()) return {};
      return "missing \"component\" (a component-transition names its component)";
    case RecordKind::Reset:
    case RecordKind::Injection:
      if (!e.machine.empty() || !e.component.empty()) return {};
      return "missing \"machine\" or \"component\"";
  }
  return {};
}

}  // namespace

[[nodiscard]] Expected<HistoryEntry> history_entry_from_json(const json::JsonValue& v) {
  if (!v.is_object()) {
    return fail(ErrorCode::Parse,
                "expected a JSON object (one record per line), not " + std::string(json::type_name(v.type)));
  }
  FieldReader f(v);
  const std::string kind = f.string("kind", true);
  if (f.error()) return fail(ErrorCode::Parse, *f.error());
  HistoryEntry e;
  const auto k = parse_record_kind(kind);
  if (!k) {
    return fail(ErrorCode::Parse, "unknown record kind \"" + kind +
                                      "\" (expected event, transition, component-transition, reset, injection or "
                                      "overflow)");
  }
  e.kind = *k;
  if (const auto seq = f.number("seq", false); seq && *seq >= 0 && *seq <= 9.0e15) {
    e.seq = static_cast<std::uint64_t>(*seq);
  }
  e.time = f.time("t", true).value_or(Time{0});
  e.component = f.string("component", false);
  e.machine = f.string("machine", false);
  e.event = f.string("event", false);
  e.text = f.string("text", false);
  e.mirror = f.boolean("mirror");
  const bool has_states = e.kind != RecordKind::Injection;
  e.from = f.state("from", has_states);
  e.to = f.state("to", has_states);
  if (e.kind == RecordKind::Event) {
    const std::string outcome = f.string("outcome", true);
    const auto o = parse_outcome(outcome);
    if (!f.error() && (!o || *o == Outcome::None)) {
      f.fail("unknown outcome \"" + outcome + "\" (expected raised, override, joined, masked, cleared or ignored)");
    }
    e.outcome = o.value_or(Outcome::None);
    e.level = f.state("level", false);
    if (const auto sev = f.number("severity", false)) e.severity = static_cast<int>(std::clamp(*sev, 0.0, 255.0));
  }
  read_root(v, e, f);
  if (f.error()) return fail(ErrorCode::Parse, *f.error());
  if (std::string missing = missing_names(e); !missing.empty()) return fail(ErrorCode::Parse, std::move(missing));
  return e;
}

}  // namespace safecass::introspect
