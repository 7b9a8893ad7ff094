// `safecass timeline`: history (JSON lines) → model (lanes, bars, markers) → static HTML page.

#include "safecass/timeline/timeline.hpp"
#include "safecass/introspect/format.hpp"

#include "safecass/json/write.hpp"

#include "safecass/json/read.hpp"
#include "safecass/spec/file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>

#include "timeline_assets.hpp"  // generated from web/timeline/ at build time

namespace safecass::timeline {

namespace {

using json::JsonValue;

// ---------------------------------------------------------------------------------------------
// Text helpers (all deterministic: no locale, no pointers, no clocks).

/// Shortest decimal text that reads back as the same double ("0.486", "30.025", "2").
std::string num(double v) {
  char buf[40];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::string("0");
}

/// Seconds for people: at most nine decimals, trailing zeros dropped ("0.252", "1.4", "0").
std::string secs(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9f", v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

/// JSON text made safe inside an HTML <script> element: <, > and & (which JSON allows only inside
/// strings) are written as \u003c, \u003e and \u0026.
std::string script_safe(std::string_view json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    switch (c) {
      case '<': out += "\\u003c"; break;
      case '>': out += "\\u003e"; break;
      case '&': out += "\\u0026"; break;
      default: out += c;
    }
  }
  return out;
}

/// A parsed line written back as compact JSON by the JSON writer, members in file order
/// (comments dropped).
std::string canonical(const JsonValue& v) {
  switch (v.type) {
    case JsonValue::Type::Null: return "null";
    case JsonValue::Type::Bool: return v.boolean ? "true" : "false";
    case JsonValue::Type::Number: return num(v.number);
    case JsonValue::Type::String: return json::json_string(v.string);
    case JsonValue::Type::Array: {
      json::JsonArray a;
      for (const JsonValue& item : v.array) a.raw(canonical(item));
      return a.text();
    }
    case JsonValue::Type::Object: {
      json::JsonObject o;
      for (const auto& member : v.object) o.raw(member.key, canonical(member.value));
      return o.text();
    }
  }
  return "null";
}

// ---------------------------------------------------------------------------------------------
// Reading one line.

/// A time in seconds as read ("0.301" reads back as 0.301: the nanoseconds divided, not
/// multiplied by 1e-9, so that the page shows the file's numbers).
double seconds(Time t) { return static_cast<double>(t.count()) / 1e9; }
double t_of(const HistoryRecord& r) { return seconds(r.entry.time); }
std::string state_of(State s) { return std::string(to_string(s)); }

/// Checks and types one parsed line. Returns an error message, or nothing when the record is good.
std::optional<std::string> read_record(const JsonValue& v, HistoryRecord& r) {
  if (const JsonValue* kind = v.is_object() ? v.find("kind") : nullptr;
      kind != nullptr && kind->is_string() && kind->string == "overflow") {
    r.overflow = true;
    const JsonValue* dropped = v.find("dropped");
    if (dropped == nullptr) return std::string("missing \"dropped\"");
    if (!dropped->is_number()) {
      return "\"dropped\" must be a number, not " + std::string(json::type_name(dropped->type));
    }
    const double n = dropped->number;
    if (n < 0 || n != std::floor(n) || n > 9.0e15)
      return "\"dropped\" must be a whole number of records, not " + num(n);
    r.dropped = static_cast<std::uint64_t>(n);
    return std::nullopt;
  }
  auto entry = introspect::history_entry_from_json(v);
  if (!entry) return entry.error().message;
  r.entry = std::move(*entry);
  const JsonValue* root = v.find("root");
  r.root_time_known = root == nullptr || root->find("t") != nullptr;
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// The model.

std::string component_of(const HistoryRecord& r) {
  if (!r.entry.component.empty()) return r.entry.component;
  return r.entry.machine.substr(0, r.entry.machine.find('.'));
}

/// Where a machine's lane goes inside its component: framework, application, provided,
/// required, service, anything else (DESIGN §2.2 order).
int machine_rank(std::string_view address) {
  const auto dot = address.find('.');
  const std::string_view rest = dot == std::string_view::npos ? std::string_view() : address.substr(dot + 1);
  if (rest == "s_F") return 0;
  if (rest == "s_A") return 1;
  if (rest.starts_with("s_P")) return 2;
  if (rest.starts_with("s_R")) return 3;
  if (rest.starts_with("s_S")) return 4;
  return 5;
}

struct Bar {
  std::string state;
  double from = 0.0;
  std::optional<double> to;                ///< nothing: still in this state at the end of the history
  const HistoryRecord* entered = nullptr;  ///< the transition that began it; null for the initial state
  std::string reset_text;                  ///< a reset at the same time, when no event caused it
};

struct Marker {
  std::string kind;
  const HistoryRecord* record = nullptr;
};

struct Lane {
  std::string address;
  bool component = false;
  std::optional<std::string> initial;  ///< state before the first record that tells it
  std::vector<Bar> bars;
  std::vector<Marker> markers;
};

struct Group {
  std::string component;
  std::map<std::string, Lane> machines;  // by address
  Lane extended;
};

struct LastReset {
  double t = 0.0;
  std::string text;
};

/// The root cause of a record; `clears` when the record ends that condition (an improving transition).
std::string root_lines(const HistoryRecord& r, bool clears = false) {
  if (!r.entry.root) return {};
  const ResolvedRoot& root = *r.entry.root;
  std::string out = std::string(clears ? "\nclears root cause " : "\nroot cause ") + root.name() +
                    (r.root_time_known ? " at " + secs(seconds(root.time)) + " s" : std::string());
  if (!root.filter.empty() || !root.signal.empty() || root.injected) {
    out += "\n";
    std::string detail;
    if (!root.filter.empty()) detail += "filter " + root.filter;
    if (!root.signal.empty()) {
      detail += (detail.empty() ? "" : ", ") + root.signal + " = " + num(root.value) + " (sample at " +
                secs(seconds(root.sample_time)) + " s)";
    }
    if (root.injected) detail += (detail.empty() ? "" : ", ") + std::string("injected sample");
    out += detail;
  }
  return out;
}

std::string bar_tip(const Lane& lane, const Bar& b) {
  std::string tip = lane.address + (lane.component ? " (extended state): " : ": ") + b.state + "\n";
  tip += secs(b.from) + " s to " +
         (b.to ? secs(*b.to) + " s (" + secs(*b.to - b.from) + " s)" : std::string("the end of the history"));
  if (b.entered == nullptr) return tip + "\nstate at the start of the history";
  const HistoryRecord& r = *b.entered;
  if (!r.entry.event.empty()) {
    tip += "\nentered by " + r.entry.event + " (history line " + std::to_string(r.line) + ")";
  } else if (!b.reset_text.empty()) {
    tip += "\nentered by a reset (history line " + std::to_string(r.line) + ")\nreason: " + b.reset_text;
  } else {
    tip += "\nentered at history line " + std::to_string(r.line);
  }
  return tip + root_lines(r, r.entry.to < r.entry.from);
}

std::string marker_tip(const Lane& lane, const Marker& m) {
  const HistoryRecord& r = *m.record;
  std::string head;
  if (m.kind == "ignored")
    head = "Ignored completion " + r.entry.event;
  else if (m.kind == "masked")
    head = "Masked onset " + r.entry.event + " (below the current state)";
  else if (m.kind == "override")
    head = "Override: onset " + r.entry.event + " at the current level, now outstanding";
  else if (m.kind == "joined")
    head = "Joined: onset " + r.entry.event + " at the current level";
  else if (m.kind == "cleared")
    head =
        "Cleared " +
        (r.entry.event.empty() ? "condition " + (r.entry.root ? r.entry.root->event : std::string()) : r.entry.event) +
        " (no state change)";
  else if (m.kind == "reset")
    head = "Reset (state before: " + state_of(r.entry.from) + ")";
  else
    head = "Fault injection";
  std::string tip =
      head + "\n" + lane.address + ", t = " + secs(t_of(r)) + " s (history line " + std::to_string(r.line) + ")";
  if (r.entry.kind == RecordKind::Event) {
    tip += "\n";
    tip += "level " + state_of(r.entry.level) + ", ";
    tip += "severity " + std::to_string(r.entry.severity);
    if (r.entry.mirror) tip += ", mirrored from a provider";
  }
  tip += root_lines(r);
  if (!r.entry.text.empty()) tip += (r.entry.kind == RecordKind::Injection ? "\n" : "\nreason: ") + r.entry.text;
  return tip;
}

/// One lane of the model as JSON (the JSON writer), one bar or marker a line so that golden diffs
/// read well. Not yet safe inside <script>: model_json() makes the whole text so.
std::string lane_json(const Lane& l) {
  using json::JsonArray;
  using json::JsonObject;
  JsonArray bars(JsonArray::Layout::OnePerLine);
  for (const Bar& b : l.bars) {
    JsonObject bar;
    bar.str("state", b.state).raw("from", num(b.from)).raw("to", b.to ? num(*b.to) : "null");
    if (b.entered != nullptr) {
      bar.integer("line", b.entered->line);
      if (!b.entered->entry.event.empty()) bar.str("event", b.entered->entry.event);
    }
    bars.raw(bar.str("tip", bar_tip(l, b)).text());
  }
  JsonArray markers(JsonArray::Layout::OnePerLine);
  for (const Marker& m : l.markers) {
    JsonObject marker;
    marker.str("kind", m.kind).raw("t", num(t_of(*m.record))).integer("line", m.record->line);
    if (!m.record->entry.event.empty()) marker.str("event", m.record->entry.event);
    markers.raw(marker.str("tip", marker_tip(l, m)).text());
  }
  return JsonObject()
      .str("address", l.address)
      .str("kind", l.component ? "component" : "machine")
      .raw("bars", bars.text())
      .raw("markers", markers.text())
      .text();
}

}  // namespace

// ---------------------------------------------------------------------------------------------

HistoryParse parse_history(std::string_view text) {
  HistoryParse out;
  std::optional<double> last_t;
  int line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") == std::string_view::npos) {
      out.errors.push_back({line_no, "empty line: expected a JSON object (one record per line)"});
      continue;
    }
    json::JsonParse parsed = json::parse_json(line, 16);
    if (parsed.error) {
      HistoryError e{line_no, "invalid JSON at column " + std::to_string(parsed.error->position.column) + ": " +
                                  parsed.error->message};
      // The recorder ends every record with a newline: a last line without one that is not even
      // JSON was being written when the recording process died.
      if (eol == text.size()) {
        out.torn = std::move(e);
      } else {
        out.errors.push_back(std::move(e));
      }
      continue;
    }
    HistoryRecord r;
    r.line = line_no;
    if (auto problem = read_record(*parsed.value, r)) {
      out.errors.push_back({line_no, std::move(*problem)});
      continue;
    }
    if (!r.overflow) {
      if (last_t && t_of(r) < *last_t) {
        out.errors.push_back({line_no, "time " + secs(t_of(r)) + " s is earlier than the previous record's (" +
                                           secs(*last_t) + " s): records must be in time order"});
        continue;
      }
      last_t = t_of(r);
    }
    r.json = canonical(*parsed.value);
    out.records.push_back(std::move(r));
  }
  return out;
}

std::vector<HistoryRecord> records_of(const std::vector<introspect::HistoryEntry>& entries) {
  std::vector<HistoryRecord> out;
  out.reserve(entries.size());
  for (const introspect::HistoryEntry& e : entries) {
    HistoryRecord r;
    r.line = static_cast<int>(out.size()) + 1;
    r.entry = e;
    r.json = introspect::history_json(e);
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

struct Model {
  double start = 0.0;
  double end = 0.0;
  std::size_t transitions = 0;
  std::size_t lanes = 0;
  std::vector<Group> groups;  // in order of first appearance
  struct Band {
    const HistoryRecord* record;
    double from;
    std::optional<double> to;
  };
  std::vector<Band> overflows;
};

Model build_model(const std::vector<HistoryRecord>& records) {
  Model m;
  bool any_time = false;
  for (const HistoryRecord& r : records) {
    if (r.overflow) continue;
    if (!any_time || t_of(r) < m.start) m.start = t_of(r);
    m.end = any_time ? std::max(m.end, t_of(r)) : t_of(r);
    any_time = true;
  }
  // Time 0 is the coordinator's start (clock epoch): show it unless a record comes before it.
  m.start = std::min(m.start, 0.0);
  m.end = std::max(m.end, m.start);

  std::map<std::string, std::size_t> group_index;
  auto group = [&](const std::string& component) -> Group& {
    auto [it, added] = group_index.emplace(component, m.groups.size());
    if (added) {
      m.groups.emplace_back();
      m.groups.back().component = component;
      m.groups.back().extended.address = component;
      m.groups.back().extended.component = true;
    }
    return m.groups[it->second];
  };
  auto lane_of = [&](const HistoryRecord& r) -> Lane& {
    Group& g = group(component_of(r));
    if (r.entry.kind == RecordKind::ComponentTransition || r.entry.machine.empty()) return g.extended;
    Lane& l = g.machines[r.entry.machine];
    l.address = r.entry.machine;
    return l;
  };

  // Pass 1: the lanes and the state each starts in (the "from" of its first record that has one).
  for (const HistoryRecord& r : records) {
    if (r.overflow) continue;
    Lane& l = lane_of(r);
    const bool tells_state =
        r.entry.kind == RecordKind::ComponentTransition || (!l.component && r.entry.kind != RecordKind::Injection);
    if (!l.initial && tells_state) l.initial = state_of(r.entry.from);
  }
  auto open = [&](Lane& l) {
    if (l.bars.empty()) l.bars.push_back(Bar{l.initial.value_or("Normal"), m.start, std::nullopt, nullptr, {}});
  };
  for (Group& g : m.groups) {
    open(g.extended);
    for (auto& [address, l] : g.machines) open(l);
  }

  // Pass 2: bars, markers, overflow bands.
  std::map<std::string, LastReset> machine_reset;
  std::map<std::string, LastReset> component_reset;
  std::optional<double> previous_t;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const HistoryRecord& r = records[i];
    if (r.overflow) {
      std::optional<double> next_t;
      for (std::size_t j = i + 1; j < records.size(); ++j) {
        if (!records[j].overflow) {
          next_t = t_of(records[j]);
          break;
        }
      }
      m.overflows.push_back({&r, previous_t.value_or(m.start), next_t});
      continue;
    }
    previous_t = t_of(r);
    Lane& l = lane_of(r);
    switch (r.entry.kind) {
      case RecordKind::Transition:
      case RecordKind::ComponentTransition: {
        ++m.transitions;
        l.bars.back().to = t_of(r);
        Bar b{state_of(r.entry.to), t_of(r), std::nullopt, &r, {}};
        const auto& resets = l.component ? component_reset : machine_reset;
        const auto it = resets.find(l.address);
        if (r.entry.event.empty() && it != resets.end() && it->second.t == t_of(r)) b.reset_text = it->second.text;
        l.bars.push_back(std::move(b));
        break;
      }
      case RecordKind::Event:
        if (const Outcome o = r.entry.outcome; o == Outcome::Ignored || o == Outcome::Masked ||
                                               o == Outcome::Override || o == Outcome::Joined ||
                                               (o == Outcome::Cleared && r.entry.from == r.entry.to)) {
          l.markers.push_back({std::string(to_string(o)), &r});
        }
        break;
      case RecordKind::Reset:
        l.markers.push_back({"reset", &r});
        machine_reset[l.address] = {t_of(r), r.entry.text};
        component_reset[component_of(r)] = {t_of(r), r.entry.text};
        break;
      case RecordKind::Injection: l.markers.push_back({"injection", &r}); break;
    }
  }
  for (const Group& g : m.groups) m.lanes += 1 + g.machines.size();
  return m;
}

std::vector<const Lane*> ordered_machines(const Group& g) {
  std::vector<const Lane*> lanes;
  for (const auto& [address, l] : g.machines) lanes.push_back(&l);
  std::stable_sort(lanes.begin(), lanes.end(),
                   [](const Lane* a, const Lane* b) { return machine_rank(a->address) < machine_rank(b->address); });
  return lanes;
}

std::string model_json(const Model& m, std::size_t record_count) {
  using json::JsonArray;
  using json::JsonObject;
  JsonArray overflows(JsonArray::Layout::OnePerLine);
  for (const auto& band : m.overflows) {
    const std::string tip = "The recorder dropped " + std::to_string(band.record->dropped) +
                            " records here (history line " + std::to_string(band.record->line) +
                            "): states in this interval may be incomplete.";
    overflows.raw(JsonObject()
                      .integer("line", band.record->line)
                      .integer("dropped", static_cast<long long>(band.record->dropped))
                      .raw("from", num(band.from))
                      .raw("to", band.to ? num(*band.to) : "null")
                      .str("tip", tip)
                      .text());
  }
  JsonArray groups(JsonArray::Layout::OnePerLine);
  for (const Group& g : m.groups) {
    JsonArray lanes(JsonArray::Layout::OnePerLine);
    lanes.raw(lane_json(g.extended));
    for (const Lane* l : ordered_machines(g)) lanes.raw(lane_json(*l));
    groups.raw(JsonObject().str("component", g.component).raw("lanes", lanes.text()).text());
  }
  JsonObject model;
  model.raw("start", num(m.start))
      .raw("end", num(m.end))
      .integer("records", static_cast<long long>(record_count))
      .integer("transitions", static_cast<long long>(m.transitions))
      .integer("lanes", static_cast<long long>(m.lanes));
  model.line_break().raw("overflows", overflows.text());
  model.line_break().raw("groups", groups.text());
  return script_safe(model.text());
}

std::string history_json(const std::vector<HistoryRecord>& records) {
  json::JsonArray lines(json::JsonArray::Layout::OnePerLine);
  for (const HistoryRecord& r : records) lines.raw(r.json);
  return script_safe(lines.text());
}

std::string summary_text(const Model& m, std::size_t record_count) {
  if (record_count == 0) return "The history is empty: no transitions.";
  std::string s = std::to_string(record_count) + (record_count == 1 ? " record, " : " records, ");
  s += m.transitions == 0 ? std::string("no transitions")
                          : std::to_string(m.transitions) + (m.transitions == 1 ? " transition" : " transitions");
  s += ", " + std::to_string(m.lanes) + (m.lanes == 1 ? " lane" : " lanes") + " in " + std::to_string(m.groups.size()) +
       (m.groups.size() == 1 ? " component" : " components");
  s += ", from " + secs(m.start) + " s to " + secs(m.end) + " s.";
  return s;
}

std::string warnings_html(const Model& m, const std::optional<HistoryError>& torn) {
  std::string out;
  for (const auto& band : m.overflows) {
    out += "<p class=\"warning\">&#9888; History line " + std::to_string(band.record->line) +
           ": the recorder dropped " + std::to_string(band.record->dropped) + " records between " + secs(band.from) +
           " s and " + (band.to ? secs(*band.to) + " s" : std::string("the end")) +
           "; states in that interval may be incomplete (hatched band).</p>\n";
  }
  if (torn) {
    out += "<p class=\"warning\">&#9888; History line " + std::to_string(torn->line) +
           " is torn (the recording process stopped in the middle of writing it): it is not drawn; every record "
           "before it is.</p>\n";
  }
  return out;
}

/// Replaces each {{NAME}} of the template once, in one pass (inserted text is not scanned again).
std::string fill(std::string_view tmpl, const std::map<std::string, std::string, std::less<>>& values) {
  std::string out;
  out.reserve(tmpl.size());
  std::size_t pos = 0;
  while (pos < tmpl.size()) {
    const std::size_t open = tmpl.find("{{", pos);
    if (open == std::string_view::npos) break;
    const std::size_t close = tmpl.find("}}", open + 2);
    if (close == std::string_view::npos) break;
    const auto it = values.find(tmpl.substr(open + 2, close - open - 2));
    out.append(tmpl.substr(pos, open - pos));
    if (it != values.end()) {
      out += it->second;
    } else {
      out.append(tmpl.substr(open, close + 2 - open));
    }
    pos = close + 2;
  }
  out.append(tmpl.substr(std::min(pos, tmpl.size())));
  return out;
}

}  // namespace

std::string timeline_model_json(const std::vector<HistoryRecord>& records) {
  return model_json(build_model(records), records.size());
}

std::string render_timeline_page(const std::vector<HistoryRecord>& records, const std::string& title,
                                 const std::optional<HistoryError>& torn) {
  const Model m = build_model(records);
  const std::map<std::string, std::string, std::less<>> values{
      {"TITLE", introspect::markup_text(title)}, {"SUMMARY", introspect::markup_text(summary_text(m, records.size()))},
      {"WARNINGS", warnings_html(m, torn)},      {"CSS", std::string(web::kTimelineCss)},
      {"JS", std::string(web::kTimelineJs)},     {"MODEL", model_json(m, records.size())},
      {"HISTORY", history_json(records)},
  };
  return fill(web::kTimelineHtml, values);
}

int run_timeline(const std::string& history, const std::string& html_out) {
  const auto text = spec::read_regular_file(history);
  if (!text) {
    std::fprintf(stderr, "safecass timeline: history: %s\n", text.error().message.c_str());
    return 2;
  }
  const HistoryParse parsed = parse_history(*text);
  if (!parsed.errors.empty()) {
    for (const HistoryError& e : parsed.errors) {
      std::fprintf(stderr, "%s:%d: error: %s\n", history.c_str(), e.line, e.message.c_str());
    }
    std::fprintf(stderr, "safecass timeline: %zu malformed %s in '%s'; no page written\n", parsed.errors.size(),
                 parsed.errors.size() == 1 ? "line" : "lines", history.c_str());
    return 2;
  }
  if (parsed.torn) {
    std::fprintf(stderr,
                 "%s:%d: warning: the last line is torn (no newline at its end, %s): the recording process was "
                 "probably killed while writing it; drawing the %zu complete records before it\n",
                 history.c_str(), parsed.torn->line, parsed.torn->message.c_str(), parsed.records.size());
  }
  std::string title = history;
  if (const auto slash = title.find_last_of('/'); slash != std::string::npos) title.erase(0, slash + 1);
  return write_timeline_page(parsed.records, title, html_out, parsed.torn);
}

int write_timeline_page(const std::vector<HistoryRecord>& records, const std::string& title,
                        const std::string& html_out, const std::optional<HistoryError>& torn) {
  const std::string page = render_timeline_page(records, title, torn);
  std::ofstream out(html_out, std::ios::binary | std::ios::trunc);
  if (out) out.write(page.data(), static_cast<std::streamsize>(page.size()));
  if (out) out.close();
  if (!out) {
    std::fprintf(stderr, "safecass timeline: cannot write '%s'\n", html_out.c_str());
    return 2;
  }
  return 0;
}

}  // namespace safecass::timeline
