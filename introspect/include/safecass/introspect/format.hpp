#pragma once
/// @file format.hpp
/// The one text formatter and the one JSON formatter of the read model, used by every tool: the
/// console, the viewer, the timeline, the supervisor, `safecass run` and the history file.
///
/// Times: a simulated run shows its scenario seconds ("t=0.301000"); a live system shows
/// wall-clock time, ISO 8601 in the local zone with milliseconds ("2026-03-01T14:02:11.532+01:00"),
/// converted from the host's monotonic clock with the offset its ClockInfo gives. JSON keeps
/// times as seconds of the system's clock ("t":0.301000), the history-file format.

#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/core/text.hpp"
#include "safecass/introspect/model.hpp"
#include "safecass/json/read.hpp"

namespace safecass::introspect {

/// `items` with `separator` between them: joined({"a", "b"}, ", ") == "a, b".
std::string joined(const std::vector<std::string>& items, std::string_view separator);

/// How the times of one system are written.
class TimeFormat {
public:
  TimeFormat() = default;
  explicit TimeFormat(const ClockInfo& clock) : base_(clock.base), wall_offset_ns_(clock.wall_offset_ns) {}
  TimeFormat(TimeBase base, std::int64_t wall_offset_ns) : base_(base), wall_offset_ns_(wall_offset_ns) {}
  /// The time a record line starts with: "t=0.301000" or "2026-03-01T14:02:11.532+01:00".
  std::string at(Time t) const;
  /// A time inside a sentence: "0.301000 s" or "2026-03-01T14:02:11.532+01:00".
  std::string stamp(Time t) const;
  TimeBase base() const noexcept { return base_; }

private:
  TimeBase base_ = TimeBase::Simulated;
  std::int64_t wall_offset_ns_ = 0;
};

/// ISO 8601 in the local time zone with milliseconds: "2026-03-01T14:02:11.532+01:00".
std::string iso8601_local(std::int64_t unix_ns);
/// Text for an HTML or XML document (the timeline and trace pages, `safecass run --junit`):
/// & < > " ' become character references; every other byte is copied.
std::string markup_text(std::string_view text);
/// Left-aligned columns, two spaces apart; the last column is not padded. Each row ends in '\n'.
std::string columns(const std::vector<std::vector<std::string>>& rows);
/// "N2E,W2E".
std::string transitions_text(const std::vector<Transition>& transitions);
/// A parameter value as text ("30", "true", "[a, b]") and as JSON.
std::string param_text(const ParamValue& v);
std::string param_json(const ParamValue& v);

// ---- history records --------------------------------------------------------------------------

/// "t=0.301000  JR3.s_A  Normal -> Error  EVT_FORCE_ERROR  [filter force_limit, JR3.ForceNorm = 35]".
std::string history_text(const HistoryEntry& e, const TimeFormat& time);
/// The history-file line (no newline): {"seq":..,"t":..,"kind":..,...,"root":{...},"text":..}.
/// Deterministic: same entry, same bytes. A non-finite sample value is written as a string
/// ("nan", "inf", "-inf") so that it is not lost.
std::string history_json(const HistoryEntry& e);
/// A history-file line read back (one parsed JSON object): the one reader of what history_json()
/// writes, for the timeline and trace. "kind", "t" and, but for an injection, "from" and "to" are
/// required, an event needs its "outcome" and "machine", a transition its "machine", a component
/// transition its "component", a reset or injection one of them; "seq", "level", "severity",
/// "mirror", "root" and "text" are optional. Errors (Parse): the first wrong field, said as
/// `missing "machine" (...)` or `"to" must be Normal, Warning or Error, not "Bad"`; a root's
/// prefixed `in "root": `. An overflow line ({"kind":"overflow"}) is not a record: its kind is
/// unknown here.
[[nodiscard]] Expected<HistoryEntry> history_entry_from_json(const json::JsonValue& line);
/// Whether `watch` shows a record as it happens: transitions, resets, injections, and masked or
/// ignored events.
bool shown_while_watching(const HistoryEntry& e) noexcept;

// ---- lines of a live log (`safecass run`, the supervisor) ----------------------------------------

/// A record as one line of a live log, after the reporter's tag ("[robot] ", "supervisor: "):
/// a transition "JR3.s_A Normal -> Error EVT_FORCE_ERROR (root JR3.s_A:EVT_FORCE_ERROR)", a reset
/// "reset BMM (operator: why)", an event "JR3.s_A masked EVT_X", an injection "JR3.s_A injection
/// (text)". Names are copied as they are: a caller that prints text from a message escapes it.
std::string live_line(const HistoryEntry& e);
/// A state as one line of a live log: "C.s_S.Out Error (roots JR3.s_A:EVT_X)"; the note in
/// brackets is left out when empty.
std::string live_state_line(std::string_view address, State state, std::string_view note);

// ---- explanations -----------------------------------------------------------------------------

/// "CONTROL.s_R.ForceData: Error EVT_SERVICE_FAILURE (severity 220) <- JR3.s_A:EVT_FORCE_ERROR since ... path ...".
std::string explanation_text(const Explanation& e, const TimeFormat& time);
/// One object with every field of the explanation; `address` is what was asked.
std::string explanation_json(const std::string& address, const Explanation& e);
/// The lines of `explain`: one per condition, or "ADDRESS is STATE: no active condition".
std::string explain_text(const ExplainAnswer& a, const TimeFormat& time);
std::string explain_json(const ExplainAnswer& a);

// ---- lists ------------------------------------------------------------------------------------
// Each *_text returns the whole table (lines ending in '\n'); each *_json one object per row,
// one per line.

std::string state_list_text(const std::vector<StateRow>& rows);
std::string state_list_json(const std::vector<StateRow>& rows);
/// "SYSTEM Error: 5 components, 3 Normal, 1 Warning, 1 Error", then one line per component that
/// is not Normal (name, state, outstanding event).
std::string state_summary_text(const StateSummary& summary);
/// One line: {"system":..,"normal":N,"warning":N,"error":N,"not_normal":[{"component","state","outstanding"}]}.
std::string state_summary_json(const StateSummary& summary);
/// The inverse of state_summary_json(). Errors: Parse (what is missing or wrong).
[[nodiscard]] Expected<StateSummary> state_summary_from_json(std::string_view json);
/// `analyze now`: each hazard, covered or UNCOVERED with each gap, and a last line that counts them.
std::string coverage_now_text(const CoverageNow& coverage);
/// {"t":...,"uncovered":N,"hazards":[{"hazard":...,"covered":...,"onsets":[...],"gaps":[{"onset":...,"reason":...}]}]}
std::string coverage_now_json(const CoverageNow& coverage);
/// The inverse of coverage_now_json(). Errors: Parse (what is missing or wrong).
[[nodiscard]] Expected<CoverageNow> coverage_now_from_json(std::string_view json);

std::string filter_list_text(const std::vector<FilterRow>& rows);
std::string filter_list_json(const std::vector<FilterRow>& rows);
std::string filter_info_text(const FilterInfo& info);
std::string filter_info_json(const FilterInfo& info);
std::string event_list_text(const std::vector<EventRow>& rows);
std::string event_list_json(const std::vector<EventRow>& rows);
std::string connection_list_text(const std::vector<ConnectionRow>& rows);
std::string connection_list_json(const std::vector<ConnectionRow>& rows);
std::string service_list_text(const std::vector<ServiceRow>& rows);
std::string service_list_json(const std::vector<ServiceRow>& rows);

}  // namespace safecass::introspect
