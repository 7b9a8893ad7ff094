#include "safecass/introspect/coverage.hpp"

#include <algorithm>

#include "safecass/introspect/format.hpp"

namespace safecass::introspect {

namespace {
bool contains(const std::vector<std::string>& items, const std::string& item) {
  return std::find(items.begin(), items.end(), item) != items.end();
}
bool is_watchdog(const FilterRow& f) { return f.type == "Watchdog"; }
}  // namespace

std::size_t CoverageNow::uncovered() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(hazards.begin(), hazards.end(), [](const HazardCoverage& h) { return !h.covered(); }));
}

std::vector<std::string> stale_signals(const std::vector<FilterRow>& filters) {
  std::vector<std::string> stale;
  for (const FilterRow& f : filters) {
    if (!is_watchdog(f) || !f.detected) continue;
    for (const SignalRef& s : f.inputs) {
      if (!contains(stale, s.name)) stale.push_back(s.name);
    }
  }
  // Downstream: what a filter fed by a stale signal writes is stale too (to a fixed point: each
  // pass adds a signal or ends).
  for (bool grew = true; grew;) {
    grew = false;
    for (const FilterRow& f : filters) {
      const bool fed =
          std::any_of(f.inputs.begin(), f.inputs.end(), [&](const SignalRef& s) { return contains(stale, s.name); });
      if (!fed || is_watchdog(f)) continue;
      for (const SignalRef& s : f.outputs) {
        if (contains(stale, s.name)) continue;
        stale.push_back(s.name);
        grew = true;
      }
    }
  }
  return stale;
}

std::string blind_reason(const FilterRow& f, const std::vector<std::string>& stale) {
  const std::string who = "filter " + f.name;
  if (!f.enabled) return who + " is disabled";
  if (f.injected) return who + " judges injected samples";
  if (is_watchdog(f)) return "";
  if (!f.inputs.empty() && !f.last_sample) return who + " has judged no sample yet";
  for (const SignalRef& s : f.inputs) {
    if (contains(stale, s.name)) return who + " reads " + s.name + ", which is stale";
  }
  return "";
}

CoverageNow coverage_now(const std::vector<EventRow>& events, const std::vector<ProcessFilters>& processes,
                         const std::vector<std::string>& lost_elsewhere, Time now) {
  CoverageNow out;
  out.now = now;
  std::vector<FilterRow> all;
  for (const ProcessFilters& p : processes) all.insert(all.end(), p.filters.begin(), p.filters.end());
  const std::vector<std::string> stale = stale_signals(all);
  for (const EventRow& e : events) {
    if (!e.onset || e.hazard.empty()) continue;
    auto h = std::find_if(out.hazards.begin(), out.hazards.end(),
                          [&](const HazardCoverage& c) { return c.hazard == e.hazard; });
    if (h == out.hazards.end()) {
      out.hazards.push_back(HazardCoverage{e.hazard, {}, {}});
      h = out.hazards.end() - 1;
    }
    h->onsets.push_back(e.name);
    std::vector<std::string> reasons;
    bool raised = false;
    bool seeing = false;  // a filter that raises it can detect now
    for (const ProcessFilters& p : processes) {
      for (const FilterRow& f : p.filters) {
        if (f.onset != e.name) continue;
        raised = true;
        std::string reason = p.lost ? "filter " + f.name + " runs in " + p.coordinator + ", whose coordinator is lost"
                                    : blind_reason(f, stale);
        if (reason.empty()) seeing = true;
        if (!reason.empty()) reasons.push_back(std::move(reason));
      }
    }
    if (raised && !seeing) {
      h->gaps.push_back(CoverageGap{e.name, joined(reasons, "; ")});
    } else if (!raised && !lost_elsewhere.empty()) {
      h->gaps.push_back(CoverageGap{
          e.name, "no filter here raises it, and the coordinator of " + joined(lost_elsewhere, ", ") + " is lost"});
    }
  }
  return out;
}

}  // namespace safecass::introspect
