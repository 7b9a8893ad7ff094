#include "local_view.hpp"

#include <algorithm>
#include <iterator>

#include "safecass/introspect/format.hpp"
#include "safecass/json/write.hpp"
#include "safecass/viewer/live_diff.hpp"

namespace safecass::viewer {

Coordinators coordinators_of(const spec::SystemSpec& system, const Coordinator& co) {
  auto ids_of = [&co](const std::vector<std::string>& names) {
    std::vector<ComponentId> ids;
    for (const std::string& n : names) {
      if (auto id = co.structure().find_component(n)) ids.push_back(*id);
    }
    return ids;
  };
  Coordinators out;
  if (system.coordinators.empty()) {
    std::vector<std::string> all;
    for (const spec::ComponentSpec& c : system.components) all.push_back(c.name);
    out.emplace_back(std::string(co.structure().name()), ids_of(all));
  } else {
    for (const auto& [name, components] : system.coordinators) out.emplace_back(name, ids_of(components));
  }
  return out;
}

SystemView local_view(const introspect::LocalQuery& query, const Coordinators& coordinators,
                      const std::vector<ConnectionView>& connections) {
  SystemView v;
  for (const auto& [name, ids] : coordinators) {
    std::vector<introspect::StateRow> rows;
    for (const ComponentId id : ids) {
      std::vector<introspect::StateRow> part = query.component_rows(id);
      rows.insert(rows.end(), std::make_move_iterator(part.begin()), std::make_move_iterator(part.end()));
    }
    CoordinatorView cv = coordinator_view(name, rows);
    v.state = std::max(v.state, cv.state);
    v.coordinators.push_back(std::move(cv));
  }
  v.connections = connections;
  return v;
}

std::vector<ConnectionView> local_connections(introspect::LocalQuery& query) {
  std::vector<ConnectionView> out;
  auto rows = query.connection_list();
  if (!rows) return out;
  for (const introspect::ConnectionRow& r : *rows) out.push_back(ConnectionView{r.required, r.provided});
  return out;
}

[[nodiscard]] Expected<std::vector<Explanation>> local_explain(introspect::LocalQuery& query, const Coordinator& co,
                                                               const Coordinators& coordinators,
                                                               std::string_view address) {
  if (address.substr(0, 12) == "coordinator:") {
    const std::string_view name = address.substr(12);
    const auto it =
        std::find_if(coordinators.begin(), coordinators.end(), [name](const auto& c) { return c.first == name; });
    if (it == coordinators.end()) return fail(ErrorCode::NotFound, "no coordinator '" + std::string(name) + "'");
    std::vector<Explanation> all;
    for (const ComponentId id : it->second) {
      auto part = query.explain(co.structure().component_name(id));
      if (!part) return tl::unexpected(part.error());
      all.insert(all.end(), part->conditions.begin(), part->conditions.end());
    }
    return all;
  }
  auto answer = query.explain(address);
  if (!answer) return tl::unexpected(answer.error());
  return std::move(answer->conditions);
}

void PendingRecords::push(const introspect::HistoryEntry& e) {
  if (records_.size() >= kLimit) {
    ++dropped_;
    return;
  }
  records_.push_back(introspect::history_json(e));
}

std::vector<std::string> PendingRecords::take() {
  std::vector<std::string> out;
  out.swap(records_);
  if (dropped_ != 0) {
    out.push_back(
        json::JsonObject().str("kind", "overflow").integer("dropped", static_cast<long long>(dropped_)).text());
    dropped_ = 0;
  }
  return out;
}

void PendingRecords::clear() {
  records_.clear();
  dropped_ = 0;
}

}  // namespace safecass::viewer
