#pragma once
// What the in-process sources (a scenario run, a replay) share: the picture of a system run in
// this process through its read model (introspect::LocalQuery), and explain with the viewer's
// coordinator addresses ("coordinator:NAME").

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "safecass/introspect/local_query.hpp"
#include "safecass/spec/system.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

/// At most this many ticks are processed per poll of an in-process source (a scenario run, a
/// replay), so that a poll never holds the event loop for long; the clock catches up over the
/// next polls.
inline constexpr std::int64_t kMaxTicksPerPoll = 5000;

/// The coordinators of a system file with their components (one named after the coordinator
/// holding every component when the file names none).
using Coordinators = std::vector<std::pair<std::string, std::vector<ComponentId>>>;

Coordinators coordinators_of(const spec::SystemSpec& system, const Coordinator& co);

/// SystemView::coordinators, state and connections, from the read model; the caller fills the rest.
SystemView local_view(const introspect::LocalQuery& query, const Coordinators& coordinators,
                      const std::vector<ConnectionView>& connections);

/// The connections of the system, from the read model (`connection list`).
std::vector<ConnectionView> local_connections(introspect::LocalQuery& query);

/// Every active condition at `address`; "coordinator:NAME" gathers those of its components.
[[nodiscard]] Expected<std::vector<Explanation>> local_explain(introspect::LocalQuery& query, const Coordinator& co,
                                                               const Coordinators& coordinators,
                                                               std::string_view address);

/// The records a local source has produced and the server has not taken yet, as JSON lines.
/// Bounded: past kLimit a record is dropped and counted (memory stays bounded if nobody polls;
/// the server takes them every poll), and take() ends with an overflow line saying how many.
class PendingRecords {
public:
  static constexpr std::size_t kLimit = 100000;
  void push(const introspect::HistoryEntry& e);
  std::vector<std::string> take();
  void clear();

private:
  std::vector<std::string> records_;
  std::uint64_t dropped_ = 0;
};

}  // namespace safecass::viewer
