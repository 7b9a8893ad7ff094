// explain(): each active condition with its root cause and the path of hops it took (DESIGN §2.6).

#include <algorithm>

#include "safecass/core/address.hpp"
#include "safecass/core/coordinator.hpp"

namespace safecass {

std::vector<std::string> Coordinator::hop_path(MachineId holder, const Condition& condition) const {
  if (!condition.mirror) return {machines_[holder].address};
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
  std::vector<std::string> reversed{machines_[holder].address};
  for (MachineId at = holder; at != origin && parent_edge[to_index(at)] != kUnseen;) {
    const auto [from, edge] = edges[parent_edge[to_index(at)]];
    const Connection& conn = connections_[to_index(edge->via)];
    const ComponentData& provider = components_[conn.provider];
    reversed.push_back(address::service(provider.name, interface_name(provider.provided[conn.provided])));
    reversed.push_back(machines_[from].address);
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
    e.machine = m.address;
    e.event = events_[to_index(c->event)].name;
    e.level = c->level;
    e.severity = c->severity;
    e.mirror = c->mirror;
    e.outstanding = m.conditions.outstanding() == c;
    e.count = c->count;
    e.first = c->first;
    e.last = c->last;
    e.root = resolve_root(c->root);
    e.hazard = events_[to_index(c->root.event)].hazard;
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
    case Address::Kind::Component: {
      const ComponentData& c = components_[address.component];
      machines.push_back(c.framework);
      machines.push_back(c.application);
      machines.insert(machines.end(), c.provided.begin(), c.provided.end());
      machines.insert(machines.end(), c.required.begin(), c.required.end());
      break;
    }
    case Address::Kind::Service: {
      const ComponentData& c = components_[address.component];
      for (MachineId m : {c.framework, c.application}) {
        if (depends_on(address.component, address.service, machines_[m])) machines.push_back(m);
      }
      machines.push_back(c.provided[address.service]);
      for (MachineId m : c.required) {
        if (depends_on(address.component, address.service, machines_[m])) machines.push_back(m);
      }
      break;
    }
    case Address::Kind::Machine: machines.push_back(address.machine); break;
  }
  std::vector<Explanation> out;
  for (MachineId m : machines) {
    auto part = explain_machine(m);
    out.insert(out.end(), std::make_move_iterator(part.begin()), std::make_move_iterator(part.end()));
  }
  return out;
}

Expected<std::vector<Explanation>> Coordinator::explain(std::string_view address) const {
  auto a = resolve(address);
  if (!a) return tl::unexpected(a.error());
  return explain(*a);
}

}  // namespace safecass
