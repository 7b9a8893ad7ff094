#include "safecass/spec/diagnostics.hpp"

#include "safecass/spec/json.hpp"

namespace safecass::spec {

std::string format(const Diagnostic& d) {
  std::string out = d.where.file;
  if (d.where.line > 0) {
    out += ':' + std::to_string(d.where.line) + ':' + std::to_string(d.where.column);
  }
  out += d.severity == Diagnostic::Severity::Error ? ": error: " : ": warning: ";
  out += d.message;
  if (!d.pointer.empty()) out += " [" + d.pointer + "]";
  return out;
}

std::string to_json(const Diagnostic& d) {
  const bool error = d.severity == Diagnostic::Severity::Error;
  return "{\"file\": " + json_quote(d.where.file) + ", \"line\": " + std::to_string(d.where.line) +
         ", \"column\": " + std::to_string(d.where.column) + ", \"severity\": " +
         (error ? "\"error\"" : "\"warning\"") + ", \"message\": " + json_quote(d.message) +
         ", \"pointer\": " + json_quote(d.pointer) + "}";
}

}  // namespace safecass::spec
