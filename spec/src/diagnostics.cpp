#include "safecass/spec/diagnostics.hpp"

#include "safecass/introspect/json.hpp"
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
  return introspect::JsonObject().str("file", d.where.file).integer("line", d.where.line)
      .integer("column", d.where.column).str("severity", error ? "error" : "warning").str("message", d.message)
      .str("pointer", d.pointer).text();
}

}  // namespace safecass::spec
