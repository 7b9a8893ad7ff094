#pragma once
// `safecass timeline`: a recorded history (the JSON lines of `safecass run --record`) as one
// self-contained static HTML page of Normal/Warning/Error swimlanes.
//
// The work is split in three pure steps, so that each can be tested on its own:
//   parse_history()        text → records, every malformed line reported with its number
//                          (records_of(): records already in memory);
//   timeline_model_json()  records → the page's data model (lanes, bars, markers, overflow bands);
//   render_timeline_page() records → the whole page (template, CSS and JS embedded at build time).
// run_timeline() reads a file, runs the three and writes the page.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/introspect/model.hpp"

namespace safecass::timeline {

/// One record the timeline draws: a history record (introspect's HistoryEntry, the one record
/// type: read from a history line by introspect::history_entry_from_json, or taken from a live
/// coordinator) or an overflow mark the recorder wrote where it dropped records.
struct HistoryRecord {
  int line = 0;                    ///< 1-based line number in the history file (or the record's number)
  bool overflow = false;           ///< {"kind":"overflow","dropped":N}: the recorder dropped records here
  std::uint64_t dropped = 0;       ///< overflow: how many
  introspect::HistoryEntry entry;  ///< every record but an overflow mark
  bool root_time_known = true;     ///< false when the line's root cause had no "t"
  std::string json;                ///< the record as JSON (the line as read), re-emitted into the page
};

struct HistoryError {
  int line = 0;
  std::string message;
};

struct HistoryParse {
  std::vector<HistoryRecord> records;
  std::vector<HistoryError> errors;  ///< empty when every line is a valid record
  /// The last line when it was torn: the file does not end with a newline and that line's JSON
  /// stops short (the recording process was killed in the middle of writing it). Not a record and
  /// not an error: every complete record before it is drawn, and the command warns about it.
  std::optional<HistoryError> torn;
};

/// Reads history text, one JSON object per line. Every line must be a record: an empty line,
/// invalid JSON, an unknown kind, a missing or mistyped field, or a time earlier than the
/// previous record's is an error naming its line. Nothing is skipped, with one exception: a torn
/// last line (see HistoryParse::torn), which a killed recorder leaves behind. Overflow lines
/// (`{"kind":"overflow","dropped":N}`) are records too.
HistoryParse parse_history(std::string_view text);

/// Records taken as they are (a live coordinator's history, a trace's run), numbered from 1, for
/// timeline_model_json() and render_timeline_page(): no JSON text in between.
std::vector<HistoryRecord> records_of(const std::vector<introspect::HistoryEntry>& entries);

/// The data model the page draws, as JSON (deterministic; safe to embed in a <script> element):
/// {"start","end","records","transitions","overflows":[...],"groups":[{"component","lanes":[
///   {"address","kind":"component"|"machine","bars":[...],"markers":[...]}]}]}.
/// Documented in docs/tools.md, section "Timeline". Expects records as parse_history() returns them.
std::string timeline_model_json(const std::vector<HistoryRecord>& records);

/// The whole page: the embedded template with the model, the history (as a JSON array, one
/// element per line), a static summary and the overflow warnings. `title` names the history
/// (usually its file name); `torn`, when given, is a torn last line, shown as a warning. Same
/// records and title → same bytes.
std::string render_timeline_page(const std::vector<HistoryRecord>& records, const std::string& title,
                                 const std::optional<HistoryError>& torn = std::nullopt);

/// `safecass timeline HISTORY --html OUT`: 0 the page was written (after a torn last line too:
/// then "HISTORY:LINE: warning: ..." on stderr and on the page); 2 the history cannot be read
/// (not a regular file, larger than 64 MiB), has a malformed line (each printed as
/// "HISTORY:LINE: error: message"), or OUT cannot be written.
int run_timeline(const std::string& history, const std::string& html_out);

/// Renders `records` and writes the page to `html_out`. Returns 0, or 2 after printing
/// "safecass timeline: cannot write ..." to stderr.
int write_timeline_page(const std::vector<HistoryRecord>& records, const std::string& title,
                        const std::string& html_out, const std::optional<HistoryError>& torn = std::nullopt);

}  // namespace safecass::timeline
