// `safecass validate` and `safecass schema`.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>

#include "safecass/filters/registry.hpp"
#include "safecass/introspect/json.hpp"
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

int run_validate(const std::vector<std::string>& files, bool json_output) {
  FilterRegistry registry;
  register_builtin_filters(registry);
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
      diagnostics = spec::load_system(file, registry).diagnostics;
    }
    for (const spec::Diagnostic& d : diagnostics) {
      (d.severity == spec::Diagnostic::Severity::Error ? errors : warnings) += 1;
      std::printf("%s\n", (json_output ? spec::to_json(d) : spec::format(d)).c_str());
    }
  }
  if (json_output) {
    const std::string summary = introspect::JsonObject().strings("files", files).integer("errors", static_cast<long long>(errors))
                                    .integer("warnings", static_cast<long long>(warnings)).text();
    std::printf("%s\n", summary.c_str());
  } else {
    std::printf("%zu error%s, %zu warning%s\n", errors, errors == 1 ? "" : "s", warnings, warnings == 1 ? "" : "s");
  }
  std::fflush(stdout);
  if (unreadable) return 2;
  return errors > 0 ? 1 : 0;
}

int run_schema() {
  FilterRegistry registry;
  register_builtin_filters(registry);
  const std::string schema = spec::json_schema(registry);
  std::fwrite(schema.data(), 1, schema.size(), stdout);
  std::fflush(stdout);
  return 0;
}

}  // namespace safecass::tools
