// `safecass trace SYSTEM --scenarios S... [--html FILE] [--csv FILE] [--json] [--verify FILE]
// [--strict]` (docs/trace.md).

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>

#include "commands.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/trace/trace.hpp"

namespace safecass::tools {

bool write_output(const char* command, const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (out) out.close();
  if (!out) std::fprintf(stderr, "safecass %s: cannot write '%s'\n", command, path.c_str());
  return static_cast<bool>(out);
}

/// The report's date: now in UTC, or SOURCE_DATE_EPOCH when set (reproducible builds).
std::string report_date() {
  std::time_t now = std::time(nullptr);
  if (const char* epoch = std::getenv("SOURCE_DATE_EPOCH"); epoch != nullptr && *epoch != '\0') {
    char* end = nullptr;
    const long long v = std::strtoll(epoch, &end, 10);
    if (end != nullptr && *end == '\0' && v >= 0) now = static_cast<std::time_t>(v);
  }
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

int run_trace(const TraceArgs& args) {
  const FilterRegistry& registry = builtin_filters();
  trace::TraceOptions options;
  options.system = args.system;
  options.scenarios = args.scenarios;
  options.verify_json = args.verify;
  options.histories = !args.html.empty();
  auto built = trace::build_trace(options, registry);
  if (!built) {
    for (const spec::Diagnostic& d : built.error()) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
    std::fprintf(stderr, "safecass trace: nothing traced (%zu error%s)\n", built.error().size(),
                 built.error().size() == 1 ? "" : "s");
    return 2;
  }
  const trace::Trace& t = *built;
  for (const spec::Diagnostic& d : t.notes) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
  const std::string text = args.json ? trace::trace_json(t) : trace::trace_text(t);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (!args.csv.empty() && !write_output("trace", args.csv, trace::trace_csv(t))) return 2;
  if (!args.html.empty()) {
    if (!write_output("trace", args.html, trace::render_trace_page(t, report_date()))) return 2;
    std::fprintf(stderr, "safecass trace: report written to %s\n", args.html.c_str());
  }
  if (t.has_error_gap()) return 1;
  if (args.strict && !t.gaps.empty()) {
    for (const trace::Gap& g : t.gaps) {
      if (g.severity != trace::Severity::Info) return 1;
    }
  }
  return 0;
}

}  // namespace safecass::tools
