#pragma once
/// @file coverage.hpp
/// `analyze now`: which hazards a running system cannot detect now (docs/analyze.md, "At run
/// time"). Judged from what any query answers: the event list (each onset's hazard), the filter
/// list (each filter's onset, signals and run-time facts) and the components whose coordinator is
/// lost; so a process answers for itself and a tool can judge the rows it already holds.

#include <string>
#include <vector>

#include "safecass/introspect/model.hpp"

namespace safecass::introspect {

/// A filter that cannot detect now, and why: disabled; judging injected samples; no sample judged
/// yet; or reading a stale signal — one a detected Watchdog watches, or one written by a filter
/// that reads a stale signal. A Watchdog is judged by the first two alone: it detects the absence
/// of samples. Empty: it can detect.
std::string blind_reason(const FilterRow& filter, const std::vector<std::string>& stale_signals);

/// The signals that are stale now: those a detected Watchdog reads, and, to the end of each chain,
/// the outputs of the filters that read a stale one.
std::vector<std::string> stale_signals(const std::vector<FilterRow>& filters);

/// The filters of one process as last read, and whether its coordinator is lost now.
struct ProcessFilters {
  std::string coordinator;
  bool lost = false;
  std::vector<FilterRow> filters;
};

/// Each hazard that an onset of `events` names and whether it is covered at `now`. An onset is
/// uncovered when every filter that raises it is blind (blind_reason()) or runs in a process whose
/// coordinator is lost; or when no filter known here raises it and `lost_elsewhere` names
/// components of other processes whose coordinator is lost (its filter may have run there). An
/// onset no filter raises, with nothing lost, is raised by the components' code: not a gap.
CoverageNow coverage_now(const std::vector<EventRow>& events, const std::vector<ProcessFilters>& processes,
                         const std::vector<std::string>& lost_elsewhere, Time now);

}  // namespace safecass::introspect
