#include "model.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "safecass/core/named.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::verify {

namespace {

/// The event a filter generates as its onset and its completion: the first and second event
/// parameters of its type's manifest, as given or by default (as the monitor reads them).
std::pair<std::string, std::string> filter_events(const FilterConfig& config, const FilterRegistry& registry) {
  const FilterRegistry::Entry* entry = registry.find(config.type);
  if (entry == nullptr) return {};
  std::vector<std::string> names;
  for (const ParamSpec& p : entry->manifest.params) {
    if (p.type != ParamType::Event) continue;
    std::string value;
    if (const auto it = config.params.find(p.name); it != config.params.end()) {
      if (const auto* s = std::get_if<std::string>(&it->second)) value = *s;
    } else if (p.default_value) {
      if (const auto* s = std::get_if<std::string>(&*p.default_value)) value = *s;
    }
    names.push_back(value);
    if (names.size() == 2) break;
  }
  names.resize(2);
  return {names[0], names[1]};
}

std::string machine_of(const FilterTarget& t) { return address::machine(t.kind, t.component, t.interface); }

}  // namespace

Expected<std::unique_ptr<Model>> Model::build(const spec::SystemSpec& system, const FilterRegistry& registry) {
  std::unique_ptr<Model> m(new Model());
  spec::InstanceOptions options;
  options.coordinator_options.history_records = 64;
  options.coordinator_options.history_per_address = 1;
  options.signal_history = 2;
  // One process: every component, every connection (cross-process ones become synchronous).
  auto built = spec::build_instance(system, registry, options);
  if (!built) {
    return fail(ErrorCode::InvalidArgument,
                "cannot build system '" + system.name + "': " + spec::to_text(built.error()));
  }
  m->instance_ = std::move(*built);
  m->system_ = &m->instance_->spec();
  if (auto r = m->derive(registry); !r) return tl::unexpected(r.error());
  return m;
}

Expected<void> Model::derive(const FilterRegistry& registry) {
  at_machine_.assign(instance_->coordinator().structure().machine_count(), {});
  derive_roots(registry);
  derive_reach();
  const RootsAt at = roots_at();
  derive_addresses(at);
  derive_levels(at);
  return {};
}

void Model::derive_roots(const FilterRegistry& registry) {
  Coordinator& co = instance_->coordinator();
  std::map<std::string, spec::Position, std::less<>> event_where;
  std::map<std::string, std::string, std::less<>> declared_by;
  for (const spec::ComponentSpec& c : system_->components) {
    for (std::size_t i = 0; i < c.events.size(); ++i) {
      if (i < c.event_where.size()) event_where[c.events[i].name] = c.event_where[i];
      declared_by[c.events[i].name] = c.name;
    }
  }
  std::set<std::pair<std::string, MachineId>> seen;
  std::set<std::string, std::less<>> generated;
  std::map<std::string, int, std::less<>> broadcast_index;
  const auto add_root = [&](const std::string& event, MachineId machine, const std::string& source) {
    auto id = co.structure().find_event(event);
    if (!id) return;
    const Event& e = co.structure().event(*id);
    if (!e.is_onset) return;
    if (e.is_broadcast()) {
      if (broadcast_index.count(event) > 0) return;
      const int b = static_cast<int>(broadcasts_.size());
      broadcast_index[event] = b;
      Broadcast bc;
      bc.event = event;
      if (e.counterpart != kNoEvent) bc.completion = co.structure().event(e.counterpart).name;
      for (ComponentId c : id_range<ComponentId>(co.structure().component_count())) {
        if (co.structure().is_remote(c)) continue;
        Root r;
        r.event = event;
        r.completion = bc.completion;
        r.machine = co.structure().application_machine(c);
        r.transitions = e.transitions;
        r.latched = e.latched;
        r.hazard = e.hazard;
        r.broadcast = b;
        r.source = "broadcast";
        if (const auto w = event_where.find(event); w != event_where.end()) r.where = w->second;
        bc.roots.push_back(roots_.size());
        roots_.push_back(std::move(r));
      }
      broadcasts_.push_back(std::move(bc));
      return;
    }
    if (!seen.emplace(event, machine).second) return;
    Root r;
    r.event = event;
    if (e.counterpart != kNoEvent) r.completion = co.structure().event(e.counterpart).name;
    r.machine = machine;
    r.transitions = e.transitions;
    r.latched = e.latched;
    r.hazard = e.hazard;
    r.source = source;
    if (const auto w = event_where.find(event); w != event_where.end()) r.where = w->second;
    roots_.push_back(std::move(r));
  };

  // Onsets filters generate, on their targets.
  for (const spec::ComponentSpec& c : system_->components) {
    for (const spec::FilterSpec& f : c.filters) {
      for (const FilterConfig& stage : f.stages) {
        const auto [onset, completion] = filter_events(stage, registry);
        if (!onset.empty()) generated.insert(onset);
        if (!completion.empty()) generated.insert(completion);
        if (onset.empty()) continue;
        auto machine = co.structure().find_machine(machine_of(stage.target));
        if (!machine) continue;
        add_root(onset, *machine, "filter '" + stage.name + "'");
      }
    }
  }
  // Onsets a component declares and no filter generates: the component's own code raises them
  // on its s_A (the paper's SC::Generate). Broadcasts: on every s_A.
  for (const spec::ComponentSpec& c : system_->components) {
    auto comp = co.structure().find_component(c.name);
    if (!comp) continue;
    for (const EventDef& e : c.events) {
      auto id = co.structure().find_event(e.name);
      if (!id || !co.structure().event(*id).is_onset) continue;
      if (co.structure().event(*id).is_broadcast()) {
        add_root(e.name, kNoMachine, "broadcast");
      } else if (generated.count(e.name) == 0) {
        add_root(e.name, co.structure().application_machine(*comp), "the code of component '" + c.name + "'");
      }
    }
  }
  for (std::size_t i = 0; i < roots_.size(); ++i) {
    Root& r = roots_[i];
    for (State s : {State::Normal, State::Warning, State::Error})
      r.level[static_cast<std::size_t>(s)] = onset_level(r.transitions, s);
    at_machine_[r.machine].push_back(i);
  }
}

void Model::derive_reach() {
  // From the coordinator itself: a root of each level at each machine that holds roots, and
  // where its mirrors land.
  Coordinator& co = instance_->coordinator();
  const std::size_t machines = co.structure().machine_count();
  reach_error_.assign(machines, IdVector<bool, MachineId>(machines, false));
  reach_warning_.assign(machines, IdVector<bool, MachineId>(machines, false));
  for (MachineId origin : id_range<MachineId>(machines)) {
    if (at_machine_[origin].empty()) continue;
    for (const bool error : {true, false}) {
      const EventId probe = error ? framework_event::kServiceFailure : framework_event::kServiceDegraded;
      co.generate(probe, origin);
      auto& reach = error ? reach_error_[origin] : reach_warning_[origin];
      reach[origin] = true;
      for (MachineId m : id_range<MachineId>(machines)) {
        for (const Condition& c : co.conditions(m)) {
          if (c.mirror && c.root.origin == origin) reach[m] = true;
        }
      }
      (void)reset(co, std::string_view("SYSTEM"), "verify", "probe");
    }
  }
}

Model::RootsAt Model::roots_at() const {
  const std::size_t machines = instance_->coordinator().structure().machine_count();
  const auto machine_roots = [&](MachineId m, bool error) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < roots_.size(); ++i) {
      const auto& reach = error ? reach_error_[roots_[i].machine] : reach_warning_[roots_[i].machine];
      if (roots_[i].machine == m || (!reach.empty() && reach[m])) out.push_back(i);
    }
    return out;
  };
  RootsAt at{IdVector<std::vector<std::size_t>, MachineId>(machines),
             IdVector<std::vector<std::size_t>, MachineId>(machines)};
  for (MachineId m : id_range<MachineId>(machines)) {
    at.error[m] = machine_roots(m, true);
    at.warning[m] = machine_roots(m, false);
  }
  return at;
}

void Model::derive_addresses(const RootsAt& at) {
  const Coordinator& co = instance_->coordinator();
  const auto make = [&](std::string address, std::vector<MachineId> ms, spec::Position where) {
    AddressInfo a;
    a.address = std::move(address);
    a.where = std::move(where);
    std::set<std::size_t> e, w;
    for (MachineId m : ms) {
      e.insert(at.error[m].begin(), at.error[m].end());
      w.insert(at.warning[m].begin(), at.warning[m].end());
    }
    a.error_roots.assign(e.begin(), e.end());
    a.warning_roots.assign(w.begin(), w.end());
    a.machines = std::move(ms);
    addresses_.push_back(std::move(a));
  };
  std::vector<MachineId> all;
  std::map<std::string, spec::Position, std::less<>> component_where;
  for (const spec::ComponentSpec& c : system_->components) component_where[c.name] = c.where;
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count())) {
    if (co.structure().is_remote(c)) continue;
    std::vector<MachineId> ms{co.structure().framework_machine(c), co.structure().application_machine(c)};
    for (MachineId p : co.structure().provided_machines(c)) ms.push_back(p);
    for (MachineId r : co.structure().required_machines(c)) ms.push_back(r);
    all.insert(all.end(), ms.begin(), ms.end());
  }
  make("SYSTEM", all, {});
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count())) {
    if (co.structure().is_remote(c)) continue;
    const std::string name(co.structure().component_name(c));
    const spec::Position where = component_where[name];
    std::vector<MachineId> ms{co.structure().framework_machine(c), co.structure().application_machine(c)};
    for (MachineId p : co.structure().provided_machines(c)) ms.push_back(p);
    for (MachineId r : co.structure().required_machines(c)) ms.push_back(r);
    make(name, ms, where);
    for (MachineId m : ms) make(co.structure().address_of(m), {m}, where);
    for (std::uint32_t p = 0; p < co.structure().provided_machines(c).size(); ++p) {
      const ServiceDependency& d = co.structure().service(c, p);
      std::vector<MachineId> deps{co.structure().provided_machines(c)[p]};
      if (d.framework) deps.push_back(co.structure().framework_machine(c));
      if (d.application) deps.push_back(co.structure().application_machine(c));
      for (MachineId r : co.structure().required_machines(c)) {
        const std::string iface(co.structure().interface_name(r));
        if (d.all_required || std::find(d.required.begin(), d.required.end(), iface) != d.required.end())
          deps.push_back(r);
      }
      make(address::service(name, co.structure().interface_name(co.structure().provided_machines(c)[p])), deps, where);
    }
  }
}

void Model::derive_levels(const RootsAt& at) {
  const std::size_t machines = instance_->coordinator().structure().machine_count();
  can_.assign(roots_.size(), {false, false, false});
  IdVector<std::array<bool, 3>, MachineId> possible(machines, {true, false, false});
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < roots_.size(); ++i) {
      const Root& r = roots_[i];
      for (std::size_t s = 0; s < 3; ++s) {
        if (!possible[r.machine][s]) continue;
        const auto l = static_cast<std::size_t>(r.level[s]);
        if (!can_[i][l]) {
          can_[i][l] = true;
          changed = true;
        }
      }
    }
    for (MachineId m : id_range<MachineId>(machines)) {
      for (std::size_t i : at.error[m]) {
        if (can_[i][2] && !possible[m][2]) possible[m][2] = changed = true;
      }
      for (std::size_t i : at.warning[m]) {
        if (can_[i][1] && !possible[m][1]) possible[m][1] = changed = true;
      }
    }
  }
}

int Model::address_index(std::string_view address) const {
  for (std::size_t i = 0; i < addresses_.size(); ++i) {
    if (addresses_[i].address == address) return static_cast<int>(i);
  }
  return -1;
}

bool Model::can_leave_normal(std::size_t address) const {
  const AddressInfo& a = addresses_[address];
  for (std::size_t r : a.error_roots) {
    if (can_[r][2]) return true;
  }
  for (std::size_t r : a.warning_roots) {
    if (can_[r][1]) return true;
  }
  return false;
}

std::vector<std::size_t> Model::linked(std::string_view hazard) const {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < roots_.size(); ++i) {
    if (!roots_[i].hazard.empty() && roots_[i].hazard == hazard) out.push_back(i);
  }
  return out;
}

std::vector<RootClass> Model::classes(const std::vector<std::size_t>& roots, bool merge) const {
  std::vector<RootClass> out;
  std::map<std::tuple<MachineId, std::uint8_t, bool, std::string, std::string>, std::size_t> index;
  for (std::size_t i : roots) {
    const Root& r = roots_[i];
    if (!merge || r.broadcast >= 0) {
      out.push_back(RootClass{{i}});
      continue;
    }
    // Interchangeable: same machine (resets), same level rule, same latching and clearability,
    // same hazard (reactions tell roots apart by hazard only).
    std::uint8_t bits = 0;
    for (std::size_t s = 0; s < 3; ++s)
      bits = static_cast<std::uint8_t>(bits * 3 + static_cast<std::uint8_t>(r.level[s]));
    const auto key =
        std::make_tuple(r.machine, bits, r.latched, r.clearable() ? std::string("c") : std::string(), r.hazard);
    const auto [it, fresh] = index.emplace(key, out.size());
    if (fresh)
      out.push_back(RootClass{{i}});
    else
      out[it->second].members.push_back(i);
  }
  return out;
}

std::vector<std::size_t> Model::cone(const std::vector<std::size_t>& seed_roots,
                                     const std::vector<std::pair<std::size_t, bool>>& seed_addresses) const {
  std::vector<bool> in(roots_.size(), false);
  std::vector<std::size_t> work;
  const auto add = [&](std::size_t r) {
    if (!in[r]) {
      in[r] = true;
      work.push_back(r);
    }
  };
  const auto add_address = [&](const AddressInfo& a, bool warning) {
    for (std::size_t r : a.error_roots) {
      if (can_[r][2]) add(r);
    }
    if (!warning) return;
    for (std::size_t r : a.warning_roots) {
      if (can_[r][1]) add(r);
    }
  };
  for (std::size_t r : seed_roots) add(r);
  for (const auto& [a, warning] : seed_addresses) add_address(addresses_[a], warning);
  // A root whose level depends on its machine's state depends on every root that can change it.
  for (std::size_t head = 0; head < work.size(); ++head) {
    const Root& r = roots_[work[head]];
    if (r.constant_level()) continue;
    const int a = address_index(machine_address(r.machine));
    if (a >= 0) add_address(addresses_[static_cast<std::size_t>(a)], true);
  }
  // A broadcast's roots outside the cone are left out too: the broadcast step of the model acts
  // on those inside it (the others cannot change what the property reads).
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < roots_.size(); ++i) {
    if (in[i]) out.push_back(i);
  }
  return out;
}

}  // namespace safecass::verify
