#pragma once
/// @file registry.hpp
/// Creates filters by type name. A registry is an ordinary object (no singleton): built-ins are
/// added by register_builtin_filters(), user types the same way:
///
///     FilterRegistry registry;
///     register_builtin_filters(registry);
///     registry.add<MyFilter>("MyFilter");
///
/// A filter type T provides `static FilterManifest manifest()`, a constructor `T(FilterInit)`, and
/// optionally `static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&)` to
/// check input sizes and size its outputs (default: every input and output is a scalar).

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/filters/filter.hpp"
#include "safecass/filters/params.hpp"

namespace safecass {

/// What the sizing check of a filter type sees: its checked parameters and resolved inputs.
struct FilterShape {
  const std::string& filter;  ///< instance name, for messages
  const Params& params;
  const std::vector<Signal*>& inputs;  ///< manifest order, lists expanded
};

/// Checks input sizes and returns the size of each output (manifest order).
using ShapeCheck = std::function<Expected<std::vector<std::size_t>>(const FilterShape&)>;
using FilterFactory = std::function<std::unique_ptr<Filter>(FilterInit)>;

/// The default ShapeCheck: every input must be a scalar; every output is a scalar.
[[nodiscard]] Expected<std::vector<std::size_t>> scalar_shape(const FilterManifest& manifest, const FilterShape& shape);

namespace detail {
template <class T, class = void>
struct HasOutputSizes : std::false_type {};
template <class T>
struct HasOutputSizes<T, std::void_t<decltype(T::output_sizes(std::declval<const FilterShape&>()))>> : std::true_type {
};
}  // namespace detail

class FilterRegistry {
public:
  struct Entry {
    FilterManifest manifest;
    FilterFactory factory;
    ShapeCheck shape;
  };

  /// Registers type T under `type`. Errors: Duplicate.
  template <class T>
  [[nodiscard]] Expected<void> add(std::string type) {
    FilterManifest m = T::manifest();
    m.type = type;
    ShapeCheck shape;
    if constexpr (detail::HasOutputSizes<T>::value) {
      shape = [](const FilterShape& s) { return T::output_sizes(s); };
    }
    return add(
        std::move(type), std::move(m),
        [](FilterInit init) -> std::unique_ptr<Filter> { return std::make_unique<T>(std::move(init)); },
        std::move(shape));
  }
  /// Registers a type from its parts. An empty `shape` means scalar_shape. Errors: Duplicate.
  [[nodiscard]] Expected<void> add(std::string type, FilterManifest manifest, FilterFactory factory,
                                   ShapeCheck shape = {});
  /// Makes `alias` another name of `type` (the 2016 names: "FilterThreshold" → "Threshold").
  [[nodiscard]] Expected<void> alias(std::string alias, std::string type);

  /// The entry for a type or alias, or nullptr.
  const Entry* find(std::string_view type) const noexcept;
  /// Every registered type (not aliases), in registration order.
  std::vector<const FilterManifest*> manifests() const;
  /// Every alias and the type it names, in registration order.
  const std::vector<std::pair<std::string, std::string>>& aliases() const noexcept { return aliases_; }

private:
  std::vector<std::pair<std::string, std::unique_ptr<Entry>>> entries_;
  std::vector<std::pair<std::string, std::string>> aliases_;
};

/// Adds Threshold, Range, OnOff, ChangeDetection, Derivative, MovingAverage, Norm, Arithmetic,
/// Vectorize, Bypass, NOP, Debounce, Occurrence, Watchdog, Frequency, DutyCycle and Deadline, and
/// the 2016 names (`Filter` + type) as aliases.
void register_builtin_filters(FilterRegistry& registry);

/// The built-in types alone (register_builtin_filters()), made once on first use (thread-safe) and
/// never changed: the registry of a program that has no filter type of its own, and the default
/// of every library that takes a registry.
const FilterRegistry& builtin_filters();

}  // namespace safecass
