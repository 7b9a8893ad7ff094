#pragma once
/// @file action_observer.hpp
/// ActionObserver: what a LocalQuery tells of the writes it applied (local_query.hpp,
/// LocalOptions::actions). Plain C++17, so framework extensions built as C++17 can implement it.

#include <string_view>
#include <vector>

namespace safecass::introspect {

/// Told of every write a LocalQuery applied, after it succeeded (a refused write is not told): a
/// live coordinator records the operator's actions next to its inputs with it, so a replay of the
/// recording applies them at the same times. Called on the writing thread; must not call back
/// into the query.
class ActionObserver {
public:
  virtual ~ActionObserver() = default;
  virtual void generated(std::string_view event, std::string_view target) = 0;
  virtual void broadcast(std::string_view event) = 0;
  virtual void injected(std::string_view filter, const std::vector<std::vector<double>>& samples) = 0;
  virtual void injected_deep(std::string_view signal, const std::vector<std::vector<double>>& samples) = 0;
  virtual void reset(std::string_view target, std::string_view who, std::string_view why) = 0;
};

}  // namespace safecass::introspect
