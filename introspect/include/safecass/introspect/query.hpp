#pragma once
/// @file query.hpp
/// SystemQuery: the one interface through which every tool reads (and, with write access,
/// changes) a running system. Two implementations: LocalQuery (local_query.hpp) over a
/// Coordinator, its Monitor and the FilterRegistry of this process, and the middleware's
/// RemoteClient (safecass/middleware/client.hpp) over a live coordinator process. The
/// middleware's Control servant answers with a LocalQuery, so both give the same answers.
///
/// Every answer is a value type of model.hpp with names resolved. Errors are the system's own:
/// NotFound / Parse / InvalidArgument (bad names or arguments: nothing changed), Denied (a write
/// refused), Io (a remote system that does not answer). Thread-safety: one thread at a time,
/// except that records reach a follow() sink on the thread that produced them.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/introspect/model.hpp"

namespace safecass::introspect {

/// Receives the records of a followed system, in stream order, each once.
using RecordSink = std::function<void(const HistoryEntry&)>;

/// A follow() in progress; the sink is not called any more once this is destroyed.
class Subscription {
public:
  virtual ~Subscription() = default;
  /// Delivers the records the stream has not delivered yet, and returns how many. A remote stream
  /// sees a lost record as a gap only when a later one arrives: a follower calls this when the
  /// stream has been quiet for a while, and before it stops, so the last records are not lost with
  /// nothing after them. Errors: Io (a remote system that does not answer). In-process: nothing
  /// is ever missing (0).
  [[nodiscard]] virtual Expected<std::size_t> catch_up() { return std::size_t{0}; }
};

class SystemQuery {
public:
  virtual ~SystemQuery() = default;

  /// The coordinator (or in-process system) this query answers for.
  virtual std::string name() const = 0;
  [[nodiscard]] virtual Expected<ClockInfo> clock() = 0;

  // ---- reads -----------------------------------------------------------------------------------
  /// SYSTEM (the product over the components), then for each component in declaration order its
  /// extended state, s_F, s_A, each s_P, each s_R and each s_S. With `component`: that
  /// component's rows alone, without SYSTEM. Errors: NotFound.
  [[nodiscard]] virtual Expected<std::vector<StateRow>> state_list(std::string_view component = {}) = 0;
  /// The last `last` records (0: all that are kept) about `scope` (SYSTEM or empty, a component,
  /// a service — its component — or a machine), oldest first. Errors: as resolving the address.
  [[nodiscard]] virtual Expected<std::vector<HistoryEntry>> history(std::string_view scope, std::size_t last,
                                                                    HistoryFilter filter = HistoryFilter::All) = 0;
  /// The records kept whose sequence number is above `seq`, oldest first, at most `max` and at
  /// most the coordinator's bound per read (0: that bound; Coordinator::records_since): how a
  /// follower fills a gap in the pushed stream, reading on from the last record until an answer
  /// is empty.
  [[nodiscard]] virtual Expected<std::vector<HistoryEntry>> records_since(std::uint64_t seq, std::size_t max) = 0;
  [[nodiscard]] virtual Expected<std::vector<FilterRow>> filter_list() = 0;
  /// A filter (by name) or a filter type. Errors: NotFound.
  [[nodiscard]] virtual Expected<FilterInfo> filter_info(std::string_view name) = 0;
  [[nodiscard]] virtual Expected<std::vector<EventRow>> event_list() = 0;
  [[nodiscard]] virtual Expected<std::vector<ConnectionRow>> connection_list() = 0;
  [[nodiscard]] virtual Expected<std::vector<ServiceRow>> service_list() = 0;
  /// Errors: as resolving the address.
  [[nodiscard]] virtual Expected<ExplainAnswer> explain(std::string_view address) = 0;
  /// The names TAB completes.
  [[nodiscard]] virtual Expected<Names> names() = 0;
  /// A named read (NamedRead, local_query.hpp: `state summary`, ...): its answer as the JSON that
  /// `--json` prints. A read added there needs no request of its own: a live coordinator answers it
  /// through the one generic request. Errors: NotFound (no such read), those of the read.
  [[nodiscard]] virtual Expected<std::string> read(std::string_view name, const std::vector<std::string>& args) = 0;

  // ---- the record stream ---------------------------------------------------------------------
  /// Calls `sink` for every record from now on, in order and each once (a remote query fills
  /// gaps from records_since()). Errors: Io (a remote stream cannot be subscribed to).
  [[nodiscard]] virtual Expected<std::unique_ptr<Subscription>> follow(RecordSink sink) = 0;

  // ---- writes (the caller checked its own write access; a remote system checks its token) -----
  /// Applies one action (action.hpp) with the system's current time: a deep injection is written
  /// at it. Errors: those of check() (NotFound, InvalidArgument, InvalidState), then nothing
  /// changed; a remote system also Io, Denied (the token) and InvalidArgument for an action the
  /// bus does not carry (a sample: samples come from the system's own framework).
  [[nodiscard]] virtual Expected<void> apply(const Action& action) = 0;
};

}  // namespace safecass::introspect
