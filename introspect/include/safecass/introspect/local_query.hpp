#pragma once
/// @file local_query.hpp
/// LocalQuery: the SystemQuery of a system in this process, over its Coordinator, Monitor and
/// FilterRegistry. The only place where the facts of the read model are derived from the core:
/// the row order of `state list`, the shape of a history record, the service formulas.
///
/// Reads take the coordinator's lock briefly (its introspection calls) and allocate; they never
/// run on the hot path. follow() converts each record on the thread that produced it.

#include <functional>
#include <memory>
#include <string>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/introspect/query.hpp"

namespace safecass::introspect {

struct LocalOptions {
  std::string name;  ///< what name() answers (default: the coordinator's name)
  /// Simulated (in-process runs) or Host (a live coordinator process on HostClock).
  TimeBase base = TimeBase::Simulated;
  double period = 0.0;                ///< Simulated: the tick, seconds
  std::string scenario;               ///< Simulated: the scenario file, if any
  double duration = 0.0;              ///< Simulated: the scenario's duration, seconds
  ActionObserver* actions = nullptr;  ///< told of every applied action; must outlive the query
};

class LocalQuery final : public SystemQuery {
public:
  /// `co`, `monitor` and `registry` must outlive the query.
  LocalQuery(Coordinator& co, Monitor& monitor, const FilterRegistry& registry, LocalOptions options = {});

  std::string name() const override;
  [[nodiscard]] Expected<ClockInfo> clock() override;
  [[nodiscard]] Expected<std::vector<StateRow>> state_list(std::string_view component = {}) override;
  [[nodiscard]] Expected<std::vector<HistoryEntry>> history(std::string_view scope, std::size_t last,
                                                            HistoryFilter filter) override;
  [[nodiscard]] Expected<std::vector<HistoryEntry>> records_since(std::uint64_t seq, std::size_t max) override;
  [[nodiscard]] Expected<std::vector<FilterRow>> filter_list() override;
  [[nodiscard]] Expected<FilterInfo> filter_info(std::string_view name) override;
  [[nodiscard]] Expected<std::vector<EventRow>> event_list() override;
  [[nodiscard]] Expected<std::vector<ConnectionRow>> connection_list() override;
  [[nodiscard]] Expected<std::vector<ServiceRow>> service_list() override;
  [[nodiscard]] Expected<ExplainAnswer> explain(std::string_view address) override;
  [[nodiscard]] Expected<Names> names() override;
  [[nodiscard]] Expected<std::string> read(std::string_view name, const std::vector<std::string>& args) override;
  [[nodiscard]] Expected<std::unique_ptr<Subscription>> follow(RecordSink sink) override;
  /// Applies `action` at the coordinator's clock (Simulated: never before 0), then tells
  /// LocalOptions::actions.
  [[nodiscard]] Expected<void> apply(const Action& action) override;

  /// The components of other processes whose coordinator is lost (EVT_COORDINATOR_LOST on their
  /// s_F), in declaration order.
  std::vector<std::string> lost_components() const;
  /// `analyze now`: the hazards this process cannot detect now (coverage.hpp), its filters judged
  /// by their run-time facts.
  [[nodiscard]] Expected<CoverageNow> coverage();
  /// The rows of one component (its extended state, s_F, s_A, each s_P, s_R and s_S), in the
  /// order of state_list(). For tools that show a coordinator before it answers.
  std::vector<StateRow> component_rows(ComponentId id) const;

private:
  Coordinator& co_;
  Monitor& monitor_;
  const FilterRegistry& registry_;
  LocalOptions options_;
};

/// A read that is answered as JSON through SystemQuery::read(), in-process and from a live
/// coordinator alike: a new read command is one entry in the table of local_query.cpp (and one in
/// the console's command table), with its value type and formatter (docs/contributing.md).
struct NamedRead {
  std::string_view name;  ///< the console command, "state summary"
  /// The answer, as JSON, of a system in this process.
  Expected<std::string> (*answer)(LocalQuery& query, const std::vector<std::string>& args);
  /// A JSON answer as text, wherever it came from.
  Expected<std::string> (*text)(std::string_view json);
};

/// The read called `name`, or null.
const NamedRead* find_read(std::string_view name) noexcept;
/// The JSON answer of the read called `name` as text. Errors: NotFound, Parse (not its answer).
[[nodiscard]] Expected<std::string> read_text(std::string_view name, std::string_view json);

}  // namespace safecass::introspect
