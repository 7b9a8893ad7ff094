// explain(): each active condition with its root cause and the path of hops it took (DESIGN §2.6).

#include <algorithm>

#include "safecass/core/address.hpp"
#include "safecass/core/coordinator.hpp"

namespace safecass {

std::vector<std::string> Coordinator::hop_path(MachineId holder, const Condition& condition) const {
  if (!condition.mirror) return {structure_.address_of(holder)};
  // The shortest path of hops the condition's level passes, found by a breadth-first search from
  // the origin along the same edges propagation uses. Walking back from the holder instead can
  // circle a cycle of connections forever (every machine on the cycle holds a mirror).
  const MachineId origin = condition.root.origin;
  constexpr std::size_t kUnseen = static_cast<std::size_t>(-1);
  std::vector<std::size_t> parent_edge(machines_.size(), kUnseen);  // index into `edges`
  std::vector<std::pair<MachineId, const Edge*>> edges;             // (from, edge)
  std::vector<MachineId> queue{origin};
  std::vector<bool> seen(machines_.size(), false);
  seen[to_index(origin)] = true;
  for (std::size_t head = 0; head < queue.size() && !seen[to_index(holder)]; ++head) {
    const MachineId from = queue[head];
    for (const Edge& e : machines_[from].fanout) {
      if (condition.level < e.min_level || seen[to_index(e.to)]) continue;
      seen[to_index(e.to)] = true;
      parent_edge[to_index(e.to)] = edges.size();
      edges.emplace_back(from, &e);
      queue.push_back(e.to);
    }
  }
  std::vector<std::string> reversed{structure_.address_of(holder)};
  for (MachineId at = holder; at != origin && parent_edge[to_index(at)] != kUnseen;) {
    const auto [from, edge] = edges[parent_edge[to_index(at)]];
    const Connection& conn = structure_.connections_[to_index(edge->via)];
    const MachineId provided = structure_.provided_machines(conn.provider)[conn.provided];
    reversed.push_back(address::service(structure_.component_name(conn.provider), structure_.interface_name(provided)));
    reversed.push_back(structure_.address_of(from));
    at = from;
  }
  std::reverse(reversed.begin(), reversed.end());
  if (condition.root.remote != kNone && condition.root.remote < remote_roots_.size()) {
    // A remote root: its hops in the provider's process, then the local ones after the remote
    // provided interface (which stands for the provider's machine that feeds the service).
    std::vector<std::string> full = remote_roots_[condition.root.remote].path;
    full.insert(full.end(), reversed.begin() + 1, reversed.end());
    return full;
  }
  return reversed;
}

std::vector<Explanation> Coordinator::explain_machine(MachineId id) const {
  const MachineData& m = machines_[id];
  std::vector<const Condition*> sorted;
  for (const Condition& c : m.conditions) sorted.push_back(&c);
  std::sort(sorted.begin(), sorted.end(), [](const Condition* a, const Condition* b) {
    if (a->level != b->level) return a->level > b->level;
    if (a->severity != b->severity) return a->severity > b->severity;
    return a->seq > b->seq;
  });
  std::vector<Explanation> out;
  for (const Condition* c : sorted) {
    Explanation e;
    e.machine = structure_.address_of(id);
    e.event = structure_.event(c->event).name;
    e.level = c->level;
    e.severity = c->severity;
    e.mirror = c->mirror;
    e.outstanding = m.conditions.outstanding() == c;
    e.count = c->count;
    e.first = c->first;
    e.last = c->last;
    e.root = resolve_root(c->root);
    e.hazard = structure_.event(c->root.event).hazard;
    e.path = hop_path(id, *c);
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<Explanation> Coordinator::explain(const Address& address) const {
  const std::lock_guard lock(mutex_);
  std::vector<MachineId> machines;
  switch (address.kind) {
    case Address::Kind::System:
      for (MachineId m : id_range<MachineId>(machines_.size())) machines.push_back(m);
      break;
    case Address::Kind::Component: machines = structure_.machines_of(address.component); break;
    case Address::Kind::Service:
      for (MachineId m : structure_.machines_of(address.component)) {
        if (depends_on(address.component, address.service, m)) machines.push_back(m);
      }
      break;
    case Address::Kind::Machine: machines.push_back(address.machine); break;
  }
  std::vector<Explanation> out;
  for (MachineId m : machines) {
    auto part = explain_machine(m);
    out.insert(out.end(), std::make_move_iterator(part.begin()), std::make_move_iterator(part.end()));
  }
  return out;
}

}  // namespace safecass
