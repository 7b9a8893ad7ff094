#include "safecass/introspect/local_query.hpp"

#include "safecass/core/address.hpp"
#include "safecass/introspect/coverage.hpp"
#include "safecass/introspect/format.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

namespace safecass::introspect {

namespace {

std::string outstanding_name(const Coordinator& co, StateSnapshot s) {
  return s.state == State::Normal || s.outstanding == kNoEvent ? std::string()
                                                               : co.structure().event(s.outstanding).name;
}

RowKind row_kind(MachineKind k) {
  switch (k) {
    case MachineKind::Framework: return RowKind::Framework;
    case MachineKind::Application: return RowKind::Application;
    case MachineKind::Provided: return RowKind::Provided;
    case MachineKind::Required: return RowKind::Required;
  }
  return RowKind::Framework;
}

std::vector<SignalRef> signal_refs(const std::vector<Signal*>& signals) {
  std::vector<SignalRef> out;
  for (const Signal* s : signals) {
    if (s != nullptr) out.push_back({s->name(), s->size()});
  }
  return out;
}

class LocalSubscription final : public Subscription {
public:
  LocalSubscription(Coordinator& co, Coordinator::SubscriptionId id) : co_(co), id_(id) {}
  ~LocalSubscription() override { co_.unsubscribe(id_); }

private:
  Coordinator& co_;
  Coordinator::SubscriptionId id_;
};

std::vector<HistoryEntry> tail(const Coordinator& co, const std::vector<Record>& records, std::size_t last) {
  const std::size_t n = last == 0 ? records.size() : std::min(records.size(), last);
  std::vector<HistoryEntry> out;
  out.reserve(n);
  for (std::size_t i = records.size() - n; i < records.size(); ++i) out.push_back(history_entry(records[i], co));
  return out;
}

}  // namespace

LocalQuery::LocalQuery(Coordinator& co, Monitor& monitor, const FilterRegistry& registry, LocalOptions options)
    : co_(co), monitor_(monitor), registry_(registry), options_(std::move(options)) {
  if (options_.name.empty()) options_.name = std::string(co_.structure().name());
}

std::string LocalQuery::name() const { return options_.name; }

Expected<ClockInfo> LocalQuery::clock() {
  ClockInfo c;
  c.base = options_.base;
  c.now = co_.clock().now();
  if (c.base == TimeBase::Simulated && c.now < Time{0}) c.now = Time{0};
  if (c.base == TimeBase::Host) {
    const auto wall = std::chrono::duration_cast<Time>(std::chrono::system_clock::now().time_since_epoch());
    const auto steady = std::chrono::duration_cast<Time>(std::chrono::steady_clock::now().time_since_epoch());
    c.wall_offset_ns = (wall - steady).count();
  }
  c.period = options_.period;
  c.scenario = options_.scenario;
  c.duration = options_.duration;
  return c;
}

std::vector<StateRow> LocalQuery::component_rows(ComponentId id) const {
  const Structure& shape = co_.structure();
  std::vector<StateRow> out;
  const std::string name(shape.component_name(id));
  const StateSnapshot ext = co_.extended(id);
  out.push_back({name, RowKind::Component, ext.state, outstanding_name(co_, ext)});
  auto machine = [&](MachineId m) {
    const StateSnapshot s = co_.snapshot(m);
    out.push_back({shape.address_of(m), row_kind(shape.machine_kind(m)), s.state, outstanding_name(co_, s)});
  };
  machine(shape.framework_machine(id));
  machine(shape.application_machine(id));
  for (const MachineId m : shape.provided_machines(id)) machine(m);
  for (const MachineId m : shape.required_machines(id)) machine(m);
  const auto& provided = shape.provided_machines(id);
  for (std::uint32_t p = 0; p < provided.size(); ++p) {
    out.push_back(
        {address::service(name, shape.interface_name(provided[p])), RowKind::Service, co_.service_state(id, p), {}});
  }
  return out;
}

Expected<std::vector<StateRow>> LocalQuery::state_list(std::string_view component) {
  const Structure& shape = co_.structure();
  std::vector<StateRow> out;
  if (!component.empty()) {
    auto id = shape.find_component(component);
    if (!id || shape.is_remote(*id)) {
      return fail(ErrorCode::NotFound,
                  "no component '" + std::string(component) + "' in coordinator '" + options_.name + "'");
    }
    return component_rows(*id);
  }
  out.push_back({"SYSTEM", RowKind::System, co_.coordinator_state(), {}});
  for (ComponentId id : id_range<ComponentId>(shape.component_count())) {
    if (shape.is_remote(id)) continue;
    std::vector<StateRow> rows = component_rows(id);
    out.insert(out.end(), std::make_move_iterator(rows.begin()), std::make_move_iterator(rows.end()));
  }
  return out;
}

Expected<std::vector<HistoryEntry>> LocalQuery::history(std::string_view scope, std::size_t last,
                                                        HistoryFilter filter) {
  Address a;  // SYSTEM
  if (!scope.empty() && scope != "SYSTEM") {
    auto r = co_.structure().resolve(scope);
    if (!r) return tl::unexpected(r.error());
    a = *r;
    if (a.kind == Address::Kind::Service) a.kind = Address::Kind::Component;
  }
  const auto kind = filter == HistoryFilter::Events ? std::optional(RecordKind::Event) : std::nullopt;
  return tail(co_, co_.history(a, last, kind), 0);
}

Expected<std::vector<HistoryEntry>> LocalQuery::records_since(std::uint64_t seq, std::size_t max) {
  return tail(co_, co_.records_since(seq, max), 0);
}

Expected<std::vector<FilterRow>> LocalQuery::filter_list() {
  std::vector<FilterRow> out;
  for (const auto& f : monitor_.filters()) {
    FilterRow r;
    r.name = f->name();
    r.type = f->type();
    r.target = f->target() == kNoMachine ? std::string() : co_.structure().address_of(f->target());
    r.active = f->execution() == ExecutionMode::Active;
    r.edge = f->detection() == DetectionMode::Edge;
    r.detected = f->detected();
    r.inputs = signal_refs(f->inputs());
    r.outputs = signal_refs(f->outputs());
    if (f->onset() != kNoEvent) r.onset = co_.structure().event(f->onset()).name;
    const FilterFacts facts = f->facts();
    r.enabled = facts.enabled;
    r.injected = facts.injected;
    r.last_sample = facts.last_sample;
    r.evaluations = facts.evaluations;
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<std::string> LocalQuery::lost_components() const {
  std::vector<std::string> lost;
  const Structure& shape = co_.structure();
  for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
    if (!shape.is_remote(c)) continue;
    for (const Condition& condition : co_.conditions(shape.framework_machine(c))) {
      if (condition.event == framework_event::kCoordinatorLost) {
        lost.emplace_back(shape.component_name(c));
        break;
      }
    }
  }
  return lost;
}

Expected<CoverageNow> LocalQuery::coverage() {
  auto events = event_list();
  if (!events) return tl::unexpected(events.error());
  auto filters = filter_list();
  if (!filters) return tl::unexpected(filters.error());
  auto now = clock();
  if (!now) return tl::unexpected(now.error());
  return coverage_now(*events, {ProcessFilters{name(), false, std::move(*filters)}}, lost_components(), now->now);
}

Expected<FilterInfo> LocalQuery::filter_info(std::string_view name) {
  const Filter* f = monitor_.find_filter(name);
  const FilterRegistry::Entry* entry = registry_.find(f != nullptr ? std::string_view(f->type()) : name);
  if (entry == nullptr)
    return fail(ErrorCode::NotFound, "no filter or filter type '" + std::string(name) + "' (see filter list)");
  const FilterManifest& m = entry->manifest;
  FilterInfo info;
  info.type = m.type;
  info.doc = m.doc;
  info.inputs = m.inputs;
  info.outputs = m.outputs;
  info.generates_events = m.generates_events;
  if (f != nullptr) {
    auto rows = filter_list();
    for (FilterRow& r : *rows) {
      if (r.name == f->name()) info.filter = std::move(r);
    }
    info.missed_samples = f->missed_samples();
  }
  for (const ParamSpec& p : m.params) {
    ParamRow row;
    row.name = p.name;
    row.type = p.type;
    row.doc = p.doc;
    row.default_value = p.default_value;
    row.optional = p.optional;
    row.min = p.min;
    row.max = p.max;
    row.choices = p.choices;
    if (f != nullptr) {
      const auto it = f->config().params.find(p.name);
      if (it != f->config().params.end()) row.value = it->second;
    }
    info.params.push_back(std::move(row));
  }
  return info;
}

Expected<std::vector<EventRow>> LocalQuery::event_list() {
  const Structure& shape = co_.structure();
  std::vector<EventRow> out;
  for (EventId id : id_range<EventId>(shape.event_count())) {
    const Event& e = shape.event(id);
    EventRow r;
    r.name = e.name;
    r.severity = e.severity;
    r.onset = e.is_onset;
    r.broadcast = e.is_broadcast();
    for (const Transition t :
         {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N, Transition::E2W}) {
      if (e.transitions.contains(t)) r.transitions.push_back(t);
    }
    r.counterpart = e.counterpart == kNoEvent ? std::string() : shape.event(e.counterpart).name;
    r.latched = e.latched;
    r.framework = to_index(id) < framework_event::kCount;
    r.hazard = e.hazard;
    r.description = e.description;
    out.push_back(std::move(r));
  }
  return out;
}

Expected<std::vector<ConnectionRow>> LocalQuery::connection_list() {
  const Structure& shape = co_.structure();
  std::vector<ConnectionRow> out;
  for (const Connection& k : shape.connections()) {
    const MachineId required = shape.required_machines(k.client)[k.required];
    const MachineId provided = shape.provided_machines(k.provider)[k.provided];
    ConnectionRow r;
    r.required = std::string(shape.component_name(k.client)) + "." + std::string(shape.interface_name(required));
    r.provided = std::string(shape.component_name(k.provider)) + "." + std::string(shape.interface_name(provided));
    r.remote = shape.is_remote(k.provider);
    r.required_state = co_.state(required);
    if (!r.remote) {
      r.service_state = co_.service_state(k.provider, k.provided);
      r.propagate = shape.service(k.provider, k.provided).propagate;
    }
    out.push_back(std::move(r));
  }
  return out;
}

Expected<std::vector<ServiceRow>> LocalQuery::service_list() {
  const Structure& shape = co_.structure();
  std::vector<ServiceRow> out;
  for (ComponentId id : id_range<ComponentId>(shape.component_count())) {
    if (shape.is_remote(id)) continue;
    const auto& provided = shape.provided_machines(id);
    for (std::uint32_t i = 0; i < provided.size(); ++i) {
      const std::string p(shape.interface_name(provided[i]));
      const ServiceDependency& d = shape.service(id, i);
      ServiceRow r;
      r.address = address::service(shape.component_name(id), p);
      r.state = co_.service_state(id, i);
      r.propagate = d.propagate;
      r.depends_on.push_back("s_P." + p);
      if (d.framework) r.depends_on.emplace_back("s_F");
      if (d.application) r.depends_on.emplace_back("s_A");
      if (d.all_required) {
        for (const MachineId m : shape.required_machines(id))
          r.depends_on.push_back("s_R." + std::string(shape.interface_name(m)));
      } else {
        for (const std::string& name : d.required) r.depends_on.push_back("s_R." + name);
      }
      out.push_back(std::move(r));
    }
  }
  return out;
}

Expected<ExplainAnswer> LocalQuery::explain(std::string_view address) {
  const Structure& shape = co_.structure();
  ExplainAnswer a;
  a.address = std::string(address);
  if (address == "SYSTEM") {
    a.state = co_.coordinator_state();
    for (ComponentId id : id_range<ComponentId>(shape.component_count())) {
      if (shape.is_remote(id)) continue;
      std::vector<Explanation> part = co_.explain(Address{Address::Kind::Component, id});
      a.conditions.insert(a.conditions.end(), std::make_move_iterator(part.begin()),
                          std::make_move_iterator(part.end()));
    }
    return a;
  }
  auto resolved = shape.resolve(address);
  if (!resolved) return tl::unexpected(resolved.error());
  a.state = co_.state_of(*resolved);
  a.conditions = co_.explain(*resolved);
  return a;
}

Expected<Names> LocalQuery::names() {
  const Structure& shape = co_.structure();
  Names n;
  n.addresses.emplace_back("SYSTEM");
  for (ComponentId i : id_range<ComponentId>(shape.component_count())) {
    if (shape.is_remote(i)) continue;
    n.components.emplace_back(shape.component_name(i));
    n.addresses.emplace_back(shape.component_name(i));
    for (const MachineId p : shape.provided_machines(i)) {
      n.addresses.push_back(address::service(shape.component_name(i), shape.interface_name(p)));
    }
  }
  for (MachineId m : id_range<MachineId>(shape.machine_count())) {
    if (shape.is_remote(shape.machine_component(m))) continue;
    n.machines.push_back(shape.address_of(m));
    n.addresses.push_back(shape.address_of(m));
  }
  for (EventId e : id_range<EventId>(shape.event_count())) n.events.push_back(shape.event(e).name);
  for (const auto& f : monitor_.filters()) n.filters.push_back(f->name());
  for (const FilterManifest* m : registry_.manifests()) n.filter_types.push_back(m->type);
  for (const auto& s : monitor_.signals().all()) n.signals.push_back(s->name());
  return n;
}

Expected<std::unique_ptr<Subscription>> LocalQuery::follow(RecordSink sink) {
  const Coordinator* co = &co_;
  const auto id = co_.subscribe([co, sink = std::move(sink)](const Record& r) { sink(history_entry(r, *co)); });
  return std::unique_ptr<Subscription>(std::make_unique<LocalSubscription>(co_, id));
}

Expected<void> LocalQuery::apply(const Action& action) {
  Time now = co_.clock().now();
  if (options_.base == TimeBase::Simulated && now < Time{0}) now = Time{0};
  return introspect::apply(action, co_, monitor_, now, options_.actions);
}

// ---- named reads ---------------------------------------------------------------------------------

namespace {

[[nodiscard]] Expected<StateSummary> state_summary(LocalQuery& query) {
  auto rows = query.state_list();
  if (!rows) return tl::unexpected(rows.error());
  StateSummary s;
  for (const StateRow& r : *rows) {
    if (r.kind == RowKind::System) s.system = r.state;
    if (r.kind != RowKind::Component) continue;
    (r.state == State::Normal ? s.normal : r.state == State::Warning ? s.warning : s.error) += 1;
    if (r.state != State::Normal) s.not_normal.push_back({r.address, r.state, r.outstanding});
  }
  return s;
}

[[nodiscard]] Expected<CoverageNow> analyze_now(LocalQuery& query) { return query.coverage(); }

/// A read whose answer is `Value`: produced by `Produce`, written by `Json`, read back by `Parse`
/// and shown by `Text`.
template <class Value, Expected<Value> (*Produce)(LocalQuery&), std::string (*Json)(const Value&),
          Expected<Value> (*Parse)(std::string_view), std::string (*Text)(const Value&)>
constexpr NamedRead read_without_arguments(std::string_view name) {
  return NamedRead{name,
                   [](LocalQuery& query, const std::vector<std::string>&) -> Expected<std::string> {
                     auto value = Produce(query);
                     if (!value) return tl::unexpected(value.error());
                     return Json(*value);
                   },
                   [](std::string_view json) -> Expected<std::string> {
                     auto value = Parse(json);
                     if (!value) return tl::unexpected(value.error());
                     return Text(*value);
                   }};
}

constexpr NamedRead kReads[] = {
    read_without_arguments<StateSummary, state_summary, state_summary_json, state_summary_from_json,
                           state_summary_text>("state summary"),
    read_without_arguments<CoverageNow, analyze_now, coverage_now_json, coverage_now_from_json, coverage_now_text>(
        "analyze now"),
};

}  // namespace

const NamedRead* find_read(std::string_view name) noexcept {
  for (const NamedRead& r : kReads) {
    if (r.name == name) return &r;
  }
  return nullptr;
}

namespace {
/// The read named `name`. Errors: NotFound.
[[nodiscard]] Expected<const NamedRead*> named_read(std::string_view name) {
  if (const NamedRead* r = find_read(name)) return r;
  return fail(ErrorCode::NotFound, "no read '" + std::string(name) + "'");
}
}  // namespace

[[nodiscard]] Expected<std::string> read_text(std::string_view name, std::string_view json) {
  auto r = named_read(name);
  if (!r) return tl::unexpected(r.error());
  return (*r)->text(json);
}

Expected<std::string> LocalQuery::read(std::string_view name, const std::vector<std::string>& args) {
  auto r = named_read(name);
  if (!r) return tl::unexpected(r.error());
  return (*r)->answer(*this, args);
}

}  // namespace safecass::introspect
