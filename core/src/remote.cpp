// Remote provided interfaces: the stand-ins through which roots of other processes enter the local
// propagation (DESIGN §2.6 across processes, §4 middleware).

#include <algorithm>
#include <string>
#include <tuple>

#include "safecass/core/coordinator.hpp"

namespace safecass {

Expected<MachineId> Coordinator::add_remote_provided(std::string_view provider_provided, State propagate) {
  const std::string text(provider_provided);
  const auto dot = provider_provided.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 == provider_provided.size() ||
      provider_provided.find('.', dot + 1) != std::string_view::npos) {
    return fail(ErrorCode::InvalidArgument,
                "remote provided interface '" + text + "' must be written Component.Interface");
  }
  if (propagate == State::Normal) {
    return fail(ErrorCode::InvalidArgument,
                "remote provided interface '" + text + "': propagate must be Warning or Error");
  }
  const std::string_view component = provider_provided.substr(0, dot);
  const std::string_view iface = provider_provided.substr(dot + 1);
  ComponentId id = kNoComponent;
  if (auto found = structure_.find_component(component)) {
    if (!structure_.components_[*found].remote) {
      return fail(ErrorCode::Duplicate, "remote provided interface '" + text + "': component '" +
                                            std::string(component) + "' runs in this process");
    }
    id = *found;
  } else {
    auto added = add_component(component);
    if (!added) return tl::unexpected(added.error());
    id = *added;
    structure_.components_[id].remote = true;
  }
  auto machine = add_provided(id, iface);
  if (!machine) return tl::unexpected(machine.error());
  ServiceDependency dependency = ServiceDependency::provided_only();
  dependency.propagate = propagate;
  if (auto r = set_service(id, iface, dependency); !r) return tl::unexpected(r.error());
  return *machine;
}

ResolvedRoot Coordinator::resolve_root(const RootCause& root) const {
  ResolvedRoot r;
  if (root.event == kNoEvent || to_index(root.event) >= structure_.event_count()) return r;
  r.event = structure_.event(root.event).name;
  // A root from another process names its origin there (interned when it arrived), not the local
  // stand-in it came through; the name is kept by value, so it outlives the root's remote slot.
  if (root.remote_origin != kNoName) {
    r.origin = std::string(structure_.name_of(root.remote_origin));
  } else if (machines_.contains(root.origin)) {
    r.origin = structure_.address_of(root.origin);
  }
  r.time = root.time;
  if (root.sample.filter != kNoName) r.filter = std::string(structure_.name_of(root.sample.filter));
  if (root.sample.signal != kNoName) {
    r.signal = std::string(structure_.name_of(root.sample.signal));
    r.value = root.sample.value;
    r.sample_time = root.sample.sample_time;
  }
  r.injected = root.sample.injected;
  return r;
}

Expected<RemoteApplyResult> Coordinator::apply_remote(MachineId proxy, const std::vector<RemoteRoot>& roots) {
  if (!machines_.contains(proxy) || structure_.machine_kind(proxy) != MachineKind::Provided ||
      !structure_.is_remote(structure_.machine_component(proxy))) {
    return fail(ErrorCode::NotFound,
                "machine " + std::to_string(to_index(proxy)) + " is not a remote provided interface");
  }
  const std::string& where = structure_.address_of(proxy);
  // Check everything before changing anything.
  std::vector<EventId> ids;
  ids.reserve(roots.size());
  for (std::size_t i = 0; i < roots.size(); ++i) {
    const ResolvedRoot& r = roots[i].root;
    const std::string what =
        "update of " + where + ", root " + std::to_string(i) + " ('" + r.event + "' at '" + r.origin + "')";
    auto e = structure_.find_event(r.event);
    if (!e) return fail(ErrorCode::InvalidArgument, what + ": no event '" + r.event + "' in this system");
    if (!structure_.event(*e).is_onset)
      return fail(ErrorCode::InvalidArgument, what + ": '" + r.event + "' is not an onset");
    if (roots[i].level == State::Normal)
      return fail(ErrorCode::InvalidArgument, what + ": level Normal is not a condition");
    if (r.origin.empty()) return fail(ErrorCode::InvalidArgument, what + ": empty origin");
    for (std::size_t j = 0; j < i; ++j) {
      if (roots[j].root.origin == r.origin && roots[j].root.event == r.event && roots[j].root.time == r.time) {
        return fail(ErrorCode::InvalidArgument, what + ": reported twice");
      }
    }
    ids.push_back(*e);
  }
  std::vector<SampleCause> samples(roots.size());
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (!roots[i].root.filter.empty()) samples[i].filter = intern(roots[i].root.filter);
    if (!roots[i].root.signal.empty()) samples[i].signal = intern(roots[i].root.signal);
    samples[i].value = roots[i].root.value;
    samples[i].sample_time = roots[i].root.sample_time;
    samples[i].injected = roots[i].root.injected;
  }

  if (delivering_here()) {
    return fail(ErrorCode::InvalidState, "apply_remote() called from a callback or observer");
  }
  std::unique_lock lock(mutex_);
  RemoteApplyResult result;
  const Time now = clock_->now();
  MachineData& m = machines_[proxy];

  // Path-vector rule: a root that has already passed through a machine this interface feeds is
  // coming back around a cycle of processes; mirroring it again would keep it alive forever.
  std::vector<bool> wanted(roots.size(), true);
  for (std::size_t i = 0; i < roots.size(); ++i) {
    for (const Edge& e : m.fanout) {
      const std::string& receiver = structure_.address_of(e.to);
      if (std::find(roots[i].path.begin(), roots[i].path.end(), receiver) != roots[i].path.end()) {
        wanted[i] = false;
        ++result.dropped;
        break;
      }
    }
  }
  auto same = [&](const Condition& c, std::size_t i) {
    const RemoteRootData& d = remote_roots_[c.root.remote];
    return c.root.event == ids[i] && c.root.time == roots[i].root.time && d.origin == roots[i].root.origin;
  };

  // Roots no longer reported: clear them and everything they reached.
  for (std::size_t k = m.conditions.size(); k-- > 0;) {
    if (k >= m.conditions.size()) continue;  // propagation around a cycle may have shrunk the set
    const Condition c = m.conditions[k];
    if (c.root.remote == kNone || c.root.origin != proxy) continue;
    std::size_t match = roots.size();
    for (std::size_t i = 0; i < roots.size(); ++i) {
      if (wanted[i] && same(c, i)) match = i;
    }
    if (match < roots.size()) {
      RemoteRootData& d = remote_roots_[c.root.remote];
      d.path = roots[match].path.empty() ? std::vector<std::string>{roots[match].root.origin} : roots[match].path;
      wanted[match] = false;  // already held
      ++result.kept;
      continue;
    }
    remove_condition(proxy, k, framework_event::completion_of(c.event), now, kTextNoLongerReported);
    propagate_clear(c.root, c.level, now);
    remote_roots_[c.root.remote].used = false;
    remote_roots_[c.root.remote].path.clear();
    free_remote_.push_back(c.root.remote);
    ++result.removed;
  }

  // New roots: hold them here and mirror them wherever they reach.
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (!wanted[i]) continue;
    std::uint32_t slot;
    if (!free_remote_.empty()) {
      slot = free_remote_.back();
      free_remote_.pop_back();
    } else {
      slot = static_cast<std::uint32_t>(remote_roots_.size());
      remote_roots_.emplace_back();
    }
    RemoteRootData& d = remote_roots_[slot];
    d.used = true;
    d.origin = roots[i].root.origin;
    d.path = roots[i].path.empty() ? std::vector<std::string>{roots[i].root.origin} : roots[i].path;
    const EventId mirror_event =
        roots[i].level == State::Error ? framework_event::kServiceFailure : framework_event::kServiceDegraded;
    Condition c;
    c.event = mirror_event;
    c.level = roots[i].level;
    c.severity = structure_.event(mirror_event).severity;
    c.mirror = true;
    c.first = c.last = now;
    c.seq = ++condition_seq_;
    c.root = RootCause{ids[i], proxy, roots[i].root.time, samples[i], slot, intern(roots[i].root.origin)};
    add_condition(proxy, c, now);
    propagate_onset(c);
    ++result.added;
  }
  const Sealed sealed = seal();
  lock.unlock();
  finish(sealed);
  return result;
}

}  // namespace safecass

namespace safecass {

std::vector<RemoteRoot> Coordinator::service_roots(ComponentId component, std::uint32_t service) const {
  // The same roots, levels and shortest paths as explain() of the service address gives, built
  // straight from the conditions: no Explanation (machine, event and hazard texts) per condition.
  const std::lock_guard lock(mutex_);
  std::vector<RemoteRoot> out;
  if (!components_.contains(component) || service >= structure_.provided_machines(component).size()) return out;
  std::vector<EventId> ids;  // out[i]'s root event, compared by id rather than by name
  std::vector<const Condition*> sorted;
  auto visit = [&](MachineId id) {
    const MachineData& m = machines_[id];
    if (m.conditions.empty()) return;
    sorted.clear();
    for (const Condition& k : m.conditions) sorted.push_back(&k);
    // explain()'s order within a machine: the first condition seen gives a root its level.
    std::sort(sorted.begin(), sorted.end(), [](const Condition* a, const Condition* b) {
      if (a->level != b->level) return a->level > b->level;
      if (a->severity != b->severity) return a->severity > b->severity;
      return a->seq > b->seq;
    });
    for (const Condition* k : sorted) {
      const bool remote = k->root.remote != kNone && k->root.remote < remote_roots_.size();
      const std::string& origin = remote ? remote_roots_[k->root.remote].origin : structure_.address_of(k->root.origin);
      std::size_t i = 0;
      while (i < out.size() &&
             !(ids[i] == k->root.event && out[i].root.time == k->root.time && out[i].root.origin == origin))
        ++i;
      if (i < out.size()) {
        std::vector<std::string> path = hop_path(id, *k);
        if (path.size() < out[i].path.size()) out[i].path = std::move(path);
        continue;
      }
      RemoteRoot r;
      r.root = resolve_root(k->root);
      r.level = k->level;
      r.path = hop_path(id, *k);
      out.push_back(std::move(r));
      ids.push_back(k->root.event);
    }
  };
  for (MachineId m : structure_.machines_of(component)) {
    if (depends_on(component, service, m)) visit(m);
  }
  return out;
}

}  // namespace safecass
