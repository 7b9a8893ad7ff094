// The remote operations (DESIGN §6 console commands) served by every coordinator process.
// Reads take the coordinator's lock briefly; writes are refused unless the process runs with
// --allow-write and the request carries its token. A bad request changes nothing.

#include "control.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "safecass/middleware/token.hpp"

namespace safecass::middleware::detail {

namespace {

std::string code_text(ErrorCode c) {
  switch (c) {
    case ErrorCode::Duplicate: return "Duplicate";
    case ErrorCode::NotFound: return "NotFound";
    case ErrorCode::InvalidArgument: return "InvalidArgument";
    case ErrorCode::InvalidState: return "InvalidState";
    case ErrorCode::Io: return "Io";
    case ErrorCode::Parse: return "Parse";
    case ErrorCode::Denied: return "Denied";
  }
  return "Error";
}

[[noreturn]] void raise(const Error& e) { throw wire::OperationError(code_text(e.code), e.message); }
[[noreturn]] void raise(ErrorCode c, std::string message) { raise(Error{c, std::move(message)}); }

std::string param_text(const ParamValue& v) {
  std::ostringstream out;
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          out << x;
        } else if constexpr (std::is_same_v<T, bool>) {
          out << (x ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::string>) {
          out << x;
        } else {
          out << '[';
          for (std::size_t i = 0; i < x.size(); ++i) out << (i ? ", " : "") << x[i];
          out << ']';
        }
      },
      v);
  return out.str();
}

wire::RecordEntry entry(const Coordinator& co, const Record& r) {
  wire::RecordEntry e;
  e.seq = static_cast<long long>(r.seq);
  fill_record(co, r, e);
  return e;
}

class ControlServant final : public wire::Control {
public:
  explicit ControlServant(ControlContext c) : c_(std::move(c)) {}

  std::string coordinator(const Ice::Current& current) override {
    check_read(current);
    return c_.name;
  }

  wire::StateEntrySeq stateList(std::string component, const Ice::Current& current) override {
    check_read(current);
    wire::StateEntrySeq out;
    const Coordinator& co = c_.co;
    auto outstanding_name = [&](EventId e) { return e == kNoEvent ? std::string() : co.event(e).name; };
    for (ComponentId id = 0; id < co.component_count(); ++id) {
      if (co.is_remote(id)) continue;
      if (!component.empty() && co.component_name(id) != component) continue;
      const StateSnapshot s = co.extended(id);
      out.push_back({std::string(co.component_name(id)), "component", to_wire(s.state), outstanding_name(s.outstanding)});
      auto machine = [&](MachineId m, const char* kind) {
        const StateSnapshot ms = co.snapshot(m);
        out.push_back({co.address_of(m), kind, to_wire(ms.state), outstanding_name(ms.outstanding)});
      };
      machine(co.framework_machine(id), "s_F");
      machine(co.application_machine(id), "s_A");
      for (MachineId m : co.provided_machines(id)) machine(m, "s_P");
      for (MachineId m : co.required_machines(id)) machine(m, "s_R");
      const auto& provided = co.provided_machines(id);
      for (std::uint32_t p = 0; p < provided.size(); ++p) {
        out.push_back({std::string(co.component_name(id)) + ".s_S." + std::string(co.interface_name(provided[p])), "s_S",
                       to_wire(co.service_state(id, p)), ""});
      }
    }
    if (!component.empty() && out.empty()) raise(ErrorCode::NotFound, "no component '" + component + "' in coordinator '" + c_.name + "'");
    return out;
  }

  wire::RecordEntrySeq stateHistory(std::string address, int last, const Ice::Current& current) override {
    check_read(current);
    const Coordinator& co = c_.co;
    std::vector<Record> records;
    if (address.empty()) {
      records = co.history(Address{});  // every component's transitions, in stream order
      std::erase_if(records, [](const Record& r) { return r.kind != RecordKind::ComponentTransition; });
    } else {
      auto a = co.resolve(address);
      if (!a) raise(a.error());
      if (a->kind == Address::Kind::Machine) {
        records = co.history(a->machine);
      } else if (a->kind == Address::Kind::Component) {
        records = co.component_history(a->component);
      } else {
        raise(ErrorCode::InvalidArgument, "state history: '" + address + "' is not a component or machine");
      }
    }
    return tail(records, last);
  }

  wire::FilterEntrySeq filterList(const Ice::Current& current) override {
    check_read(current);
    wire::FilterEntrySeq out;
    for (const auto& f : c_.monitor.filters()) out.push_back(filter_entry(*f));
    return out;
  }

  wire::FilterDetails filterInfo(std::string name, const Ice::Current& current) override {
    check_read(current);
    const Filter* f = c_.monitor.find_filter(name);
    const FilterRegistry::Entry* e = c_.registry.find(f != nullptr ? std::string_view(f->type()) : std::string_view(name));
    if (e == nullptr) raise(ErrorCode::NotFound, "no filter or filter type '" + name + "' in coordinator '" + c_.name + "'");
    wire::FilterDetails d;
    if (f != nullptr) {
      d.filter = filter_entry(*f);
      d.missedSamples = static_cast<long long>(f->missed_samples());
    } else {
      d.filter.type = e->manifest.type;
    }
    d.doc = e->manifest.doc;
    for (const ParamSpec& p : e->manifest.params) {
      wire::ParamEntry pe;
      pe.name = p.name;
      pe.type = std::string(to_string(p.type));
      if (p.default_value) pe.defaultValue = param_text(*p.default_value);
      if (f != nullptr) {
        const auto it = f->config().params.find(p.name);
        if (it != f->config().params.end()) pe.value = param_text(it->second);
      }
      pe.doc = p.doc;
      d.params.push_back(std::move(pe));
    }
    return d;
  }

  void filterInject(std::string token, std::string filter, wire::SampleSeq samples, const Ice::Current&) override {
    check_write(token, "filter inject");
    if (samples.empty()) raise(ErrorCode::InvalidArgument, "filter inject " + filter + ": no samples");
    if (auto r = c_.monitor.inject_shallow(filter, samples); !r) raise(r.error());
    c_.log("middleware: " + c_.name + ": filter inject " + filter + " (" + std::to_string(samples.size()) + " samples)");
  }

  void filterDinject(std::string token, std::string signal, wire::SampleSeq samples, const Ice::Current&) override {
    check_write(token, "filter dinject");
    deep(signal, samples);
  }

  void filterDinload(std::string token, std::string signal, std::string text, const Ice::Current&) override {
    check_write(token, "filter dinload");
    wire::SampleSeq samples;
    std::istringstream lines(text);
    std::string line;
    for (int number = 1; std::getline(lines, line); ++number) {
      line = line.substr(0, line.find('#'));
      for (char& ch : line) {
        if (ch == ',') ch = ' ';
      }
      std::istringstream words(line);
      std::vector<double> values;
      std::string word;
      while (words >> word) {
        char* end = nullptr;
        const double v = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0' || !std::isfinite(v)) {
          // Injected values are finite (Monitor's rule, docs/filters.md), said with the line.
          raise(ErrorCode::Parse, "filter dinload " + signal + ": line " + std::to_string(number) + ": '" + word +
                                      (end == word.c_str() || *end != '\0' ? "' is not a number"
                                                                             : "' is not a finite number: injected values must be finite"));
        }
        values.push_back(v);
      }
      if (!values.empty()) samples.push_back(std::move(values));
    }
    if (samples.empty()) raise(ErrorCode::InvalidArgument, "filter dinload " + signal + ": no samples");
    deep(signal, samples);
  }

  wire::EventEntrySeq eventList(const Ice::Current& current) override {
    check_read(current);
    wire::EventEntrySeq out;
    const Coordinator& co = c_.co;
    for (EventId id = 0; id < co.event_count(); ++id) {
      const Event& e = co.event(id);
      wire::EventEntry w;
      w.name = e.name;
      w.severity = e.severity;
      w.onset = e.is_onset;
      for (Transition t : {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N,
                           Transition::E2W}) {
        if (e.transitions.contains(t)) w.transitions.emplace_back(to_string(t));
      }
      w.completes = e.completes;
      w.latched = e.latched;
      w.hazard = e.hazard;
      w.description = e.description;
      out.push_back(std::move(w));
    }
    return out;
  }

  wire::RecordEntrySeq eventHistory(int last, const Ice::Current& current) override {
    check_read(current);
    const Coordinator& co = c_.co;
    std::vector<Record> records = co.history(Address{});  // in stream order
    std::erase_if(records, [](const Record& r) {
      return r.kind != RecordKind::Event && r.kind != RecordKind::Reset && r.kind != RecordKind::Injection;
    });
    return tail(records, last);
  }

  void eventGenerate(std::string token, std::string event, std::string target, const Ice::Current&) override {
    check_write(token, "event generate");
    if (auto r = c_.co.generate(event, target); !r) raise(r.error());
    c_.log("middleware: " + c_.name + ": event generate " + event + " " + target);
  }

  void eventBroadcast(std::string token, std::string event, const Ice::Current&) override {
    check_write(token, "event broadcast");
    if (auto r = c_.co.broadcast(event); !r) raise(r.error());
    c_.log("middleware: " + c_.name + ": event broadcast " + event);
  }

  wire::ConnectionEntrySeq connectionList(const Ice::Current& current) override {
    check_read(current);
    wire::ConnectionEntrySeq out;
    const Coordinator& co = c_.co;
    for (const Connection& k : co.connections()) {
      out.push_back({std::string(co.component_name(k.client)) + "." +
                         std::string(co.interface_name(co.required_machines(k.client)[k.required])),
                     std::string(co.component_name(k.provider)) + "." +
                         std::string(co.interface_name(co.provided_machines(k.provider)[k.provided])),
                     co.is_remote(k.provider)});
    }
    return out;
  }

  wire::ServiceEntrySeq serviceList(const Ice::Current& current) override {
    check_read(current);
    wire::ServiceEntrySeq out;
    const Coordinator& co = c_.co;
    for (ComponentId id = 0; id < co.component_count(); ++id) {
      if (co.is_remote(id)) continue;
      const auto& provided = co.provided_machines(id);
      for (std::uint32_t p = 0; p < provided.size(); ++p) {
        const ServiceDependency& d = co.service(id, p);
        wire::ServiceEntry s;
        const std::string cname(co.component_name(id));
        s.address = cname + ".s_S." + std::string(co.interface_name(provided[p]));
        s.state = to_wire(co.service_state(id, p));
        s.propagate = std::string(to_string(d.propagate));
        s.dependsOn.push_back(co.address_of(provided[p]));
        if (d.framework) s.dependsOn.push_back(cname + ".s_F");
        if (d.application) s.dependsOn.push_back(cname + ".s_A");
        const auto& required = co.required_machines(id);
        for (std::size_t r = 0; r < required.size(); ++r) {
          if (d.all_required || std::find(d.required.begin(), d.required.end(),
                                          std::string(co.interface_name(required[r]))) != d.required.end()) {
            s.dependsOn.push_back(co.address_of(required[r]));
          }
        }
        out.push_back(std::move(s));
      }
    }
    return out;
  }

  void reset(std::string token, std::string target, std::string who, std::string why, const Ice::Current&) override {
    check_write(token, "reset");
    if (who.empty()) who = "remote";
    if (auto r = c_.co.reset(target, who, why); !r) raise(r.error());
    c_.log("middleware: " + c_.name + ": reset " + target + " by " + who + ": " + why);
  }

  wire::ExplainEntrySeq explain(std::string address, const Ice::Current& current) override {
    check_read(current);
    auto why = c_.co.explain(address);
    if (!why) raise(why.error());
    wire::ExplainEntrySeq out;
    for (const Explanation& e : *why) out.push_back(to_wire(e));
    return out;
  }

private:
  /// Reads need the read credential when the process has one (in the request context, key
  /// kReadCredentialKey); the write token is accepted too.
  void check_read(const Ice::Current& current) {
    if (c_.read_token.empty()) return;
    const auto given = current.ctx.find(kReadCredentialKey);
    if (given != current.ctx.end() &&
        (token_matches(c_.read_token, given->second) || token_matches(c_.token, given->second))) {
      return;
    }
    c_.log("middleware: " + c_.name + ": refused " + current.operation + ": no read credential");
    raise(ErrorCode::Denied, current.operation + " refused: coordinator '" + c_.name +
                                 "' needs its read credential (--read-token-file)");
  }

  void check_write(const std::string& token, const char* what) {
    if (!c_.allow_write) {
      c_.log("middleware: " + c_.name + ": refused " + what + ": read-only");
      raise(ErrorCode::Denied, std::string(what) + " refused: coordinator '" + c_.name +
                                   "' runs read-only (start it with --allow-write)");
    }
    if (!token_matches(c_.token, token)) {
      c_.log("middleware: " + c_.name + ": refused " + what + ": wrong or missing token");
      raise(ErrorCode::Denied, std::string(what) + " refused: the request does not carry coordinator '" + c_.name +
                                   "''s token (read it from its token file)");
    }
  }

  void deep(const std::string& signal, const wire::SampleSeq& samples) {
    if (samples.empty()) raise(ErrorCode::InvalidArgument, "filter dinject " + signal + ": no samples");
    const Signal* s = c_.monitor.signals().find(signal);
    if (s == nullptr) raise(ErrorCode::NotFound, "no signal '" + signal + "' in coordinator '" + c_.name + "'");
    if (samples.size() > s->buffer().capacity()) {
      raise(ErrorCode::InvalidArgument, "filter dinject " + signal + ": more samples than its history buffer holds (" +
                                            std::to_string(s->buffer().capacity()) + ")");
    }
    if (auto r = c_.monitor.inject_deep(signal, samples, c_.co.clock().now()); !r) raise(r.error());
    c_.log("middleware: " + c_.name + ": deep injection into " + signal + " (" + std::to_string(samples.size()) + " samples)");
  }

  wire::RecordEntrySeq tail(std::vector<Record>& records, int last) const {
    std::sort(records.begin(), records.end(), [](const Record& a, const Record& b) { return a.seq < b.seq; });
    const std::size_t n = last <= 0 ? records.size() : std::min<std::size_t>(records.size(), static_cast<std::size_t>(last));
    wire::RecordEntrySeq out;
    for (std::size_t i = records.size() - n; i < records.size(); ++i) out.push_back(entry(c_.co, records[i]));
    return out;
  }

  wire::FilterEntry filter_entry(const Filter& f) const {
    wire::FilterEntry e;
    e.name = f.name();
    e.type = f.type();
    e.target = f.target() == kNoMachine ? "-" : c_.co.address_of(f.target());
    e.execution = f.execution() == ExecutionMode::Active ? "ACTIVE" : "PASSIVE";
    e.detection = f.detection() == DetectionMode::Edge ? "EDGE" : "LEVEL";
    e.enabled = f.enabled();
    e.detected = f.detected();
    for (const Signal* s : f.inputs()) if (s != nullptr) e.inputs.push_back(s->name());
    for (const Signal* s : f.outputs()) if (s != nullptr) e.outputs.push_back(s->name());
    return e;
  }

  ControlContext c_;
};

}  // namespace

std::shared_ptr<wire::Control> make_control(ControlContext context) {
  return std::make_shared<ControlServant>(std::move(context));
}

wire::ExplainEntry to_wire(const Explanation& e) {
  wire::ExplainEntry w;
  w.machine = e.machine;
  w.event = e.event;
  w.level = to_wire(e.level);
  w.severity = e.severity;
  w.mirror = e.mirror;
  w.outstanding = e.outstanding;
  w.root = wire::Root{e.root_event, e.root_origin, e.root_time.count(), to_wire(e.level), e.filter, e.signal, e.value,
                      e.sample_time.count(), e.injected, e.path};
  w.hazard = e.hazard;
  w.line = to_string(e);
  return w;
}

Explanation from_wire(const wire::ExplainEntry& w) {
  Explanation e;
  e.machine = w.machine;
  e.event = w.event;
  from_wire(w.level, e.level);
  e.severity = w.severity;
  e.mirror = w.mirror;
  e.outstanding = w.outstanding;
  e.root_event = w.root.event;
  e.root_origin = w.root.origin;
  e.root_time = Time{w.root.time};
  e.hazard = w.hazard;
  e.filter = w.root.filter;
  e.signal = w.root.signal;
  e.value = w.root.value;
  e.sample_time = Time{w.root.sampleTime};
  e.injected = w.root.injected;
  e.path = w.root.path;
  return e;
}

}  // namespace safecass::middleware::detail
