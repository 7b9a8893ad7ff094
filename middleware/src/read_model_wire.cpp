#include "read_model_wire.hpp"

#include "control.hpp"
#include "safecass/introspect/format.hpp"

namespace safecass::middleware {

namespace in = introspect;

wire::Root root_to_wire(const ResolvedRoot& r, wire::Level level, std::vector<std::string> path) {
  return wire::Root{r.event,  r.origin, r.time.count(),        level,      r.filter,
                    r.signal, r.value,  r.sample_time.count(), r.injected, std::move(path)};
}

void root_from_wire(const wire::Root& w, ResolvedRoot& r) {
  r.event = w.event;
  r.origin = w.origin;
  r.time = Time{w.time};
  r.filter = w.filter;
  r.signal = w.signal;
  r.value = w.value;
  r.sample_time = Time{w.sampleTime};
  r.injected = w.injected;
}

namespace {

State level_of(wire::Level l) {
  State s = State::Normal;
  if (!from_wire(l, s)) return State::Error;  // a malformed level reads toward safe
  return s;
}

wire::RecordKind kind_to_wire(RecordKind k) noexcept {
  switch (k) {
    case RecordKind::Event: return wire::RecordKind::Event;
    case RecordKind::Transition: return wire::RecordKind::Transition;
    case RecordKind::ComponentTransition: return wire::RecordKind::ComponentTransition;
    case RecordKind::Reset: return wire::RecordKind::Reset;
    case RecordKind::Injection: return wire::RecordKind::Injection;
  }
  return wire::RecordKind::Event;
}

bool kind_of(wire::RecordKind k, RecordKind& out) noexcept {
  switch (k) {
    case wire::RecordKind::Event: out = RecordKind::Event; return true;
    case wire::RecordKind::Transition: out = RecordKind::Transition; return true;
    case wire::RecordKind::ComponentTransition: out = RecordKind::ComponentTransition; return true;
    case wire::RecordKind::Reset: out = RecordKind::Reset; return true;
    case wire::RecordKind::Injection: out = RecordKind::Injection; return true;
  }
  return false;
}

wire::RecordOutcome outcome_to_wire(Outcome o) noexcept {
  switch (o) {
    case Outcome::None: return wire::RecordOutcome::NoOutcome;
    case Outcome::Raised: return wire::RecordOutcome::Raised;
    case Outcome::Override: return wire::RecordOutcome::Override;
    case Outcome::Joined: return wire::RecordOutcome::Joined;
    case Outcome::Masked: return wire::RecordOutcome::Masked;
    case Outcome::Cleared: return wire::RecordOutcome::Cleared;
    case Outcome::Ignored: return wire::RecordOutcome::Ignored;
  }
  return wire::RecordOutcome::NoOutcome;
}

bool outcome_of(wire::RecordOutcome o, Outcome& out) noexcept {
  switch (o) {
    case wire::RecordOutcome::NoOutcome: out = Outcome::None; return true;
    case wire::RecordOutcome::Raised: out = Outcome::Raised; return true;
    case wire::RecordOutcome::Override: out = Outcome::Override; return true;
    case wire::RecordOutcome::Joined: out = Outcome::Joined; return true;
    case wire::RecordOutcome::Masked: out = Outcome::Masked; return true;
    case wire::RecordOutcome::Cleared: out = Outcome::Cleared; return true;
    case wire::RecordOutcome::Ignored: out = Outcome::Ignored; return true;
  }
  return false;
}

ParamType param_type_of(std::string_view text) {
  for (const ParamType t :
       {ParamType::Number, ParamType::Integer, ParamType::Bool, ParamType::String, ParamType::Choice, ParamType::Signal,
        ParamType::SignalList, ParamType::Event, ParamType::NumberList}) {
    if (to_string(t) == text) return t;
  }
  return ParamType::String;
}

wire::ParamValue value_to_wire(const ParamValue& v) {
  wire::ParamValue w{};
  std::visit(
      [&w](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          w.kind = "number";
          w.number = x;
        } else if constexpr (std::is_same_v<T, bool>) {
          w.kind = "bool";
          w.flag = x;
        } else if constexpr (std::is_same_v<T, std::string>) {
          w.kind = "string";
          w.text = x;
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          w.kind = "strings";
          w.texts = x;
        } else {
          w.kind = "numbers";
          w.numbers = x;
        }
      },
      v);
  return w;
}

ParamValue value_from_wire(const wire::ParamValue& w) {
  if (w.kind == "number") return w.number;
  if (w.kind == "bool") return w.flag;
  if (w.kind == "strings") return w.texts;
  if (w.kind == "numbers") return w.numbers;
  return w.text;
}

void fill(const in::HistoryEntry& e, wire::RecordEntry& w) {
  w.time = e.time.count();
  w.kind = kind_to_wire(e.kind);
  w.outcome = outcome_to_wire(e.outcome);
  w.event = e.event;
  w.from = to_wire(e.from);
  w.to = to_wire(e.to);
  w.level = to_wire(e.level);
  w.mirror = e.mirror;
  w.text = e.text;
  w.component = e.component;
  w.machine = e.machine;
  w.severity = e.severity;
  w.hasRoot = e.root.has_value();
  if (e.root) w.root = root_to_wire(*e.root);
}

bool read(const wire::RecordEntry& w, in::HistoryEntry& e) {
  e.time = Time{w.time};
  if (!kind_of(w.kind, e.kind) || !outcome_of(w.outcome, e.outcome)) return false;
  if (!from_wire(w.from, e.from) || !from_wire(w.to, e.to) || !from_wire(w.level, e.level)) return false;
  e.component = w.component;
  e.machine = w.machine;
  e.event = w.event;
  e.severity = w.severity;
  e.mirror = w.mirror;
  if (w.hasRoot) {
    // Field by field into the entry's own storage: an entry reused for every record of a stream
    // (the supervisor's) does not allocate per record.
    root_from_wire(w.root, e.root ? *e.root : e.root.emplace());
  } else {
    e.root.reset();
  }
  e.text = w.text;
  return true;
}

}  // namespace

wire::StateEntry to_wire(const in::StateRow& r) {
  return wire::StateEntry{r.address, std::string(in::to_string(r.kind)), to_wire(r.state), r.outstanding};
}

bool from_wire(const wire::StateEntry& w, in::StateRow& out) {
  out.address = w.address;
  out.outstanding = w.outstanding;
  return in::parse_row_kind(w.kind, out.kind) && from_wire(w.state, out.state);
}

wire::RecordEntry to_wire(const in::HistoryEntry& e) {
  wire::RecordEntry w{};
  w.seq = static_cast<long long>(e.seq);
  fill(e, w);
  return w;
}

bool from_wire(const wire::RecordEntry& w, in::HistoryEntry& out) {
  out.seq = static_cast<std::uint64_t>(w.seq);
  return read(w, out);
}

wire::FilterEntry to_wire(const in::FilterRow& r) {
  wire::FilterEntry w{};
  w.name = r.name;
  w.type = r.type;
  w.target = r.target;
  w.execution = r.active ? "ACTIVE" : "PASSIVE";
  w.detection = r.edge ? "EDGE" : "LEVEL";
  w.enabled = r.enabled;
  w.detected = r.detected;
  for (const in::SignalRef& s : r.inputs) {
    w.inputs.push_back(s.name);
    w.inputSizes.push_back(static_cast<int>(s.size));
  }
  for (const in::SignalRef& s : r.outputs) {
    w.outputs.push_back(s.name);
    w.outputSizes.push_back(static_cast<int>(s.size));
  }
  w.onset = r.onset;
  w.injected = r.injected;
  w.sampled = r.last_sample.has_value();
  w.lastSampleNs = r.last_sample ? r.last_sample->count() : 0;
  w.evaluations = static_cast<std::int64_t>(r.evaluations);
  return w;
}

in::FilterRow from_wire(const wire::FilterEntry& w) {
  in::FilterRow r;
  r.name = w.name;
  r.type = w.type;
  r.target = w.target;
  r.active = w.execution == "ACTIVE";
  r.edge = w.detection == "EDGE";
  r.enabled = w.enabled;
  r.detected = w.detected;
  for (std::size_t i = 0; i < w.inputs.size(); ++i) {
    r.inputs.push_back({w.inputs[i], i < w.inputSizes.size() ? static_cast<std::size_t>(w.inputSizes[i]) : 1});
  }
  for (std::size_t i = 0; i < w.outputs.size(); ++i) {
    r.outputs.push_back({w.outputs[i], i < w.outputSizes.size() ? static_cast<std::size_t>(w.outputSizes[i]) : 1});
  }
  r.onset = w.onset;
  r.injected = w.injected;
  if (w.sampled) r.last_sample = Time{w.lastSampleNs};
  r.evaluations = w.evaluations < 0 ? 0 : static_cast<std::uint64_t>(w.evaluations);
  return r;
}

wire::FilterDetails to_wire(const in::FilterInfo& i) {
  wire::FilterDetails w{};
  w.instance = i.filter.has_value();
  if (i.filter) w.filter = to_wire(*i.filter);
  w.filter.type = i.type;
  w.type = i.type;
  w.doc = i.doc;
  w.missedSamples = static_cast<long long>(i.missed_samples);
  w.inputs = i.inputs;
  w.outputs = i.outputs;
  w.generatesEvents = i.generates_events;
  for (const in::ParamRow& p : i.params) {
    wire::ParamEntry e{};
    e.name = p.name;
    e.type = std::string(to_string(p.type));
    e.doc = p.doc;
    e.hasDefault = p.default_value.has_value();
    if (p.default_value) {
      e.defaultTyped = value_to_wire(*p.default_value);
      e.defaultValue = in::param_text(*p.default_value);
    }
    e.hasValue = p.value.has_value();
    if (p.value) {
      e.valueTyped = value_to_wire(*p.value);
      e.value = in::param_text(*p.value);
    }
    e.isOptional = p.optional;
    e.min = p.min;
    e.max = p.max;
    e.choices = p.choices;
    w.params.push_back(std::move(e));
  }
  return w;
}

in::FilterInfo from_wire(const wire::FilterDetails& w) {
  in::FilterInfo i;
  if (w.instance) i.filter = from_wire(w.filter);
  i.type = w.type;
  i.doc = w.doc;
  i.missed_samples = static_cast<std::uint64_t>(w.missedSamples);
  i.inputs = w.inputs;
  i.outputs = w.outputs;
  i.generates_events = w.generatesEvents;
  for (const wire::ParamEntry& e : w.params) {
    in::ParamRow p;
    p.name = e.name;
    p.type = param_type_of(e.type);
    p.doc = e.doc;
    if (e.hasDefault) p.default_value = value_from_wire(e.defaultTyped);
    if (e.hasValue) p.value = value_from_wire(e.valueTyped);
    p.optional = e.isOptional;
    p.min = e.min;
    p.max = e.max;
    p.choices = e.choices;
    i.params.push_back(std::move(p));
  }
  return i;
}

wire::EventEntry to_wire(const in::EventRow& r) {
  wire::EventEntry w{};
  w.name = r.name;
  w.severity = r.severity;
  w.onset = r.onset;
  for (const Transition t : r.transitions) w.transitions.emplace_back(to_string(t));
  w.completes = r.onset ? std::string() : r.counterpart;
  w.latched = r.latched;
  w.hazard = r.hazard;
  w.description = r.description;
  w.broadcast = r.broadcast;
  w.counterpart = r.counterpart;
  w.framework = r.framework;
  return w;
}

in::EventRow from_wire(const wire::EventEntry& w) {
  in::EventRow r;
  r.name = w.name;
  r.severity = w.severity;
  r.onset = w.onset;
  for (const std::string& t : w.transitions) {
    for (const Transition x :
         {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N, Transition::E2W}) {
      if (to_string(x) == t) r.transitions.push_back(x);
    }
  }
  r.counterpart = w.counterpart;
  r.latched = w.latched;
  r.hazard = w.hazard;
  r.description = w.description;
  r.broadcast = w.broadcast;
  r.framework = w.framework;
  return r;
}

wire::ConnectionEntry to_wire(const in::ConnectionRow& r) {
  wire::ConnectionEntry w{};
  w.required = r.required;
  w.provided = r.provided;
  w.remote = r.remote;
  w.hasRequiredState = r.required_state.has_value();
  w.requiredState = to_wire(r.required_state.value_or(State::Normal));
  w.hasServiceState = r.service_state.has_value();
  w.serviceState = to_wire(r.service_state.value_or(State::Normal));
  w.hasPropagate = r.propagate.has_value();
  w.propagate = to_wire(r.propagate.value_or(State::Error));
  return w;
}

in::ConnectionRow from_wire(const wire::ConnectionEntry& w) {
  in::ConnectionRow r;
  r.required = w.required;
  r.provided = w.provided;
  r.remote = w.remote;
  if (w.hasRequiredState) r.required_state = level_of(w.requiredState);
  if (w.hasServiceState) r.service_state = level_of(w.serviceState);
  if (w.hasPropagate) r.propagate = level_of(w.propagate);
  return r;
}

wire::ServiceEntry to_wire(const in::ServiceRow& r) {
  return wire::ServiceEntry{r.address, to_wire(r.state), std::string(to_string(r.propagate)), r.depends_on};
}

in::ServiceRow from_wire(const wire::ServiceEntry& w) {
  in::ServiceRow r;
  r.address = w.address;
  r.state = level_of(w.state);
  r.propagate = w.propagate == "Warning" ? State::Warning : State::Error;
  r.depends_on = w.dependsOn;
  return r;
}

wire::ExplainEntry to_wire(const Explanation& e) {
  wire::ExplainEntry w{};
  w.machine = e.machine;
  w.event = e.event;
  w.severity = e.severity;
  w.mirror = e.mirror;
  w.outstanding = e.outstanding;
  w.root = root_to_wire(e.root, to_wire(e.level), e.path);
  w.hazard = e.hazard;
  w.count = static_cast<int>(e.count);
  w.first = e.first.count();
  w.last = e.last.count();
  return w;
}

Explanation from_wire(const wire::ExplainEntry& w) {
  Explanation e;
  e.machine = w.machine;
  e.event = w.event;
  e.level = level_of(w.root.level);
  e.severity = w.severity;
  e.mirror = w.mirror;
  e.outstanding = w.outstanding;
  root_from_wire(w.root, e.root);
  e.hazard = w.hazard;
  e.path = w.root.path;
  e.count = static_cast<std::uint32_t>(w.count < 0 ? 0 : w.count);
  e.first = Time{w.first};
  e.last = Time{w.last};
  return e;
}

wire::ExplainReply to_wire(const in::ExplainAnswer& a) {
  wire::ExplainReply w{};
  w.address = a.address;
  w.state = to_wire(a.state);
  for (const Explanation& e : a.conditions) w.conditions.push_back(to_wire(e));
  return w;
}

in::ExplainAnswer from_wire(const wire::ExplainReply& w) {
  in::ExplainAnswer a;
  a.address = w.address;
  a.state = level_of(w.state);
  for (const wire::ExplainEntry& e : w.conditions) a.conditions.push_back(from_wire(e));
  return a;
}

wire::ClockEntry to_wire(const in::ClockInfo& c) {
  return wire::ClockEntry{
      c.base == in::TimeBase::Simulated, c.now.count(), c.wall_offset_ns, c.period, c.scenario, c.duration};
}

in::ClockInfo from_wire(const wire::ClockEntry& w) {
  in::ClockInfo c;
  c.base = w.simulated ? in::TimeBase::Simulated : in::TimeBase::Host;
  c.now = Time{w.now};
  c.wall_offset_ns = w.wallOffset;
  c.period = w.period;
  c.scenario = w.scenario;
  c.duration = w.duration;
  return c;
}

wire::NamesEntry to_wire(const in::Names& n) {
  return wire::NamesEntry{n.components, n.machines, n.addresses, n.events, n.filters, n.filter_types, n.signals};
}

in::Names from_wire(const wire::NamesEntry& w) {
  in::Names n;
  n.components = w.components;
  n.machines = w.machines;
  n.addresses = w.addresses;
  n.events = w.events;
  n.filters = w.filters;
  n.filter_types = w.filterTypes;
  n.signals = w.signals;
  return n;
}

}  // namespace safecass::middleware
