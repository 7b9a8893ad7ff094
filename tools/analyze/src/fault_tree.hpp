#pragma once
// The fault trees of the failure modes (fault_tree.cpp) and SCRAM, which computes their cut sets.

#include <optional>
#include <string>
#include <vector>

#include "modes.hpp"

namespace safecass::analyze {

/// The gates of `tops` (each given its gate name); with `order` 1, no escalation (AND) gate.
/// With `reliability` and a rate or probability for every mode, SCRAM also quantifies them.
FaultTrees fault_trees(const std::vector<FailureMode>& modes, const std::vector<std::vector<Raise>>& raises,
                       std::vector<TopEvent> tops, int order, const std::optional<spec::ReliabilitySpec>& reliability);

/// Gives each mode its rate or probability from the system's "reliability" section: an entry
/// named by an event alone applies to every onset mode of that event, one named exactly to that
/// mode (and wins). Errors: an entry that names no failure mode of the analysis, at its position.
[[nodiscard]] spec::Opened<bool> apply_reliability(const spec::ReliabilitySpec& reliability,
                                                   std::vector<FailureMode>& modes);

/// Writes the MEF into `trees.mef`, runs `scram` on it (in `work_dir`, or a private directory)
/// and fills each top's minimal cut sets. Returns SCRAM's version line. Errors: Io (SCRAM missing,
/// failing, or its report unreadable).
[[nodiscard]] Expected<std::string> run_scram(const std::string& system, const std::vector<FailureMode>& modes,
                                              FaultTrees& trees, const std::string& scram, const std::string& work_dir);

/// The number in a mode id ("FM12" → 12), for ordering.
inline std::size_t mode_number(const std::string& id) {
  std::size_t n = 0;
  for (char c : id) {
    if (c >= '0' && c <= '9') n = n * 10 + static_cast<std::size_t>(c - '0');
  }
  return n;
}

}  // namespace safecass::analyze
