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

Diagnostics keep_errors(Diagnostics diagnostics, Diagnostics* notes) {
  Diagnostics errors;
  for (Diagnostic& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error)
      errors.push_back(std::move(d));
    else if (notes != nullptr)
      notes->push_back(std::move(d));
  }
  return errors;
}

void print(const Diagnostics& diagnostics, std::FILE* out) {
  for (const Diagnostic& d : diagnostics) std::fprintf(out, "%s\n", format(d).c_str());
}

std::string to_text(const Diagnostics& diagnostics) {
  std::string text;
  for (const Diagnostic& d : diagnostics) text += (text.empty() ? "" : "\n") + format(d);
  return text;
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

}  // namespace safecass::spec
