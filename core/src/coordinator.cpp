#include "safecass/core/coordinator.hpp"
#include "safecass/core/address.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

#include "safecass/core/assert.hpp"

namespace safecass {

namespace {

constexpr std::size_t index(State s) noexcept { return static_cast<std::size_t>(s); }

State state_from_counts(const std::array<std::uint32_t, 3>& counts) noexcept {
  if (counts[index(State::Error)] > 0) return State::Error;
  if (counts[index(State::Warning)] > 0) return State::Warning;
  return State::Normal;
}

bool valid_name(std::string_view name) noexcept {
  return !name.empty() && name.find('.') == std::string_view::npos &&
         name.find_first_of(" \t\r\n") == std::string_view::npos;
}

struct FrameworkEventSpec {
  const char* name;
  int severity;
  TransitionSet onset;
  TransitionSet completion;
  const char* description;
};

constexpr TransitionSet kToError{Transition::N2E, Transition::W2E};
constexpr TransitionSet kFromError{Transition::E2N, Transition::E2W};
constexpr TransitionSet kToWarning{Transition::N2W};
constexpr TransitionSet kFromWarning{Transition::W2N};

// Order fixes the ids in framework_event (onset at 2k, completion at 2k+1).
constexpr FrameworkEventSpec kFrameworkEvents[] = {
    {"EVT_SERVICE_FAILURE", 220, kToError, kFromError, "a service this component requires has failed"},
    {"EVT_SERVICE_DEGRADED", 215, kToWarning, kFromWarning, "a service this component requires is degraded"},
    {"EVT_THREAD_EXCEPTION", 210, kToError, kFromError, "the component's thread threw an exception"},
    {"EVT_PERIOD_OVERRUN", 205, kToWarning, kFromWarning, "the component's cycle overran its period"},
    {"EVT_STALE", 230, kToError, kFromError, "no new sample or heartbeat within the timeout"},
    {"EVT_CALLBACK_EXCEPTION", 210, kToError, kFromError, "a SAFECASS callback threw an exception"},
    {"EVT_COORDINATOR_LOST", 240, kToError, kFromError, "a connected coordinator stopped sending heartbeats"},
    {"EVT_INVALID_SAMPLE", 225, kToError, kFromError, "a filter received a NaN or infinite sample"},
    {"EVT_SUPERVISOR_LOST", 235, kToWarning, kFromWarning, "the supervisor stopped sending heartbeats"},
};

}  // namespace

// ---- history -----------------------------------------------------------------------------------

namespace {

constexpr std::uint8_t pack_states(State from, State to, State level, bool mirror) noexcept {
  return static_cast<std::uint8_t>(static_cast<unsigned>(from) | static_cast<unsigned>(to) << 2 |
                                   static_cast<unsigned>(level) << 4 | (mirror ? 1u << 6 : 0u));
}

std::uint64_t bits(double v) noexcept {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

/// The same root cause: every field equal, the sample value bit for bit (a NaN equals itself).
/// Runs for every record with a root, most often on two equal roots: plain loads, no call.
bool same_root(const RootCause& a, const RootCause& b) noexcept {
  return a.time == b.time && a.event == b.event && a.origin == b.origin && a.remote == b.remote &&
         a.remote_origin == b.remote_origin && a.sample.filter == b.sample.filter &&
         a.sample.signal == b.sample.signal && bits(a.sample.value) == bits(b.sample.value) &&
         a.sample.sample_time == b.sample.sample_time && a.sample.injected == b.sample.injected;
}

/// A record without a root cause (resets, and the transitions they cause): every field at its
/// default. Most records have a root event, so the first comparison decides.
bool no_root(const RootCause& r) noexcept {
  if (r.event != kNoEvent) return false;
  static constexpr RootCause kDefault{};
  return same_root(r, kDefault);
}

}  // namespace

void Coordinator::History::push(const Record& r, std::uint32_t text) noexcept {
  // Runs for every record: no division, and the capacity read once.
  const std::size_t capacity = items.size();
  if (capacity == 0) return;
  std::uint32_t root = kNone;
  if (!no_root(r.root)) {
    if (last_root == kNone || !same_root(roots[last_root], r.root)) {
      roots[next_root] = r.root;
      last_root = static_cast<std::uint32_t>(next_root);
      if (++next_root == capacity) next_root = 0;
    }
    root = last_root;
  }
  StoredRecord& s = items[next];
  s.time = r.time.count();
  s.seq = r.seq;
  s.subject = r.kind == RecordKind::ComponentTransition ? to_index(r.component) : to_index(r.machine);
  s.event = to_index(r.event);
  s.via = to_index(r.via);
  s.root = root;
  s.text = text;
  s.kind = r.kind;
  s.outcome = r.outcome;
  s.states = pack_states(r.from, r.to, r.level, r.mirror);
  s.severity = r.severity;
  if (++next == capacity) next = 0;
  if (size < capacity) ++size;
}

void Coordinator::History::grow(std::size_t capacity) {
  if (capacity <= items.size()) return;
  std::vector<StoredRecord> kept_items(capacity);
  std::vector<RootCause> kept_roots(capacity);
  const std::size_t old = items.size();
  std::size_t roots_kept = 0;
  std::uint32_t old_slot = kNone;
  for (std::size_t k = 0; k < size; ++k) {
    StoredRecord s = items[(next + old - size + k) % old];
    if (s.root != kNone) {
      // Records that share a root are consecutive (up to records without one): copy it once.
      if (s.root != old_slot) {
        old_slot = s.root;
        kept_roots[roots_kept++] = roots[s.root];
      }
      s.root = static_cast<std::uint32_t>(roots_kept - 1);
    }
    kept_items[k] = s;
  }
  items = std::move(kept_items);
  roots = std::move(kept_roots);
  next = size == capacity ? 0 : size;
  next_root = roots_kept == capacity ? 0 : roots_kept;
  last_root = roots_kept == 0 ? kNone : static_cast<std::uint32_t>(roots_kept - 1);
}

void Coordinator::size_history() {
  const std::size_t addresses = machines_.size() + components_.size();
  const std::size_t wanted = std::max(options_.history_records, options_.history_per_address * addresses);
  const std::size_t most = std::max<std::size_t>(options_.history_records_max, 1);
  if (wanted <= history_.items.size() || history_.items.size() >= most) return;
  // Geometric growth: configuring n addresses stays O(n); the cap is never exceeded.
  history_.grow(std::min(std::max(wanted, 2 * history_.items.size()), most));
}

std::string_view Coordinator::text_of(std::uint32_t text) const {
  switch (text) {
    case kNone: return {};
    case kTextNoOnset: return ConditionSet::kIgnoredNoOnset;
    case kTextNotActive: return ConditionSet::kIgnoredNotActive;
    case kTextLatched: return ConditionSet::kIgnoredLatched;
    case kTextNoLongerReported: return "no longer reported by the provider";
    default: return structure_.name_of(NameId{text});
  }
}

ComponentId Coordinator::stored_component(const StoredRecord& s) const noexcept {
  if (s.kind == RecordKind::ComponentTransition) return ComponentId{s.subject};
  return machines_[MachineId{s.subject}].component;
}

Record Coordinator::decode(const StoredRecord& s) const {
  Record r;
  r.kind = s.kind;
  r.outcome = s.outcome;
  r.time = Time{s.time};
  r.seq = s.seq;
  r.component = stored_component(s);
  r.machine = s.kind == RecordKind::ComponentTransition ? kNoMachine : MachineId{s.subject};
  r.event = EventId{s.event};
  r.from = static_cast<State>(s.states & 3u);
  r.to = static_cast<State>((s.states >> 2) & 3u);
  r.level = static_cast<State>((s.states >> 4) & 3u);
  r.mirror = (s.states & (1u << 6)) != 0;
  r.severity = s.severity;
  r.via = ConnectionId{s.via};
  if (s.root != kNone) r.root = history_.roots[s.root];
  r.text = text_of(s.text);
  return r;
}

// ---- construction and configuration ----------------------------------------------------------

Coordinator::Coordinator(std::string name, const Clock* clock, CoordinatorOptions options)
    : structure_(std::move(name)), clock_(clock), options_(options) {
  if (clock_ == nullptr) {
    owned_clock_ = std::make_unique<SteadyClock>();
    clock_ = owned_clock_.get();
  }
  for (const FrameworkEventSpec& spec : kFrameworkEvents) {
    Event onset;
    onset.name = spec.name;
    onset.severity = static_cast<std::uint8_t>(spec.severity);
    onset.transitions = spec.onset;
    onset.description = spec.description;
    const EventId onset_id = add_event_unchecked(std::move(onset));
    Event completion;
    completion.name = std::string("/") + spec.name;
    completion.severity = static_cast<std::uint8_t>(spec.severity);
    completion.transitions = spec.completion;
    completion.is_onset = false;
    completion.completes = spec.name;
    completion.counterpart = onset_id;
    const EventId completion_id = add_event_unchecked(std::move(completion));
    structure_.events_[to_index(onset_id)].counterpart = completion_id;
  }
  SAFECASS_ASSERT(structure_.events_.size() == framework_event::kCount);
}

Coordinator::~Coordinator() = default;

EventId Coordinator::add_event_unchecked(Event event) {
  event.id = id_at<EventId>(structure_.events_.size());
  structure_.event_index_.emplace(event.name, event.id);
  structure_.events_.push_back(std::move(event));
  structure_.event_table_.push_back(&structure_.events_.back());  // deque elements never move
  return structure_.events_.back().id;
}

Expected<ComponentId> Coordinator::add_component(std::string_view name) {
  if (!valid_name(name)) {
    return fail(ErrorCode::InvalidArgument,
                "component name '" + std::string(name) + "' must be non-empty, without dots or spaces");
  }
  if (structure_.find_component(name)) {
    return fail(ErrorCode::Duplicate, "duplicate component '" + std::string(name) + "'");
  }
  if (name == "SYSTEM") {
    return fail(ErrorCode::InvalidArgument,
                "component name 'SYSTEM' is reserved: it is the address of the whole system");
  }
  const auto id = id_at<ComponentId>(components_.size());
  Structure::Component& shape = structure_.components_.emplace_back();
  shape.name = std::string(name);
  ComponentData& cd = components_.emplace_back();
  cd.snapshot.store(pack(StateSnapshot{}), std::memory_order_relaxed);
  size_history();
  structure_.component_index_.emplace(std::string(name), id);
  shape.framework = add_machine(id, MachineKind::Framework, kNone, address::framework(shape.name));
  shape.application = add_machine(id, MachineKind::Application, kNone, address::application(shape.name));
  cd.machine_state_count[index(State::Normal)] = 2;
  return id;
}

MachineId Coordinator::add_machine(ComponentId component, MachineKind kind, std::uint32_t iface, std::string address) {
  Structure::Machine& shape = structure_.machines_.emplace_back();
  shape.kind = kind;
  shape.component = component;
  shape.iface = iface;
  shape.address = std::move(address);
  MachineData& m = machines_.emplace_back();
  m.component = component;
  m.snapshot.store(pack(StateSnapshot{}), std::memory_order_relaxed);
  const auto id = id_at<MachineId>(machines_.size() - 1);
  ComponentData& c = components_[component];
  if (c.machine_count == 0) {
    c.first_machine = id;
  } else if (to_index(c.first_machine) + c.machine_count != to_index(id)) {
    c.contiguous = false;
  }
  ++c.machine_count;
  size_history();
  // Propagation scratch space grows with the model here, never while processing.
  summaries_.resize(machines_.size());
  visit_marks_.resize(machines_.size(), 0);
  if (work_.capacity() < machines_.size()) work_.reserve(2 * machines_.size());
  return id;
}

Expected<MachineId> Coordinator::add_interface(ComponentId component, std::string_view name, MachineKind kind) {
  if (!components_.contains(component))
    return fail(ErrorCode::NotFound, "no component with id " + std::to_string(to_index(component)));
  Structure::Component& shape = structure_.components_[component];
  if (!valid_name(name)) {
    return fail(ErrorCode::InvalidArgument, "interface name '" + std::string(name) + "' of component '" + shape.name +
                                                "' must be non-empty, without dots or spaces");
  }
  const bool provided = kind == MachineKind::Provided;
  std::vector<MachineId>& list = provided ? shape.provided : shape.required;
  std::string address = address::machine(kind, shape.name, name);
  for (MachineId m : list) {
    if (structure_.machines_[m].address == address) {
      return fail(ErrorCode::Duplicate, std::string("duplicate ") + (provided ? "provided" : "required") +
                                            " interface '" + std::string(name) + "' in component '" + shape.name + "'");
    }
  }
  const auto iface = static_cast<std::uint32_t>(list.size());
  const MachineId id = add_machine(component, kind, iface, std::move(address));
  list.push_back(id);
  if (provided) {
    shape.services.emplace_back();
  } else {
    shape.required_connection.push_back(kNoConnection);
  }
  ++components_[component].machine_state_count[index(State::Normal)];
  rebuild_fanout(component);
  return id;
}

Expected<MachineId> Coordinator::add_provided(ComponentId component, std::string_view name) {
  return add_interface(component, name, MachineKind::Provided);
}

Expected<MachineId> Coordinator::add_required(ComponentId component, std::string_view name) {
  return add_interface(component, name, MachineKind::Required);
}

Expected<EventId> Coordinator::add_event(const EventDef& def) {
  const std::string where = "event '" + def.name + "'";
  if (def.name.empty()) return fail(ErrorCode::InvalidArgument, "an event needs a name");
  if (structure_.find_event(def.name)) return fail(ErrorCode::Duplicate, "duplicate " + where);
  if (def.severity < kMinSeverity || def.severity > kMaxSeverity) {
    return fail(ErrorCode::InvalidArgument, where + ": severity " + std::to_string(def.severity) + " is outside 1-255");
  }
  if (def.transitions.empty()) return fail(ErrorCode::InvalidArgument, where + ": state_transition is empty");
  const bool onset = def.transitions.worsening_only();
  if (!onset && !def.transitions.improving_only()) {
    return fail(ErrorCode::InvalidArgument,
                where + ": state_transition mixes worsening (N2W, N2E, W2E) and improving (W2N, E2N, E2W) transitions");
  }
  Event e;
  e.name = def.name;
  e.severity = static_cast<std::uint8_t>(def.severity);
  e.transitions = def.transitions;
  e.is_onset = onset;
  e.latched = def.latched;
  e.hazard = def.hazard;
  e.description = def.description;
  if (onset) {
    if (!def.completes.empty()) {
      return fail(ErrorCode::InvalidArgument, where + ": only a completion may say which onset it 'completes'");
    }
    // A completion defined earlier may be waiting for this onset.
    for (Event& other : structure_.events_) {
      if (!other.is_onset && other.counterpart == kNoEvent && other.completes == def.name) {
        other.counterpart = id_at<EventId>(structure_.events_.size());
        e.counterpart = other.id;
      }
    }
  } else {
    if (def.latched) return fail(ErrorCode::InvalidArgument, where + ": only an onset can be latched");
    e.completes = def.completes;
    if (e.completes.empty()) {
      if (def.name.size() < 2 || def.name[0] != '/') {
        return fail(ErrorCode::InvalidArgument,
                    where + ": a completion must be named '/ONSET' or say which onset it 'completes'");
      }
      e.completes = def.name.substr(1);
    }
    if (auto o = structure_.find_event(e.completes)) {
      Event& target = structure_.events_[to_index(*o)];
      if (!target.is_onset) {
        return fail(ErrorCode::InvalidArgument, where + ": completes '" + e.completes + "', which is not an onset");
      }
      e.counterpart = *o;
      if (target.counterpart == kNoEvent) target.counterpart = id_at<EventId>(structure_.events_.size());
    }
  }
  return add_event_unchecked(std::move(e));
}

Expected<void> Coordinator::set_service(ComponentId component, std::string_view provided,
                                        const ServiceDependency& dependency) {
  if (!components_.contains(component))
    return fail(ErrorCode::NotFound, "no component with id " + std::to_string(to_index(component)));
  Structure::Component& c = structure_.components_[component];
  std::uint32_t p = kNone;
  for (std::uint32_t i = 0; i < c.provided.size(); ++i) {
    if (structure_.interface_name(c.provided[i]) == provided) p = i;
  }
  if (p == kNone) {
    return fail(ErrorCode::NotFound, "service '" + std::string(provided) + "' of component '" + c.name +
                                         "': no provided interface of that name");
  }
  if (dependency.propagate == State::Normal) {
    return fail(ErrorCode::InvalidArgument,
                "service '" + c.name + "." + std::string(provided) + "': propagate must be Warning or Error");
  }
  Structure::Service data;
  data.dependency = dependency;
  if (!dependency.all_required) {
    for (const std::string& r : dependency.required) {
      std::uint32_t found = kNone;
      for (std::uint32_t i = 0; i < c.required.size(); ++i) {
        if (structure_.interface_name(c.required[i]) == r) found = i;
      }
      if (found == kNone) {
        return fail(ErrorCode::NotFound, "service '" + c.name + "." + std::string(provided) +
                                             "' depends on unknown required interface '" + r + "'");
      }
      data.required.push_back(found);
    }
  }
  const std::lock_guard lock(mutex_);
  // Only conditions on this component's own machines can flow through its services.
  for (MachineId id : structure_.machines_of(component)) {
    if (!machines_[id].conditions.empty()) {
      return fail(ErrorCode::InvalidState, "service '" + c.name + "." + std::string(provided) +
                                               "': dependencies cannot change while conditions are active");
    }
  }
  c.services[p] = std::move(data);
  rebuild_fanout(component);
  return {};
}

Expected<ConnectionId> Coordinator::connect(std::string_view client_required, std::string_view provider_provided) {
  auto split = [this](std::string_view text, const char* role) -> Expected<std::pair<ComponentId, std::string_view>> {
    const auto dot = text.find('.');
    if (dot == std::string_view::npos || dot == 0 || dot + 1 == text.size() ||
        text.find('.', dot + 1) != std::string_view::npos) {
      return fail(ErrorCode::InvalidArgument,
                  std::string(role) + " '" + std::string(text) + "' must be written Component.Interface");
    }
    auto comp = structure_.find_component(text.substr(0, dot));
    if (!comp) {
      return fail(ErrorCode::NotFound, std::string(role) + " '" + std::string(text) + "': no component '" +
                                           std::string(text.substr(0, dot)) + "'");
    }
    return std::make_pair(*comp, text.substr(dot + 1));
  };
  auto client = split(client_required, "required interface");
  if (!client) return tl::unexpected(client.error());
  auto provider = split(provider_provided, "provided interface");
  if (!provider) return tl::unexpected(provider.error());
  Structure::Component& cc = structure_.components_[client->first];
  Structure::Component& pc = structure_.components_[provider->first];
  std::uint32_t r = kNone;
  for (std::uint32_t i = 0; i < cc.required.size(); ++i) {
    if (structure_.interface_name(cc.required[i]) == client->second) r = i;
  }
  if (r == kNone) {
    return fail(ErrorCode::NotFound, "connection " + std::string(client_required) + " -> " +
                                         std::string(provider_provided) + ": '" + cc.name +
                                         "' has no required interface '" + std::string(client->second) + "'");
  }
  std::uint32_t p = kNone;
  for (std::uint32_t i = 0; i < pc.provided.size(); ++i) {
    if (structure_.interface_name(pc.provided[i]) == provider->second) p = i;
  }
  if (p == kNone) {
    return fail(ErrorCode::NotFound, "connection " + std::string(client_required) + " -> " +
                                         std::string(provider_provided) + ": '" + pc.name +
                                         "' has no provided interface '" + std::string(provider->second) + "'");
  }
  if (client->first == provider->first) {
    return fail(ErrorCode::InvalidArgument, "connection " + std::string(client_required) + " -> " +
                                                std::string(provider_provided) +
                                                ": a component cannot require its own service");
  }
  if (delivering_here()) {
    return fail(ErrorCode::InvalidState, "connection " + std::string(client_required) + " -> " +
                                             std::string(provider_provided) + ": made from a callback or observer");
  }
  if (cc.required_connection[r] != kNoConnection) {
    const Connection& old = structure_.connections_[to_index(cc.required_connection[r])];
    return fail(ErrorCode::Duplicate,
                "required interface " + std::string(client_required) + " is already connected to " +
                    std::string(structure_.component_name(old.provider)) + "." +
                    std::string(structure_.interface_name(structure_.provided_machines(old.provider)[old.provided])));
  }
  std::unique_lock lock(mutex_);
  const auto id = id_at<ConnectionId>(structure_.connections_.size());
  structure_.connections_.push_back(Connection{client->first, r, provider->first, p});
  cc.required_connection[r] = id;
  pc.provider_connections.push_back(id);
  rebuild_fanout(provider->first);
  // A connection made while faults are active carries them at once (mirrors are defined by
  // reachability). Whatever it carries is active at one of the provider's machines: when they
  // are all Normal there is nothing to carry (the common case while a system is being built).
  const ComponentData& provider_state = components_[provider->first];
  if (provider_state.machine_state_count[index(State::Normal)] == provider_state.machine_count) return id;
  for (MachineId m : id_range<MachineId>(machines_.size())) {
    const std::vector<Condition> snapshot(machines_[m].conditions.begin(), machines_[m].conditions.end());
    for (const Condition& c : snapshot) {
      // Roots, and remote roots at the remote provided interface that holds them.
      if (!c.mirror || (c.root.remote != kNone && c.root.origin == m)) propagate_onset(c);
    }
  }
  const Sealed sealed = seal();
  lock.unlock();
  finish(sealed);
  return id;
}

bool Coordinator::depends_on(ComponentId component, std::uint32_t provided, MachineId id) const noexcept {
  const Structure::Machine& m = structure_.machines_[id];
  if (m.component != component) return false;
  const Structure::Service& service = structure_.components_[component].services[provided];
  const ServiceDependency& d = service.dependency;
  switch (m.kind) {
    case MachineKind::Framework: return d.framework;
    case MachineKind::Application: return d.application;
    case MachineKind::Provided: return m.iface == provided;
    case MachineKind::Required: {
      if (d.all_required) return true;
      const auto& req = service.required;
      return std::find(req.begin(), req.end(), m.iface) != req.end();
    }
  }
  return false;
}

void Coordinator::rebuild_fanout(ComponentId provider_id) {
  const Structure::Component& provider = structure_.components_[provider_id];
  const std::vector<MachineId> machines = structure_.machines_of(provider_id);
  for (MachineId m : machines) machines_[m].fanout.clear();
  for (ConnectionId k : provider.provider_connections) {
    const Connection& conn = structure_.connections_[to_index(k)];
    const MachineId client_machine = structure_.components_[conn.client].required[conn.required];
    const State min_level = provider.services[conn.provided].dependency.propagate;
    for (MachineId m : machines) {
      if (depends_on(conn.provider, conn.provided, m)) {
        machines_[m].fanout.push_back(Edge{client_machine, min_level, k});
      }
    }
  }
}

// ---- reads -----------------------------------------------------------------------------------

State Coordinator::service_state(ComponentId component, std::uint32_t provided) const noexcept {
  const Structure::Component& c = structure_.components_[component];
  const Structure::Service& s = c.services[provided];
  State st = state(c.provided[provided]);
  if (s.dependency.framework) st = st * state(c.framework);
  if (s.dependency.application) st = st * state(c.application);
  if (s.dependency.all_required) {
    for (MachineId r : c.required) st = st * state(r);
  } else {
    for (std::uint32_t r : s.required) st = st * state(c.required[r]);
  }
  return st;
}

State Coordinator::coordinator_state() const noexcept {
  State s = State::Normal;
  for (ComponentId c : id_range<ComponentId>(components_.size())) {
    if (!structure_.components_[c].remote) s = s * extended(c).state;
  }
  return s;
}

State Coordinator::state_of(const Address& a) const noexcept {
  switch (a.kind) {
    case Address::Kind::System: return coordinator_state();
    case Address::Kind::Component: return extended(a.component).state;
    case Address::Kind::Machine: return state(a.machine);
    case Address::Kind::Service: return service_state(a.component, a.service);
  }
  return State::Normal;
}

std::vector<Condition> Coordinator::conditions(MachineId id) const {
  const std::lock_guard lock(mutex_);
  const ConditionSet& set = machines_[id].conditions;
  return std::vector<Condition>(set.begin(), set.end());
}

std::optional<Condition> Coordinator::outstanding(MachineId id) const {
  const std::lock_guard lock(mutex_);
  const MachineData& m = machines_[id];
  if (m.conditions.outstanding() == nullptr) return std::nullopt;
  return *m.conditions.outstanding();
}

namespace {
/// The newest `limit` stored records that `keep` selects, decoded, oldest first: one backwards pass.
template <class History, class Keep, class Decode>
std::vector<Record> newest(const History& h, std::size_t limit, Keep keep, Decode decode) {
  std::vector<Record> out;
  const std::size_t capacity = h.items.size();
  for (std::size_t k = 0; k < h.size && out.size() < limit; ++k) {
    const auto& s = h.items[(h.next + capacity - 1 - k) % capacity];
    if (keep(s)) out.push_back(decode(s));
  }
  std::reverse(out.begin(), out.end());
  return out;
}
}  // namespace

std::vector<Record> Coordinator::history(MachineId id) const {
  const std::lock_guard lock(mutex_);
  return newest(
      history_, options_.history_capacity,
      [id](const StoredRecord& s) { return s.kind != RecordKind::ComponentTransition && s.subject == to_index(id); },
      [this](const StoredRecord& s) { return decode(s); });
}

std::vector<Record> Coordinator::history(const Address& scope, std::size_t last, std::optional<RecordKind> kind) const {
  const std::lock_guard lock(mutex_);
  const auto of_kind = [kind](const StoredRecord& s) { return !kind || s.kind == *kind; };
  if (scope.kind == Address::Kind::Machine) {
    const std::uint32_t id = to_index(scope.machine);
    return newest(
        history_, last == 0 ? options_.history_capacity : std::min(last, options_.history_capacity),
        [&](const StoredRecord& s) {
          return s.kind != RecordKind::ComponentTransition && s.subject == id && of_kind(s);
        },
        [this](const StoredRecord& s) { return decode(s); });
  }
  // An address returns at most history_capacity records; SYSTEM, whatever the ring keeps.
  const bool system = scope.kind == Address::Kind::System;
  const std::size_t bound = system ? history_.size : options_.history_capacity;
  return newest(
      history_, last == 0 ? bound : std::min(last, bound),
      [&](const StoredRecord& s) { return (system || stored_component(s) == scope.component) && of_kind(s); },
      [this](const StoredRecord& s) { return decode(s); });
}

std::vector<Record> Coordinator::records_since(std::uint64_t seq, std::size_t max) const {
  max = max == 0 ? options_.history_capacity : std::min(max, options_.history_capacity);
  std::vector<Record> out;
  const std::lock_guard lock(mutex_);
  const std::size_t capacity = history_.items.size();
  const std::size_t oldest = (history_.next + capacity - history_.size) % std::max<std::size_t>(capacity, 1);
  const auto at = [&](std::size_t k) -> const StoredRecord& { return history_.items[(oldest + k) % capacity]; };
  // Sequence numbers grow along the ring (record() numbers and stores under this lock).
  std::size_t lo = 0, hi = history_.size;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (at(mid).seq <= seq)
      lo = mid + 1;
    else
      hi = mid;
  }
  const std::size_t n = std::min(history_.size - lo, max);
  out.reserve(n);
  for (std::size_t k = lo; k < lo + n; ++k) out.push_back(decode(at(k)));
  return out;
}

// ---- callbacks and observers -----------------------------------------------------------------

/// The writes that callbacks and observers request while one write's records are handed out
/// (and while the writes they requested are): made in order by the thread that made the write.
/// Storage is bound on the first request, to the thread's spare queue when its outermost write
/// does not use it already, so a callback that writes does not allocate once the spare has grown.
class Coordinator::Requests {
public:
  explicit Requests(std::size_t capacity) : capacity_(capacity) {}
  ~Requests() {
    if (spare_) {
      queue_->clear();
      spare_busy_ = false;
    }
  }
  Requests(const Requests&) = delete;
  Requests& operator=(const Requests&) = delete;
  void push(const Pending& op) {
    if (queue_ == nullptr) bind();
    queue_->push_back(op);
  }
  std::size_t size() const noexcept { return queue_ == nullptr ? 0 : queue_->size(); }
  const Pending& operator[](std::size_t i) const noexcept { return (*queue_)[i]; }

private:
  void bind() {
    spare_ = !spare_busy_;
    if (!spare_) {
      queue_ = &own_;
      return;
    }
    spare_busy_ = true;
    queue_ = &spare_queue_;
    queue_->reserve(capacity_);
  }
  std::size_t capacity_;
  std::vector<Pending>* queue_ = nullptr;
  std::vector<Pending> own_;
  bool spare_ = false;
};

thread_local std::vector<Coordinator::Pending> Coordinator::spare_queue_;
thread_local bool Coordinator::spare_busy_ = false;

bool Coordinator::delivering_here() const noexcept {
  const std::thread::id deliverer = deliverer_.load(std::memory_order_relaxed);
  // The first test spares the usual case (nobody hands out records) the thread's id.
  return deliverer != std::thread::id{} && deliverer == std::this_thread::get_id();
}

void Coordinator::register_now(Registration registration) {
  if (delivering_here()) {
    deferred_.push_back(std::move(registration));  // applied when this thread's turn ends
    return;
  }
  // A turn of its own: no list it changes is being walked meanwhile.
  std::uint64_t ticket = 0;
  {
    const std::lock_guard lock(mutex_);
    ticket = ++issued_;
  }
  wait_turn(ticket);
  deferred_.push_back(std::move(registration));
  apply_registrations();
  end_turn(ticket);
}

void Coordinator::on_machine(MachineId id, StateCallbacks callbacks) {
  register_now(Registration{Registration::Kind::Machine, to_index(id), std::move(callbacks), {}});
}

void Coordinator::on_component(ComponentId id, StateCallbacks callbacks) {
  register_now(Registration{Registration::Kind::Component, to_index(id), std::move(callbacks), {}});
}

Coordinator::SubscriptionId Coordinator::subscribe(std::function<void(const Record&)> observer) {
  SubscriptionId id = 0;
  {
    const std::lock_guard lock(mutex_);
    id = next_subscription_++;
  }
  register_now(Registration{Registration::Kind::Subscribe, id, {}, std::move(observer)});
  return id;
}

void Coordinator::unsubscribe(SubscriptionId id) {
  register_now(Registration{Registration::Kind::Unsubscribe, id, {}, {}});
}

void Coordinator::apply_registrations() noexcept {
  const std::lock_guard lock(mutex_);
  for (Registration& r : deferred_) {
    switch (r.kind) {
      case Registration::Kind::Machine:
        machines_[id_at<MachineId>(r.id)].callbacks.push_back(std::move(r.callbacks));
        break;
      case Registration::Kind::Component:
        components_[id_at<ComponentId>(r.id)].callbacks.push_back(std::move(r.callbacks));
        break;
      case Registration::Kind::Subscribe: observers_.emplace_back(r.id, std::move(r.observer)); break;
      case Registration::Kind::Unsubscribe:
        std::erase_if(observers_, [id = r.id](const auto& o) { return o.first == id; });
        break;
    }
  }
  deferred_.clear();
  observed_ = !observers_.empty();
}

void Coordinator::publish(Record record) {
  // Queued or not, the record's text must outlive the caller's: the interned copy does.
  if (!record.text.empty()) record.text = structure_.name_of(intern(record.text));
  Pending op;
  op.kind = PendingKind::Publish;
  op.record = record;
  write(op);
}

void Coordinator::record(Record& r, std::uint32_t text) noexcept {
  r.seq = ++record_seq_;
  history_.push(r, text);
  stage(r, false);
}

// ---- writes ----------------------------------------------------------------------------------

void Coordinator::generate(EventId event, MachineId target, const SampleCause& cause) noexcept {
  SAFECASS_ASSERT(to_index(event) < structure_.event_table_.size());
  SAFECASS_ASSERT(machines_.contains(target) || structure_.event_table_[to_index(event)]->is_broadcast());
  if (delivering_here()) {
    Pending op;
    op.event = event;
    op.machine = target;
    op.cause = cause;
    requests_->push(op);  // made once the records being handed out have been (write())
    return;
  }
  // write() without building a Pending: this is the hot path of every filter event.
  Sealed sealed;
  {
    const std::lock_guard lock(mutex_);
    process(event, target, cause);
    sealed = seal();
  }
  if (sealed.ticket != 0) finish(sealed);
}

void Coordinator::write(const Pending& op) noexcept {
  if (delivering_here()) {
    // From a callback or observer of this coordinator: made once the records being handed out
    // have been (they belong to a write whose turn this thread holds).
    requests_->push(op);
    return;
  }
  Sealed sealed;
  {
    const std::lock_guard lock(mutex_);
    run(op);
    sealed = seal();
  }
  finish(sealed);
}

void Coordinator::finish(Sealed sealed) noexcept {
  if (sealed.ticket == 0) return;
  // A callback loop could queue writes for ever; the bound keeps the monitored system alive.
  constexpr std::size_t kMaxChained = std::size_t{1} << 16;
  Requests queue(options_.pending_capacity);
  deliver(sealed, queue);
  for (std::size_t next = 0; next < queue.size(); ++next) {
    if (next == kMaxChained) {
      const std::lock_guard lock(mutex_);
      dropped_requests_ += queue.size() - next;
      break;
    }
    const Pending op = queue[next];  // deliver() may grow the queue
    {
      const std::lock_guard lock(mutex_);
      run(op);
      sealed = seal();
    }
    if (sealed.ticket != 0) deliver(sealed, queue);
  }
}

Coordinator::Sealed Coordinator::seal() noexcept {
  std::size_t first = outbox_.size();
  while (first > 0 && outbox_[first - 1].ticket == 0) --first;
  if (first == outbox_.size()) return {};
  const std::uint64_t ticket = ++issued_;
  // The usual case: every earlier turn is over. Take this one now: the staged records are all this
  // write's (earlier ones left the outbox when they were handed out; a later write cannot stage
  // while the lock is held).
  if (delivered_.load(std::memory_order_acquire) + 1 == ticket) {
    handing_.swap(outbox_);  // both keep their capacity
    return {ticket, true};
  }
  for (std::size_t i = first; i < outbox_.size(); ++i) outbox_[i].ticket = ticket;
  return {ticket, false};
}

void Coordinator::wait_turn(std::uint64_t ticket) noexcept {
  // Counted among the waiters first, so the thread whose turn ends sees that it must wake us.
  waiters_.fetch_add(1);
  for (std::uint64_t done = delivered_.load(); done + 1 != ticket; done = delivered_.load()) delivered_.wait(done);
  waiters_.fetch_sub(1);
}

void Coordinator::end_turn(std::uint64_t ticket) noexcept {
  // Sequentially consistent, as the waiters' count and load: either a waiter counted itself before
  // this load, and is woken, or its own load comes after this store and it does not wait. Waking
  // costs a read-modify-write on a line shared by the process; most turns have no waiter.
  delivered_.store(ticket);
  if (waiters_.load() != 0) delivered_.notify_all();
}

void Coordinator::deliver(Sealed sealed, Requests& queue) noexcept {
  if (!sealed.turn) {
    wait_turn(sealed.ticket);  // every earlier write's records first
    const std::lock_guard lock(mutex_);
    std::size_t n = 0;
    while (n < outbox_.size() && outbox_[n].ticket == sealed.ticket) ++n;
    handing_.assign(outbox_.begin(), outbox_.begin() + static_cast<std::ptrdiff_t>(n));
    outbox_.erase(outbox_.begin(), outbox_.begin() + static_cast<std::ptrdiff_t>(n));
  }
  requests_ = &queue;
  deliverer_.store(std::this_thread::get_id(), std::memory_order_relaxed);
  for (const Delivery& d : handing_) {
    if (d.observe) {
      for (auto& [id, fn] : observers_) {
        try {
          fn(d.record);
        } catch (...) {
          // Observers must not throw; a throwing observer must still not break monitoring.
        }
      }
    }
    if (d.callbacks) fire(d, queue);
  }
  deliverer_.store(std::thread::id{}, std::memory_order_relaxed);
  requests_ = nullptr;
  handing_.clear();
  if (!deferred_.empty()) apply_registrations();
  end_turn(sealed.ticket);
}

void Coordinator::fire(const Delivery& d, Requests& queue) noexcept {
  const Record& r = d.record;
  const bool machine = r.kind == RecordKind::Transition;
  std::vector<StateCallbacks>& callbacks =
      machine ? machines_[r.machine].callbacks : components_[r.component].callbacks;
  const TransitionInfo info{r.component,
                            machine ? r.machine : kNoMachine,
                            transition_between(r.from, r.to),
                            r.event,
                            r.root.event == kNoEvent ? nullptr : &r.root,
                            r.time};
  for (StateCallbacks& cb : callbacks) {
    try {
      if (cb.on_exit) cb.on_exit(r.from);
      if (cb.on_transition) cb.on_transition(info);
      if (cb.on_entry) cb.on_entry(r.to);
    } catch (...) {
      // §2.5: monitoring never crashes the monitored system; the fault becomes a framework event.
      Pending op;
      op.event = framework_event::kCallbackException;
      op.machine = structure_.components_[r.component].framework;
      queue.push(op);
    }
  }
}

void Coordinator::reset(const Address& target, std::string_view who, std::string_view why) {
  std::string text(who);
  text += ": ";
  text += why;
  Pending op;
  op.kind = PendingKind::Reset;
  op.address = target;
  op.why = intern(text);
  write(op);
}

void Coordinator::run(const Pending& op) noexcept {
  switch (op.kind) {
    case PendingKind::Generate: process(op.event, op.machine, op.cause); return;
    case PendingKind::Reset: reset_locked(op.address, op.why, clock_->now()); return;
    case PendingKind::Publish: {
      Record record = op.record;
      if (record.machine != kNoMachine && machines_.contains(record.machine)) {
        record.component = machines_[record.machine].component;
        // The history keeps texts by id (publish() interned this one).
        this->record(record, record.text.empty() ? kNone : to_index(intern(record.text)));  // a hit
      } else {
        record.seq = ++record_seq_;
        stage(record, false);
      }
      return;
    }
  }
}

void Coordinator::process(EventId event_id, MachineId target, const SampleCause& cause) noexcept {
  const Event& event = *structure_.event_table_[to_index(event_id)];
  const Time now = clock_->now();
  if (event.is_broadcast()) {
    for (ComponentId c : id_range<ComponentId>(components_.size())) {
      if (event.is_onset) {
        process_onset(event, structure_.components_[c].application, cause, now);
      } else {
        process_completion(event, structure_.components_[c].application, now);
      }
    }
    return;
  }
  if (event.is_onset) {
    process_onset(event, target, cause, now);
  } else {
    process_completion(event, target, now);
  }
}

void Coordinator::process_onset(const Event& event, MachineId target, const SampleCause& cause, Time now) noexcept {
  MachineData& m = machines_[target];
  const ConditionChange change =
      m.conditions.onset(event, RootCause{event.id, target, now, cause}, now, condition_seq_);
  if (change.outcome == Outcome::None) return;  // §2.4 onset rule 1: a refresh, not recorded
  const Condition c = m.conditions[static_cast<std::size_t>(change.index)];
  record_added(target, change, now);
  propagate_onset(c);
}

void Coordinator::process_completion(const Event& event, MachineId target, Time now) noexcept {
  MachineData& m = machines_[target];
  const Event* onset = event.counterpart == kNoEvent ? nullptr : structure_.event_table_[to_index(event.counterpart)];
  const ConditionChange change = m.conditions.complete(onset);
  if (change.outcome == Outcome::Ignored) {
    Record r;
    r.kind = RecordKind::Event;
    r.outcome = Outcome::Ignored;
    r.time = now;
    r.component = m.component;
    r.machine = target;
    r.event = event.id;
    r.from = r.to = change.from;
    r.severity = event.severity;
    if (change.index >= 0) r.root = m.conditions[static_cast<std::size_t>(change.index)].root;
    r.text = change.reason;
    record(r, change.reason == ConditionSet::kIgnoredLatched     ? kTextLatched
              : change.reason == ConditionSet::kIgnoredNotActive ? kTextNotActive
                                                                 : kTextNoOnset);
    return;
  }
  record_removed(target, change, event.id, now, kNone);
  propagate_clear(change.removed.root, change.removed.level, now);
}

void Coordinator::add_condition(MachineId id, const Condition& c, Time now) noexcept {
  record_added(id, machines_[id].conditions.add(c), now);
}

void Coordinator::record_added(MachineId id, const ConditionChange& change, Time now) noexcept {
  MachineData& m = machines_[id];
  const Condition& c = m.conditions[static_cast<std::size_t>(change.index)];
  Record r;
  r.kind = RecordKind::Event;
  r.outcome = change.outcome;
  r.time = now;
  r.component = m.component;
  r.machine = id;
  r.event = c.event;
  r.from = change.from;
  r.to = change.to;
  r.level = c.level;
  r.severity = c.severity;
  r.mirror = c.mirror;
  r.via = c.via;
  r.root = c.root;
  record(r, kNone);
  update_machine(id, change.from, c.event, &c.root, now);
}

void Coordinator::remove_condition(MachineId id, std::size_t i, EventId event, Time now, std::uint32_t text) noexcept {
  record_removed(id, machines_[id].conditions.remove(i), event, now, text);
}

void Coordinator::record_removed(MachineId id, const ConditionChange& change, EventId event, Time now,
                                 std::uint32_t text) noexcept {
  MachineData& m = machines_[id];
  const Condition& removed = change.removed;
  Record r;
  r.kind = RecordKind::Event;
  r.outcome = Outcome::Cleared;
  r.time = now;
  r.component = m.component;
  r.machine = id;
  r.event = event;
  r.from = change.from;
  r.to = change.to;
  r.level = removed.level;
  r.severity = removed.severity;
  r.mirror = removed.mirror;
  r.via = removed.via;
  r.root = removed.root;
  r.text = text_of(text);
  record(r, text);
  update_machine(id, change.from, event, &removed.root, now);
}

void Coordinator::update_machine(MachineId id, State old_state, EventId event, const RootCause* root,
                                 Time now) noexcept {
  MachineData& m = machines_[id];
  const State state = m.conditions.state();
  const Condition* outstanding = m.conditions.outstanding();
  MachineSummary& summary = summaries_[to_index(id)];
  summary.state = state;
  summary.event = outstanding == nullptr ? kNoEvent : outstanding->event;
  summary.severity = outstanding == nullptr ? 0 : outstanding->severity;
  summary.seq = outstanding == nullptr ? 0 : outstanding->seq;
  m.snapshot.store(pack(StateSnapshot{state, summary.event}), std::memory_order_release);

  ComponentData& comp = components_[m.component];
  if (old_state != state) {
    --comp.machine_state_count[index(old_state)];
    ++comp.machine_state_count[index(state)];
    Record r;
    r.kind = RecordKind::Transition;
    r.time = now;
    r.component = m.component;
    r.machine = id;
    r.event = event;
    r.from = old_state;
    r.to = state;
    if (root != nullptr) r.root = *root;
    r.seq = ++record_seq_;
    history_.push(r, kNone);
    stage(r, !m.callbacks.empty());
  }
  update_component(m.component, event, root, now);
}

void Coordinator::update_component(ComponentId id, EventId event, const RootCause* root, Time now) noexcept {
  ComponentData& c = components_[id];
  const State old = c.state;
  c.state = state_from_counts(c.machine_state_count);
  // The component's outstanding event: over its machines at the extended level, the outstanding
  // condition of highest severity, most recent on ties.
  // (Activation orders are unique, so the result does not depend on the order machines are seen.)
  const MachineSummary* best = nullptr;
  auto consider = [&](MachineId mid) {
    const MachineSummary& cand = summaries_[to_index(mid)];
    if (cand.state != c.state || cand.event == kNoEvent) return;
    if (best == nullptr || cand.severity > best->severity ||
        (cand.severity == best->severity && cand.seq > best->seq)) {
      best = &cand;
    }
  };
  if (c.contiguous) {
    for (MachineId m : id_range(c.first_machine, to_index(c.first_machine) + c.machine_count)) consider(m);
  } else {
    const Structure::Component& shape = structure_.components_[id];
    consider(shape.framework);
    consider(shape.application);
    for (MachineId p : shape.provided) consider(p);
    for (MachineId r : shape.required) consider(r);
  }
  c.outstanding = best == nullptr ? kNoEvent : best->event;
  c.snapshot.store(pack(StateSnapshot{c.state, c.outstanding}), std::memory_order_release);
  if (old == c.state) return;
  Record r;
  r.kind = RecordKind::ComponentTransition;
  r.time = now;
  r.seq = ++record_seq_;
  r.component = id;
  r.event = event;
  r.from = old;
  r.to = c.state;
  if (root != nullptr) r.root = *root;
  history_.push(r, kNone);
  stage(r, !c.callbacks.empty());
}

// ---- propagation (DESIGN §2.6) ---------------------------------------------------------------

template <class Visit>
void Coordinator::each_reached(MachineId origin, State level, Visit&& visit) noexcept {
  const std::uint64_t mark = ++visit_epoch_;
  work_.clear();
  work_.push_back(origin);
  visit_marks_[to_index(origin)] = mark;
  for (std::size_t head = 0; head < work_.size(); ++head) {
    const MachineId from = work_[head];
    for (const Edge& e : machines_[from].fanout) {
      if (level < e.min_level || visit_marks_[to_index(e.to)] == mark) continue;
      visit_marks_[to_index(e.to)] = mark;
      work_.push_back(e.to);
      visit(e);
    }
  }
}

void Coordinator::propagate_onset(const Condition& root_condition) noexcept {
  // A machine that feeds no connection (most s_A of a leaf, every s_R) propagates nothing.
  if (machines_[root_condition.root.origin].fanout.empty()) return;
  const RootCause root = root_condition.root;
  const State level = root_condition.level;
  const Time now = root_condition.first;
  const EventId mirror_event =
      level == State::Error ? framework_event::kServiceFailure : framework_event::kServiceDegraded;
  each_reached(root.origin, level, [&](const Edge& e) {
    if (machines_[e.to].conditions.find_mirror(root) >= 0) return;
    Condition c;
    c.event = mirror_event;
    c.level = level;
    c.severity = structure_.event_table_[to_index(mirror_event)]->severity;
    c.mirror = true;
    c.via = e.via;
    c.first = c.last = now;
    c.seq = ++condition_seq_;
    c.root = root;
    add_condition(e.to, c, now);
  });
}

void Coordinator::propagate_clear(const RootCause& root, State level, Time now) noexcept {
  if (machines_[root.origin].fanout.empty()) return;
  each_reached(root.origin, level, [&](const Edge& e) {
    const std::int32_t i = machines_[e.to].conditions.find_mirror(root);
    if (i < 0) return;
    const EventId completion =
        framework_event::completion_of(machines_[e.to].conditions[static_cast<std::size_t>(i)].event);
    remove_condition(e.to, static_cast<std::size_t>(i), completion, now, kNone);
  });
}

void Coordinator::reset_locked(const Address& target, NameId reason, Time now) noexcept {
  const std::string_view text = structure_.name_of(reason);
  std::vector<MachineId> targets;
  switch (target.kind) {
    case Address::Kind::System:
      for (MachineId m : id_range<MachineId>(machines_.size())) targets.push_back(m);
      break;
    case Address::Kind::Component:
    case Address::Kind::Service: {
      targets = structure_.machines_of(target.component);
      break;
    }
    case Address::Kind::Machine: targets.push_back(target.machine); break;
  }
  for (MachineId id : targets) {
    MachineData& m = machines_[id];
    Record r;
    r.kind = RecordKind::Reset;
    r.time = now;
    r.component = m.component;
    r.machine = id;
    r.from = r.to = m.conditions.state();
    r.text = text;
    record(r, to_index(reason));
  }
  // Warnings first, in every target machine, then errors: the component and the system then drop
  // once (E2N) instead of passing through a Warning that callbacks would react to.
  for (const State pass : {State::Warning, State::Error}) {
    for (MachineId id : targets) {
      MachineData& m = machines_[id];
      // Propagating a clear may shrink this machine's conditions (a cycle): search afresh each time.
      for (std::int32_t i = m.conditions.find_lowest_root();
           i >= 0 && m.conditions[static_cast<std::size_t>(i)].level <= pass; i = m.conditions.find_lowest_root()) {
        const Condition c = m.conditions[static_cast<std::size_t>(i)];
        remove_condition(id, static_cast<std::size_t>(i), kNoEvent, now, to_index(reason));
        propagate_clear(c.root, c.level, now);
      }
    }
  }
}

}  // namespace safecass
