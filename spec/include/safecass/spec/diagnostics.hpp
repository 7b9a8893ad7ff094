#pragma once
/// @file diagnostics.hpp
/// Problems found in a specification, each with the file, line and column of the offending value
/// and its JSON pointer, formatted the way compilers do so that editors can jump to them.

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <tl/expected.hpp>

namespace safecass::spec {

/// Where a value is: the file as it was opened (relative paths stay relative), 1-based line and
/// column (columns count bytes). Line 0 means "the file as a whole" (e.g. it cannot be read).
struct Position {
  std::string file;
  int line = 0;
  int column = 0;
};

/// One problem. Errors make a specification unusable; warnings point at something that is
/// probably not what the author meant but can still be loaded. Notes say what the loader did with
/// something it accepts but does not use (a 2016 key it ignores); they are never among
/// LoadResult::diagnostics, only in LoadResult::notes (`safecass validate --verbose`).
struct Diagnostic {
  enum class Severity { Error, Warning, Note } severity = Severity::Error;
  Position where;
  std::string message;
  std::string pointer;  ///< JSON pointer of the value in its file, e.g. /filter/1/argument/threshold
};

/// Every problem found in one piece of work (loading, building), in order.
using Diagnostics = std::vector<Diagnostic>;
/// A value, or every problem that kept it from being made.
template <class T>
using Opened = tl::expected<T, Diagnostics>;

/// "file:line:col: error: message [pointer]" ("warning:", "note:" likewise). The " [pointer]" part is left
/// out when the pointer is empty (the whole document), the ":line:col" part when line is 0.
std::string format(const Diagnostic& diagnostic);

/// One diagnostic as a one-line JSON object:
/// {"file": ..., "line": L, "column": C, "severity": "error"|"warning"|"note", "message": ..., "pointer": ...}.
std::string to_json(const Diagnostic& diagnostic);

/// Keeps the errors of `diagnostics` and moves the others (warnings, notes) to `notes`, or drops
/// them when `notes` is null. Returns the errors, in their order.
Diagnostics keep_errors(Diagnostics diagnostics, Diagnostics* notes);

/// Prints each diagnostic on its own line (format()) to `out`.
void print(const Diagnostics& diagnostics, std::FILE* out);
/// The diagnostics as text, one per line (format()), for an Error message.
std::string to_text(const Diagnostics& diagnostics);

/// "; did you mean 'x'?" when one of `candidates` is near enough to `word` to be a likely typo,
/// else "". The suggestion rule of every diagnostic (specifications, scenarios).
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace safecass::spec
