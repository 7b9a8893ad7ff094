#include "safecass/spec/diagnostics.hpp"

#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"

#include "text.hpp"

namespace safecass::spec {

std::string format(const Diagnostic& d) {
  std::string out = d.where.file;
  if (d.where.line > 0) {
    out += ':' + std::to_string(d.where.line) + ':' + std::to_string(d.where.column);
  }
  out += d.severity == Diagnostic::Severity::Error     ? ": error: "
         : d.severity == Diagnostic::Severity::Warning ? ": warning: "
                                                       : ": note: ";
  out += d.message;
  if (!d.pointer.empty()) out += " [" + d.pointer + "]";
  return out;
}

std::string to_json(const Diagnostic& d) {
  const char* severity = d.severity == Diagnostic::Severity::Error     ? "error"
                         : d.severity == Diagnostic::Severity::Warning ? "warning"
                                                                       : "note";
  return json::JsonObject()
      .str("file", d.where.file)
      .integer("line", d.where.line)
      .integer("column", d.where.column)
      .str("severity", severity)
      .str("message", d.message)
      .str("pointer", d.pointer)
      .text();
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  return detail::did_you_mean(word, candidates);
}

}  // namespace safecass::spec
