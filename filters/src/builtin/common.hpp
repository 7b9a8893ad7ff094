#pragma once
// Shared pieces of the built-in filters (internal to the filters module).

#include <string>
#include <vector>

#include "safecass/filters/filter.hpp"
#include "safecass/filters/registry.hpp"

namespace safecass::builtin {

/// `event_onset` / `event_completion` (the onset is optional for filters that can be pure transforms).
inline void add_event_params(FilterManifest& m, bool required = false) {
  m.params.push_back(
      ParamSpec::event("event_onset", "event generated when the condition is detected", std::nullopt, !required));
  m.params.push_back(ParamSpec::event("event_completion",
                                      "event generated when the condition clears (default: the onset's completion)",
                                      std::nullopt, true));
}

/// Persistence in samples or seconds: counts how long a condition has held.
class Persistence {
public:
  Persistence() = default;
  Persistence(double amount, bool seconds) : amount_(amount), seconds_(seconds) {}
  /// Feeds one sample's verdict; true once the condition has held long enough.
  bool update(bool condition, Time t) noexcept {
    if (!condition) {
      count_ = 0;
      return false;
    }
    if (count_++ == 0) since_ = t;
    if (seconds_) return to_seconds(t - since_) >= amount_;
    return static_cast<double>(count_) >= (amount_ < 1 ? 1 : amount_);
  }
  void reset() noexcept { count_ = 0; }

private:
  double amount_ = 1;
  bool seconds_ = false;
  std::uint64_t count_ = 0;
  Time since_{};
};

inline ParamSpec persistence_param(double def = 1) {
  return ParamSpec::number("persistence", "how long the condition must hold before the onset (see persistence_unit)",
                           def, 0, 1e9);
}
inline ParamSpec persistence_unit_param() {
  return ParamSpec::choice("persistence_unit", "unit of persistence", {"samples", "seconds"}, "samples");
}

/// Inputs and outputs all of the same size as the first input.
[[nodiscard]] Expected<std::vector<std::size_t>> same_size_shape(const FilterManifest& m, const FilterShape& s);

void register_detection(FilterRegistry& r);
void register_transforms(FilterRegistry& r);
void register_timing(FilterRegistry& r);

}  // namespace safecass::builtin
