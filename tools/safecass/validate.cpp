// `safecass validate` and `safecass schema`.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "safecass/filters/registry.hpp"
#include "safecass/json/write.hpp"
#include "safecass/spec/spec.hpp"
#include "spec_commands.hpp"

namespace safecass::tools {

namespace {

/// A regular file that can be opened; opened without blocking, so a FIFO is refused at once.
bool readable(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return false;
  struct stat st {};
  const bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  ::close(fd);
  return regular;
}

}  // namespace

int run_validate(const std::vector<std::string>& files, bool json_output, bool verbose) {
  const FilterRegistry& registry = builtin_filters();
  std::size_t errors = 0;
  std::size_t warnings = 0;
  bool unreadable = false;
  for (const std::string& file : files) {
    std::vector<spec::Diagnostic> diagnostics;
    if (!readable(file)) {
      unreadable = true;
      spec::Diagnostic d;
      d.where.file = file;
      d.message = "cannot read file '" + file + "'";
      diagnostics.push_back(std::move(d));
    } else {
      spec::LoadResult loaded = spec::load_system(file, registry);
      diagnostics = std::move(loaded.diagnostics);
      if (verbose && !loaded.notes.empty()) {
        // Notes go among the diagnostics, in file and position order.
        diagnostics.insert(diagnostics.end(), loaded.notes.begin(), loaded.notes.end());
        std::map<std::string, std::size_t> rank;  // files in the order they first appear (load order)
        for (const spec::Diagnostic& d : diagnostics) rank.emplace(d.where.file, rank.size());
        std::stable_sort(diagnostics.begin(), diagnostics.end(),
                         [&](const spec::Diagnostic& a, const spec::Diagnostic& b) {
                           if (a.where.file != b.where.file) return rank[a.where.file] < rank[b.where.file];
                           if (a.where.line != b.where.line) return a.where.line < b.where.line;
                           return a.where.column < b.where.column;
                         });
      }
    }
    for (const spec::Diagnostic& d : diagnostics) {
      if (d.severity == spec::Diagnostic::Severity::Error) ++errors;
      if (d.severity == spec::Diagnostic::Severity::Warning) ++warnings;
      std::printf("%s\n", (json_output ? spec::to_json(d) : spec::format(d)).c_str());
    }
  }
  if (json_output) {
    const std::string summary = json::JsonObject()
                                    .strings("files", files)
                                    .integer("errors", static_cast<long long>(errors))
                                    .integer("warnings", static_cast<long long>(warnings))
                                    .text();
    std::printf("%s\n", summary.c_str());
  } else {
    std::printf("%zu error%s, %zu warning%s\n", errors, errors == 1 ? "" : "s", warnings, warnings == 1 ? "" : "s");
  }
  std::fflush(stdout);
  if (unreadable) return 2;
  return errors > 0 ? 1 : 0;
}

int run_schema() {
  const FilterRegistry& registry = builtin_filters();
  const std::string schema = spec::json_schema(registry);
  std::fwrite(schema.data(), 1, schema.size(), stdout);
  std::fflush(stdout);
  return 0;
}

}  // namespace safecass::tools
