#include "common.hpp"

namespace safecass {

void register_builtin_filters(FilterRegistry& registry) {
  builtin::register_detection(registry);
  builtin::register_transforms(registry);
  builtin::register_timing(registry);
  // The 2016 specifications name filters "Filter<Type>"; they load unchanged.
  for (const FilterManifest* m : registry.manifests()) {
    if (m->type.rfind("Filter", 0) != 0) (void)registry.alias("Filter" + m->type, m->type);
  }
  (void)registry.alias("Persistence", "Debounce");
  (void)registry.alias("Heartbeat", "Watchdog");
  (void)registry.alias("Period", "Frequency");
  // The 2016 trend-velocity filter: a Derivative (its `time_scaling` argument included).
  (void)registry.alias("TrendVel", "Derivative");
  (void)registry.alias("FilterTrendVel", "Derivative");
}

const FilterRegistry& builtin_filters() {
  static const FilterRegistry registry = [] {
    FilterRegistry r;
    register_builtin_filters(r);
    return r;
  }();
  return registry;
}

}  // namespace safecass
