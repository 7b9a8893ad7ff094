#include "safecass/introspect/format.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <optional>

#include <fmt/format.h>
#include <variant>

#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"

namespace safecass::introspect {

namespace {

std::string state_text(State s) { return std::string(to_string(s)); }

/// "%g": the six significant digits explanations have always shown.
std::string short_number(double v) { return fmt::format("{:g}", v); }

/// A sample value in a history line: a number, or "nan"/"inf"/"-inf" as a string.
std::string sample_json(double v) {
  if (std::isnan(v)) return "\"nan\"";
  if (std::isinf(v)) return v > 0 ? "\"inf\"" : "\"-inf\"";
  return json::json_number(v);
}

std::vector<std::string> names_of(const std::vector<SignalRef>& signals) {
  std::vector<std::string> out;
  for (const SignalRef& s : signals) out.push_back(s.name);
  return out;
}

std::string propagates_text(State level) { return level == State::Warning ? "Warning and Error" : "Error"; }

std::string range_text(const ParamRow& p) {
  if (p.type == ParamType::Choice) return joined(p.choices, "|");
  if (p.type != ParamType::Number && p.type != ParamType::Integer) return {};
  const bool low = p.min > -1e299;
  const bool high = p.max < 1e299;
  if (!low && !high) return {};
  return "[" + (low ? number_text(p.min) : std::string("-inf")) + ", " +
         (high ? number_text(p.max) : std::string("+inf")) + "]";
}

std::string default_text(const ParamRow& p) {
  if (p.default_value) return param_text(*p.default_value);
  return p.optional ? "(optional)" : "(required)";
}

std::string event_kind(const EventRow& e) { return e.broadcast ? "broadcast" : e.onset ? "onset" : "completion"; }

}  // namespace

std::string joined(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (const std::string& s : items) {
    if (!out.empty()) out += separator;
    out += s;
  }
  return out;
}

// ---- times and numbers ------------------------------------------------------------------------

std::string iso8601_local(std::int64_t unix_ns) {
  std::int64_t secs = unix_ns / 1'000'000'000;
  std::int64_t rest = unix_ns % 1'000'000'000;
  if (rest < 0) {
    rest += 1'000'000'000;
    --secs;
  }
  const std::time_t tt = static_cast<std::time_t>(secs);
  std::tm tm{};
  localtime_r(&tt, &tm);
  const long offset = tm.tm_gmtoff;
  const long off = offset < 0 ? -offset : offset;
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}{}{:02}:{:02}", tm.tm_year + 1900, tm.tm_mon + 1,
                     tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, rest / 1'000'000, offset < 0 ? '-' : '+', off / 3600,
                     (off % 3600) / 60);
}

std::string markup_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string TimeFormat::at(Time t) const {
  if (base_ == TimeBase::Simulated) return "t=" + seconds_text(t);
  return iso8601_local(t.count() + wall_offset_ns_);
}

std::string TimeFormat::stamp(Time t) const {
  if (base_ == TimeBase::Simulated) return seconds_text(t) + " s";
  return iso8601_local(t.count() + wall_offset_ns_);
}

std::string columns(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows) {
    if (r.size() > width.size()) width.resize(r.size(), 0);
    for (std::size_t i = 0; i + 1 < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
  }
  std::string out;
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t i = 0; i < r.size(); ++i) {
      line += r[i];
      if (i + 1 < r.size()) line += std::string(width[i] - r[i].size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

std::string transitions_text(const std::vector<Transition>& transitions) {
  std::string out;
  for (const Transition t : transitions) out += (out.empty() ? "" : ",") + std::string(to_string(t));
  return out;
}

std::string param_text(const ParamValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          return number_text(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return x;
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          return "[" + joined(x, ", ") + "]";
        } else {
          std::vector<std::string> items;
          for (const double d : x) items.push_back(number_text(d));
          return "[" + joined(items, ", ") + "]";
        }
      },
      v);
}

std::string param_json(const ParamValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          return json::json_number(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return json::json_string(x);
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          return json::json_string_array(x);
        } else {
          return json::json_number_array(x);
        }
      },
      v);
}

// ---- history ----------------------------------------------------------------------------------

std::string history_text(const HistoryEntry& e, const TimeFormat& time) {
  std::string out = time.at(e.time) + "  " + std::string(e.where());
  switch (e.kind) {
    case RecordKind::Transition:
    case RecordKind::ComponentTransition:
      out += "  " + state_text(e.from) + " -> " + state_text(e.to);
      if (!e.event.empty()) out += "  " + e.event;
      break;
    case RecordKind::Event: out += "  " + std::string(to_string(e.outcome)) + " " + e.event; break;
    case RecordKind::Reset: out += "  reset"; break;
    case RecordKind::Injection: out += "  injection"; break;
  }
  if (e.root) {
    const ResolvedRoot& r = *e.root;
    if (!(r.origin == e.machine && r.event == e.event)) out += "  <- " + r.origin + ":" + r.event;
    if (!r.filter.empty() || !r.signal.empty()) {
      out += "  [";
      if (!r.filter.empty()) out += "filter " + r.filter;
      if (!r.signal.empty()) out += ", " + r.signal + " = " + number_text(r.value);
      if (r.injected) out += ", injected";
      out += "]";
    }
  }
  if (!e.text.empty()) out += "  (" + e.text + ")";
  return out;
}

std::string history_json(const HistoryEntry& e) {
  json::JsonObject j;
  j.integer("seq", static_cast<long long>(e.seq)).seconds("t", e.time).str("kind", to_string(e.kind));
  if (e.outcome != Outcome::None) j.str("outcome", to_string(e.outcome));
  if (!e.component.empty()) j.str("component", e.component);
  if (!e.machine.empty()) j.str("machine", e.machine);
  if (!e.event.empty()) j.str("event", e.event);
  if (e.kind != RecordKind::Injection) j.str("from", to_string(e.from)).str("to", to_string(e.to));
  if (e.kind == RecordKind::Event) j.str("level", to_string(e.level)).integer("severity", e.severity);
  if (e.mirror) j.boolean("mirror", true);
  if (e.root) {
    const ResolvedRoot& r = *e.root;
    json::JsonObject root;
    root.str("event", r.event).str("origin", r.origin).seconds("t", r.time);
    if (!r.filter.empty()) root.str("filter", r.filter);
    if (!r.signal.empty())
      root.str("signal", r.signal).raw("value", sample_json(r.value)).seconds("sample_t", r.sample_time);
    if (r.injected) root.boolean("injected", true);
    j.raw("root", root.text());
  }
  if (!e.text.empty()) j.str("text", e.text);
  return j.text();
}

bool shown_while_watching(const HistoryEntry& e) noexcept {
  return e.kind == RecordKind::Transition || e.kind == RecordKind::Reset || e.kind == RecordKind::Injection ||
         (e.kind == RecordKind::Event && (e.outcome == Outcome::Masked || e.outcome == Outcome::Ignored));
}

// ---- live lines -------------------------------------------------------------------------------

std::string live_line(const HistoryEntry& e) {
  std::string out;
  switch (e.kind) {
    case RecordKind::Transition:
    case RecordKind::ComponentTransition:
      out.append(e.where()).append(" ").append(to_string(e.from)).append(" -> ").append(to_string(e.to));
      if (!e.event.empty()) out.append(" ").append(e.event);
      if (e.root) out.append(" (root ").append(e.root->origin).append(":").append(e.root->event).append(")");
      return out;
    case RecordKind::Reset: out.append("reset ").append(e.where()); break;
    case RecordKind::Event:
      out.append(e.where()).append(" ").append(to_string(e.outcome)).append(" ").append(e.event);
      break;
    case RecordKind::Injection: out.append(e.where()).append(" injection"); break;
  }
  if (!e.text.empty()) out.append(" (").append(e.text).append(")");
  return out;
}

std::string live_state_line(std::string_view address, State state, std::string_view note) {
  std::string out;
  out.append(address).append(" ").append(to_string(state));
  if (!note.empty()) out.append(" (").append(note).append(")");
  return out;
}

// ---- explanations -----------------------------------------------------------------------------

std::string explanation_text(const Explanation& e, const TimeFormat& time) {
  std::string out =
      e.machine + ": " + state_text(e.level) + " " + e.event + " (severity " + std::to_string(e.severity) + ")";
  if (e.mirror) out += " <- " + e.root.name();
  out += " since " + time.stamp(e.root.time);
  if (!e.hazard.empty()) out += " [hazard " + e.hazard + "]";
  if (!e.root.filter.empty() || !e.root.signal.empty()) {
    out += " [";
    if (!e.root.filter.empty()) out += "filter " + e.root.filter;
    if (!e.root.signal.empty()) {
      if (!e.root.filter.empty()) out += ", ";
      out += e.root.signal + " = " + short_number(e.root.value) + " at " + time.stamp(e.root.sample_time);
    }
    if (e.root.injected) out += ", injected";
    out += "]";
  }
  if (e.path.size() > 1) out += " path " + joined(e.path, " -> ");
  return out;
}

std::string explanation_json(const std::string& address, const Explanation& e) {
  json::JsonObject j;
  j.str("address", address)
      .str("machine", e.machine)
      .str("event", e.event)
      .str("level", to_string(e.level))
      .integer("severity", e.severity)
      .boolean("mirror", e.mirror)
      .boolean("outstanding", e.outstanding)
      .integer("count", e.count)
      .seconds("first", e.first)
      .seconds("last", e.last)
      .str("root_event", e.root.event)
      .str("root_origin", e.root.origin)
      .seconds("root_t", e.root.time)
      .opt("hazard", e.hazard);
  if (!e.root.filter.empty()) j.str("filter", e.root.filter);
  if (!e.root.signal.empty())
    j.str("signal", e.root.signal).num("value", e.root.value).seconds("sample_t", e.root.sample_time);
  if (e.root.injected) j.boolean("injected", true);
  return j.strings("path", e.path).text();
}

std::string explain_text(const ExplainAnswer& a, const TimeFormat& time) {
  std::string out;
  for (const Explanation& e : a.conditions) out += explanation_text(e, time) + "\n";
  if (a.conditions.empty()) out = a.address + " is " + state_text(a.state) + ": no active condition\n";
  return out;
}

std::string explain_json(const ExplainAnswer& a) {
  std::string out;
  for (const Explanation& e : a.conditions) out += explanation_json(a.address, e) + "\n";
  return out;
}

// ---- lists ------------------------------------------------------------------------------------

std::string state_list_text(const std::vector<StateRow>& rows) {
  std::vector<std::vector<std::string>> table;
  for (const StateRow& r : rows) {
    const bool top = r.kind == RowKind::System || r.kind == RowKind::Component;
    table.push_back({(top ? "" : "  ") + r.address, state_text(r.state), r.outstanding.empty() ? "-" : r.outstanding});
  }
  return columns(table);
}

std::string state_list_json(const std::vector<StateRow>& rows) {
  std::string out;
  for (const StateRow& r : rows) {
    out += json::JsonObject()
               .str("address", r.address)
               .str("kind", to_string(r.kind))
               .str("state", to_string(r.state))
               .opt("outstanding", r.outstanding)
               .text() +
           "\n";
  }
  return out;
}

std::string state_summary_text(const StateSummary& s) {
  const std::size_t n = s.normal + s.warning + s.error;
  std::string out = "SYSTEM " + state_text(s.system) + ": " + std::to_string(n) +
                    (n == 1 ? " component, " : " components, ") + std::to_string(s.normal) + " Normal, " +
                    std::to_string(s.warning) + " Warning, " + std::to_string(s.error) + " Error\n";
  std::vector<std::vector<std::string>> table;
  for (const StateSummary::Component& c : s.not_normal) {
    table.push_back({"  " + c.name, state_text(c.state), c.outstanding.empty() ? "-" : c.outstanding});
  }
  return out + columns(table);
}

std::string state_summary_json(const StateSummary& s) {
  json::JsonArray not_normal;
  for (const StateSummary::Component& c : s.not_normal) {
    not_normal.raw(json::JsonObject()
                       .str("component", c.name)
                       .str("state", to_string(c.state))
                       .opt("outstanding", c.outstanding)
                       .text());
  }
  return json::JsonObject()
             .str("system", to_string(s.system))
             .integer("normal", static_cast<long long>(s.normal))
             .integer("warning", static_cast<long long>(s.warning))
             .integer("error", static_cast<long long>(s.error))
             .raw("not_normal", not_normal.text())
             .text() +
         "\n";
}

[[nodiscard]] Expected<StateSummary> state_summary_from_json(std::string_view text) {
  const json::JsonParse parsed = json::parse_json(text, 8);
  if (!parsed.value || !parsed.value->is_object()) return fail(ErrorCode::Parse, "state summary: not a JSON object");
  const json::JsonValue& v = *parsed.value;
  const auto state_of = [](const json::JsonValue* field) -> std::optional<State> {
    return field != nullptr && field->is_string() ? parse_state(field->string) : std::nullopt;
  };
  const auto count_of = [](const json::JsonValue* field) -> std::optional<std::size_t> {
    // A count is a whole number a double holds exactly (at most 2^53).
    if (field == nullptr || !field->is_number() || !field->integral || field->number < 0 || field->number > 0x1p53) {
      return std::nullopt;
    }
    return static_cast<std::size_t>(field->number);
  };
  StateSummary s;
  const auto system = state_of(v.find("system"));
  const auto normal = count_of(v.find("normal"));
  const auto warning = count_of(v.find("warning"));
  const auto error = count_of(v.find("error"));
  const json::JsonValue* list = v.find("not_normal");
  if (!system || !normal || !warning || !error || list == nullptr || !list->is_array()) {
    return fail(ErrorCode::Parse, "state summary: system, normal, warning, error or not_normal missing or wrong");
  }
  s.system = *system;
  s.normal = *normal;
  s.warning = *warning;
  s.error = *error;
  for (const json::JsonValue& c : list->array) {
    const json::JsonValue* name = c.find("component");
    const auto state = state_of(c.find("state"));
    const json::JsonValue* outstanding = c.find("outstanding");
    if (name == nullptr || !name->is_string() || !state || outstanding == nullptr) {
      return fail(ErrorCode::Parse, "state summary: a component without a name or a state");
    }
    s.not_normal.push_back({name->string, *state, outstanding->is_string() ? outstanding->string : std::string()});
  }
  return s;
}

std::string coverage_now_text(const CoverageNow& c) {
  if (c.hazards.empty()) return "no onset names a hazard: nothing to judge\n";
  std::string out;
  for (const HazardCoverage& h : c.hazards) {
    if (h.covered()) {
      out += "hazard " + h.hazard + ": covered (" + joined(h.onsets, ", ") + ")\n";
      continue;
    }
    out += "hazard " + h.hazard + ": UNCOVERED\n";
    for (const CoverageGap& g : h.gaps) out += "  " + g.onset + ": " + g.reason + "\n";
  }
  return out + std::to_string(c.hazards.size()) + " hazards, " + std::to_string(c.uncovered()) + " uncovered now\n";
}

std::string coverage_now_json(const CoverageNow& c) {
  std::string hazards = "[";
  for (const HazardCoverage& h : c.hazards) {
    std::string gaps = "[";
    for (const CoverageGap& g : h.gaps) {
      gaps += (gaps.size() > 1 ? "," : "") + json::JsonObject().str("onset", g.onset).str("reason", g.reason).text();
    }
    hazards += (hazards.size() > 1 ? "," : "") + json::JsonObject()
                                                     .str("hazard", h.hazard)
                                                     .boolean("covered", h.covered())
                                                     .strings("onsets", h.onsets)
                                                     .raw("gaps", gaps + "]")
                                                     .text();
  }
  return json::JsonObject()
             .seconds("t", c.now)
             .integer("uncovered", static_cast<long long>(c.uncovered()))
             .raw("hazards", hazards + "]")
             .text() +
         "\n";
}

[[nodiscard]] Expected<CoverageNow> coverage_now_from_json(std::string_view text) {
  const json::JsonParse parsed = json::parse_json(text, 8);
  if (!parsed.value || !parsed.value->is_object()) return fail(ErrorCode::Parse, "analyze now: not a JSON object");
  const json::JsonValue& v = *parsed.value;
  const auto strings_of = [](const json::JsonValue* field, std::vector<std::string>& out) {
    if (field == nullptr || !field->is_array()) return false;
    for (const json::JsonValue& item : field->array) {
      if (!item.is_string()) return false;
      out.push_back(item.string);
    }
    return true;
  };
  const json::JsonValue* t = v.find("t");
  const json::JsonValue* hazards = v.find("hazards");
  if (t == nullptr || !t->is_number() || hazards == nullptr || !hazards->is_array()) {
    return fail(ErrorCode::Parse, "analyze now: t or hazards missing or wrong");
  }
  if (!readable_seconds(t->number)) {
    return fail(ErrorCode::Parse, "analyze now: t must be a time in seconds of at most 4e9 in magnitude");
  }
  CoverageNow c;
  c.now = read_seconds(t->number);
  for (const json::JsonValue& item : hazards->array) {
    HazardCoverage h;
    const json::JsonValue* name = item.find("hazard");
    const json::JsonValue* gaps = item.find("gaps");
    if (name == nullptr || !name->is_string() || !strings_of(item.find("onsets"), h.onsets) || gaps == nullptr ||
        !gaps->is_array()) {
      return fail(ErrorCode::Parse, "analyze now: a hazard without its name, onsets or gaps");
    }
    h.hazard = name->string;
    for (const json::JsonValue& g : gaps->array) {
      const json::JsonValue* onset = g.find("onset");
      const json::JsonValue* reason = g.find("reason");
      if (onset == nullptr || !onset->is_string() || reason == nullptr || !reason->is_string()) {
        return fail(ErrorCode::Parse, "analyze now: hazard " + h.hazard + ": a gap without its onset or reason");
      }
      h.gaps.push_back(CoverageGap{onset->string, reason->string});
    }
    c.hazards.push_back(std::move(h));
  }
  return c;
}

std::string filter_list_text(const std::vector<FilterRow>& rows) {
  if (rows.empty()) return "no filters\n";
  std::vector<std::vector<std::string>> table;
  for (const FilterRow& f : rows) {
    std::string signals = joined(names_of(f.inputs), ",");
    if (!f.outputs.empty()) signals += " -> " + joined(names_of(f.outputs), ",");
    table.push_back({f.name, f.type, f.target.empty() ? "-" : f.target, f.active ? "ACTIVE" : "PASSIVE",
                     f.edge ? "EDGE" : "LEVEL",
                     std::string(f.enabled ? "enabled" : "disabled") + (f.injected ? ",injected" : ""),
                     f.detected ? "DETECTED" : "-", signals, std::to_string(f.evaluations) + " runs"});
  }
  return columns(table);
}

std::string filter_list_json(const std::vector<FilterRow>& rows) {
  std::string out;
  for (const FilterRow& f : rows) {
    out += json::JsonObject()
               .str("filter", f.name)
               .str("type", f.type)
               .str("target", f.target.empty() ? "-" : f.target)
               .str("execution", f.active ? "ACTIVE" : "PASSIVE")
               .str("detection", f.edge ? "EDGE" : "LEVEL")
               .boolean("enabled", f.enabled)
               .boolean("detected", f.detected)
               .strings("inputs", names_of(f.inputs))
               .strings("outputs", names_of(f.outputs))
               .opt("onset", f.onset)
               .boolean("injected", f.injected)
               .raw("last_sample", f.last_sample ? json::json_seconds(*f.last_sample) : "null")
               .integer("evaluations", static_cast<long long>(f.evaluations))
               .text() +
           "\n";
  }
  return out;
}

std::string filter_info_text(const FilterInfo& info) {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  auto sized = [](const std::vector<SignalRef>& signals) {
    std::vector<std::string> items;
    for (const SignalRef& s : signals) items.push_back(s.name + " (size " + std::to_string(s.size) + ")");
    return items.empty() ? std::string("-") : joined(items, ", ");
  };
  if (info.filter) {
    const FilterRow& f = *info.filter;
    line("filter " + f.name + ": " + info.type + " - " + info.doc);
    line("  target " + (f.target.empty() ? std::string("-") : f.target) + ", " + (f.active ? "ACTIVE" : "PASSIVE") +
         ", " + (f.edge ? "EDGE" : "LEVEL"));
    line(std::string("  ") + (f.enabled ? "enabled" : "disabled") + (f.injected ? ", injected" : "") + ", " +
         (f.detected ? "detected (onset sent, no completion yet)" : "not detected") + ", " +
         std::to_string(info.missed_samples) + " missed samples");
    line("  onset " + (f.onset.empty() ? std::string("-") : f.onset) + "; " + std::to_string(f.evaluations) +
         " runs; newest sample judged " + (f.last_sample ? seconds_text(*f.last_sample) + " s" : std::string("none")));
    line("  inputs:  " + sized(f.inputs));
    line("  outputs: " + sized(f.outputs));
  } else {
    line("filter type " + info.type + ": " + info.doc);
    line("  inputs:  " + (info.inputs.empty() ? std::string("-") : joined(info.inputs, ", ")));
    line("  outputs: " + (info.outputs.empty() ? std::string("-") : joined(info.outputs, ", ")));
  }
  line("  parameters:");
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"    name", "type", info.filter ? "value" : "", "default", "range", "doc"});
  for (const ParamRow& p : info.params) {
    const std::string value = info.filter ? (p.value ? param_text(*p.value) : std::string("-")) : std::string();
    const std::string range = range_text(p);
    rows.push_back(
        {"    " + p.name, std::string(to_string(p.type)), value, default_text(p), range.empty() ? "-" : range, p.doc});
  }
  if (!info.filter) {
    for (auto& r : rows) r.erase(r.begin() + 2);
  }
  return out + columns(rows);
}

std::string filter_info_json(const FilterInfo& info) {
  json::JsonObject head;
  head.opt("filter", info.filter ? info.filter->name : std::string())
      .str("type", info.type)
      .str("doc", info.doc)
      .strings("inputs", info.inputs)
      .strings("outputs", info.outputs)
      .boolean("generates_events", info.generates_events);
  if (info.filter) {
    const FilterRow& f = *info.filter;
    head.str("target", f.target)
        .str("execution", f.active ? "ACTIVE" : "PASSIVE")
        .str("detection", f.edge ? "EDGE" : "LEVEL")
        .boolean("enabled", f.enabled)
        .boolean("detected", f.detected)
        .integer("missed_samples", static_cast<long long>(info.missed_samples))
        .strings("input_signals", names_of(f.inputs))
        .strings("output_signals", names_of(f.outputs));
  }
  std::string out = head.text() + "\n";
  for (const ParamRow& p : info.params) {
    json::JsonObject j;
    j.str("param", p.name)
        .str("type", to_string(p.type))
        .raw("default", p.default_value ? param_json(*p.default_value) : "null")
        .boolean("required", !p.default_value && !p.optional);
    if (p.type == ParamType::Number || p.type == ParamType::Integer) {
      j.raw("min", p.min > -1e299 ? json::json_number(p.min) : "null")
          .raw("max", p.max < 1e299 ? json::json_number(p.max) : "null");
    }
    if (p.type == ParamType::Choice) j.strings("choices", p.choices);
    if (info.filter) j.raw("value", p.value ? param_json(*p.value) : "null");
    out += j.str("doc", p.doc).text() + "\n";
  }
  return out;
}

std::string event_list_text(const std::vector<EventRow>& rows) {
  std::vector<std::vector<std::string>> table;
  for (const EventRow& e : rows) {
    std::string extra;
    if (!e.counterpart.empty()) extra += (e.onset ? "cleared by " : "clears ") + e.counterpart;
    if (e.latched) extra += (extra.empty() ? "" : ", ") + std::string("latched");
    if (e.framework) extra += (extra.empty() ? "" : ", ") + std::string("framework");
    if (!e.hazard.empty()) extra += (extra.empty() ? "" : ", ") + std::string("hazard ") + e.hazard;
    if (!e.description.empty()) extra += (extra.empty() ? "" : " - ") + e.description;
    table.push_back({e.name, std::to_string(e.severity), event_kind(e), transitions_text(e.transitions), extra});
  }
  return columns(table);
}

std::string event_list_json(const std::vector<EventRow>& rows) {
  std::string out;
  for (const EventRow& e : rows) {
    out += json::JsonObject()
               .str("event", e.name)
               .integer("severity", e.severity)
               .str("kind", event_kind(e))
               .str("transitions", transitions_text(e.transitions))
               .opt(e.onset ? "completion" : "completes", e.counterpart)
               .boolean("latched", e.latched)
               .boolean("framework", e.framework)
               .opt("hazard", e.hazard)
               .opt("description", e.description)
               .text() +
           "\n";
  }
  return out;
}

std::string connection_list_text(const std::vector<ConnectionRow>& rows) {
  if (rows.empty()) return "no connections\n";
  std::vector<std::vector<std::string>> table;
  for (const ConnectionRow& k : rows) {
    table.push_back(
        {k.required, "->", k.provided, "s_R " + (k.required_state ? state_text(*k.required_state) : std::string("?")),
         k.service_state ? "s_S " + state_text(*k.service_state) : std::string("s_S ? (in another process)"),
         k.propagate ? "propagates " + propagates_text(*k.propagate) : std::string("remote provider")});
  }
  return columns(table);
}

std::string connection_list_json(const std::vector<ConnectionRow>& rows) {
  std::string out;
  for (const ConnectionRow& k : rows) {
    json::JsonObject j;
    j.str("required", k.required).str("provided", k.provided);
    if (k.required_state)
      j.str("required_state", to_string(*k.required_state));
    else
      j.null("required_state");
    if (k.service_state)
      j.str("service_state", to_string(*k.service_state));
    else
      j.null("service_state");
    if (k.propagate)
      j.str("propagates", to_string(*k.propagate));
    else
      j.null("propagates");
    out += j.boolean("remote", k.remote).text() + "\n";
  }
  return out;
}

std::string service_list_text(const std::vector<ServiceRow>& rows) {
  if (rows.empty()) return "no provided interfaces\n";
  std::vector<std::vector<std::string>> table;
  for (const ServiceRow& s : rows) {
    table.push_back({s.address, state_text(s.state), "= " + joined(s.depends_on, " * "),
                     "(propagates " + propagates_text(s.propagate) + ")"});
  }
  return columns(table);
}

std::string service_list_json(const std::vector<ServiceRow>& rows) {
  std::string out;
  for (const ServiceRow& s : rows) {
    out += json::JsonObject()
               .str("service", s.address)
               .str("state", to_string(s.state))
               .strings("depends_on", s.depends_on)
               .str("propagates", to_string(s.propagate))
               .text() +
           "\n";
  }
  return out;
}

}  // namespace safecass::introspect
