#pragma once
/// @file load.hpp
/// Loading, validating and instantiating specifications (DESIGN §5).
///
/// load_system() never throws and never crashes, whatever the bytes: every problem becomes a
/// Diagnostic with the position of the offending value, and all of them are reported at once.
/// It is not thread-safe against concurrent changes of the registry; distinct calls may run in
/// parallel.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::spec {

struct LoadResult {
  /// Present when there is no error (warnings allowed).
  std::optional<SystemSpec> system;
  /// Sorted by file (the loaded file first, then included files in load order), line, column.
  std::vector<Diagnostic> diagnostics;
  /// Notes (Severity::Note): what was accepted and ignored, e.g. a 2016 `debug` key; sorted the
  /// same way. Shown by `safecass validate --verbose`.
  std::vector<Diagnostic> notes;

  /// No Error diagnostics.
  bool ok() const;
  std::size_t errors() const;
  std::size_t warnings() const;
};

/// Loads a system file (or a single component file: then the system is that one component),
/// follows includes (paths relative to the including file), and validates everything, reporting
/// every problem at once. Diagnostics name files by the path they were opened with: `path` for
/// the loaded file, `dirname(including file) / include` (lexically normalised) for included ones.
LoadResult load_system(const std::string& path, const FilterRegistry& registry);

/// Same as load_system(), with the top-level file's bytes given: `name` is its path, used in
/// diagnostics and to resolve includes. Used by tools that hold the text and by the fuzzer.
LoadResult load_system_from_text(std::string_view text, const std::string& name, const FilterRegistry& registry);

/// Builds the model into a coordinator and its monitor: components, interfaces, events, services,
/// connections, signals, filters/pipelines. With `only_coordinator` non-empty, only that
/// coordinator's components (and the connections whose both ends are local); every event of the
/// system is defined either way. Errors name the thing (NotFound for an unknown coordinator,
/// otherwise what the coordinator or monitor reported). On error the coordinator and monitor are
/// partly configured: discard them. Precondition: load_system() reported no errors.
[[nodiscard]] Expected<void> instantiate(const SystemSpec& system, Coordinator& coordinator, Monitor& monitor,
                                         std::string_view only_coordinator = {});

}  // namespace safecass::spec
