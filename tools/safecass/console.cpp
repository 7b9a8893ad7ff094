// `safecass console`: the in-process backend (a system in simulated time) and the terminal front
// end (run_console). The parser and `help` are in console_shell.cpp; the remote backend is in
// console_remote.cpp.

#include "console.hpp"
#include "console_shell.hpp"
#ifdef SAFECASS_WITH_ICE
#include "console_remote.hpp"
#endif

#include "safecass/spec/json.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <variant>

#include <CLI/CLI.hpp>
#include <editline/readline.h>

#include "safecass/filters/registry.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::tools {

using namespace console;

namespace {

std::string_view machine_kind_text(MachineKind k) {
  switch (k) {
    case MachineKind::Framework: return "framework";
    case MachineKind::Application: return "application";
    case MachineKind::Provided: return "provided";
    case MachineKind::Required: return "required";
  }
  return "?";
}

std::string transitions_text(TransitionSet set) {
  std::string out;
  for (Transition t : {Transition::N2W, Transition::N2E, Transition::W2E, Transition::W2N, Transition::E2N, Transition::E2W}) {
    if (set.contains(t)) out += (out.empty() ? "" : ",") + std::string(to_string(t));
  }
  return out;
}

std::string param_text(const ParamValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          return number_text(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return x;
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          std::string out = "[";
          for (std::size_t i = 0; i < x.size(); ++i) out += (i ? ", " : "") + x[i];
          return out + "]";
        } else {
          std::string out = "[";
          for (std::size_t i = 0; i < x.size(); ++i) out += (i ? ", " : "") + number_text(x[i]);
          return out + "]";
        }
      },
      v);
}

std::string param_json(const ParamValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          return json_number(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return json_string(x);
        } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
          return json_list(x);
        } else {
          std::string out = "[";
          for (std::size_t i = 0; i < x.size(); ++i) out += (i ? "," : "") + json_number(x[i]);
          return out + "]";
        }
      },
      v);
}

std::string range_text(const ParamSpec& p) {
  if (p.type == ParamType::Choice) {
    std::string out;
    for (const std::string& c : p.choices) out += (out.empty() ? "" : "|") + c;
    return out;
  }
  if (p.type != ParamType::Number && p.type != ParamType::Integer) return {};
  const bool low = p.min > -1e299;
  const bool high = p.max < 1e299;
  if (!low && !high) return {};
  return "[" + (low ? number_text(p.min) : std::string("-inf")) + ", " + (high ? number_text(p.max) : std::string("+inf")) + "]";
}

std::string default_text(const ParamSpec& p) {
  if (p.default_value) return param_text(*p.default_value);
  return p.optional ? "(optional)" : "(required)";
}

bool shown_record(const Record& r) {
  return r.kind == RecordKind::Transition || r.kind == RecordKind::Reset || r.kind == RecordKind::Injection ||
         (r.kind == RecordKind::Event && (r.outcome == Outcome::Masked || r.outcome == Outcome::Ignored));
}

// ---- the in-process backend ----------------------------------------------------------------------

/// A system running in this process in simulated time.
class InProcessBackend final : public Backend {
public:
  ConsoleOptions options;
  FilterRegistry registry;  // outlives the runner's monitor
  std::unique_ptr<runner::ScenarioRunner> runner;
  runner::RunResult run_result;       // expectation failures of the scenario so far
  std::size_t failures_reported = 0;
  std::vector<std::string> captured;  // records shown since the last flush, formatted
  std::size_t transitions = 0;        // machine transitions seen, for the summary of watch
  Coordinator::SubscriptionId subscription = 0;
  std::string system_path;
  std::string scenario_path;

  ~InProcessBackend() override {
    if (runner && subscription != 0) runner->coordinator().unsubscribe(subscription);
  }

  Coordinator& co() { return runner->coordinator(); }
  const Coordinator& co() const { return runner->coordinator(); }
  Monitor& monitor() { return runner->monitor(); }
  const Monitor& monitor() const { return runner->monitor(); }
  Time now() const { return std::max(runner->now(), Time{0}); }

  void flush_captured(Out& out) {
    for (std::string& line : captured) out.line(std::move(line));
    captured.clear();
  }

  /// The confirmation line of a write command.
  void write_done(Out& out, const CommandSpec& c, Json json, const std::string& text) const {
    console::write_done(out, options.json, c, std::move(json), text, to_seconds(now()));
  }

  // ---- names for completion ----
  std::vector<std::string> names(Arg kind) const override {
    std::vector<std::string> out;
    const Coordinator& c = co();
    switch (kind) {
      case Arg::Component:
        for (ComponentId i = 0; i < c.component_count(); ++i) out.emplace_back(c.component_name(i));
        break;
      case Arg::Machine:
        for (MachineId m = 0; m < c.machine_count(); ++m) out.push_back(c.address_of(m));
        break;
      case Arg::Address:
        out.emplace_back("SYSTEM");
        for (ComponentId i = 0; i < c.component_count(); ++i) {
          out.emplace_back(c.component_name(i));
          for (MachineId p : c.provided_machines(i)) {
            out.push_back(std::string(c.component_name(i)) + ".s_S." + std::string(c.interface_name(p)));
          }
        }
        for (MachineId m = 0; m < c.machine_count(); ++m) out.push_back(c.address_of(m));
        break;
      case Arg::Event:
        for (EventId e = 0; e < c.event_count(); ++e) out.push_back(c.event(e).name);
        break;
      case Arg::Filter:
      case Arg::FilterOrType:
        for (const auto& f : monitor().filters()) out.push_back(f->name());
        if (kind == Arg::FilterOrType) {
          for (const FilterManifest* m : registry.manifests()) out.push_back(m->type);
        }
        break;
      case Arg::Signal:
        for (const auto& s : monitor().signals().all()) out.push_back(s->name());
        break;
      case Arg::Command:
      case Arg::None:
      case Arg::File: break;
    }
    return out;
  }

  void begin() override { captured.clear(); }
  void end(Out& out, bool ok) override {
    if (ok) flush_captured(out);
    captured.clear();
  }

  /// Runs one command; returns an error message, or empty on success.
  std::string run(const CommandSpec& c, const std::vector<std::string>& args, Out& out) override {
    switch (c.id) {
      case Id::StateList: return state_list(args, out);
      case Id::StateHistory: return state_history(args, out);
      case Id::FilterList: return filter_list(out);
      case Id::FilterInfo: return filter_info(args[0], out);
      case Id::FilterInject: return filter_inject(c, args, out);
      case Id::FilterDinject: return filter_dinject(c, args, out);
      case Id::FilterDinload: return filter_dinload(c, args, out);
      case Id::EventList: return event_list(out);
      case Id::EventHistory: return event_history(args, out);
      case Id::EventGenerate: return event_generate(c, args, out);
      case Id::EventBroadcast: return event_broadcast(c, args, out);
      case Id::ConnectionList: return connection_list(out);
      case Id::ServiceList: return service_list(out);
      case Id::Explain: return explain(args[0], out);
      case Id::Watch: return watch(args, out);
      case Id::Reset: return reset(c, args, out);
      case Id::Time: return time(out);
      case Id::Help:
      case Id::Quit: break;  // the Console answers these itself
    }
    return "not available here";
  }

  std::string outstanding_name(EventId e) const { return e == kNoEvent ? std::string() : co().event(e).name; }

  std::string state_list(const std::vector<std::string>& args, Out& out) {
    const Coordinator& c = co();
    ComponentId only = kNoComponent;
    if (!args.empty()) {
      auto id = c.find_component(args[0]);
      if (!id) return id.error().message;
      only = *id;
    }
    std::vector<std::vector<std::string>> rows;
    auto row = [&](const std::string& indent, const std::string& address, std::string_view kind, StateSnapshot s) {
      if (options.json) {
        out.line(Json().str("address", address).str("kind", kind).str("state", to_string(s.state))
                     .opt("outstanding", outstanding_name(s.outstanding)).text());
      } else {
        const std::string event = outstanding_name(s.outstanding);
        rows.push_back({indent + address, std::string(to_string(s.state)), event.empty() ? "-" : event});
      }
    };
    if (only == kNoComponent) row("", "SYSTEM", "system", StateSnapshot{c.state_of(Address{}), kNoEvent});
    for (ComponentId id = 0; id < c.component_count(); ++id) {
      if (only != kNoComponent && id != only) continue;
      row("", std::string(c.component_name(id)), "component", c.extended(id));
      std::vector<MachineId> machines{c.framework_machine(id), c.application_machine(id)};
      machines.insert(machines.end(), c.provided_machines(id).begin(), c.provided_machines(id).end());
      machines.insert(machines.end(), c.required_machines(id).begin(), c.required_machines(id).end());
      for (MachineId m : machines) row("  ", c.address_of(m), machine_kind_text(c.machine_kind(m)), c.snapshot(m));
    }
    if (!options.json) out.reply.out += columns(rows);
    return {};
  }

  /// Records of every machine and component history in `scope`, merged in stream order.
  std::vector<Record> merged_history(const Address& scope, bool events_only) const {
    std::vector<Record> all = co().history(scope);
    if (events_only) std::erase_if(all, [](const Record& r) { return r.kind != RecordKind::Event; });
    return all;
  }

  void print_records(const std::vector<Record>& records, long last, Out& out, std::string_view empty) const {
    const std::size_t n = std::min(records.size(), static_cast<std::size_t>(last));
    for (std::size_t i = records.size() - n; i < records.size(); ++i) {
      out.line(options.json ? record_to_json(records[i], co()) : record_to_text(records[i], co()));
    }
    if (n == 0 && !options.json) out.line(std::string(empty));
  }

  std::string state_history(const std::vector<std::string>& args, Out& out) {
    Address scope;  // SYSTEM
    long last = kDefaultHistory;
    std::size_t next = 0;
    if (!args.empty() && !parse_count(args[0])) {
      auto a = co().resolve(args[0]);
      if (!a) return a.error().message;
      scope = *a;
      if (scope.kind == Address::Kind::Service) scope.kind = Address::Kind::Component;
      next = 1;
    }
    if (next < args.size()) {
      const auto n = parse_count(args[next]);
      if (!n) return "N must be a positive whole number, not '" + args[next] + "'";
      last = *n;
      ++next;
    }
    if (next < args.size()) return "too many arguments";
    print_records(merged_history(scope, false), last, out, "no records");
    return {};
  }

  std::string filter_list(Out& out) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& f : monitor().filters()) {
      std::vector<std::string> inputs;
      std::vector<std::string> outputs;
      for (const Signal* s : f->inputs()) if (s != nullptr) inputs.push_back(s->name());
      for (const Signal* s : f->outputs()) if (s != nullptr) outputs.push_back(s->name());
      const std::string target = f->target() == kNoMachine ? "-" : co().address_of(f->target());
      const char* execution = f->execution() == ExecutionMode::Active ? "ACTIVE" : "PASSIVE";
      const char* detection = f->detection() == DetectionMode::Edge ? "EDGE" : "LEVEL";
      if (options.json) {
        out.line(Json().str("filter", f->name()).str("type", f->type()).str("target", target).str("execution", execution)
                     .str("detection", detection).boolean("enabled", f->enabled()).boolean("detected", f->detected())
                     .raw("inputs", json_list(inputs)).raw("outputs", json_list(outputs)).text());
        continue;
      }
      std::string signals;
      for (const std::string& s : inputs) signals += (signals.empty() ? "" : ",") + s;
      if (!outputs.empty()) {
        signals += " ->";
        for (std::size_t i = 0; i < outputs.size(); ++i) signals += (i ? "," : " ") + outputs[i];
      }
      rows.push_back({f->name(), f->type(), target, execution, detection, f->enabled() ? "enabled" : "disabled",
                      f->detected() ? "DETECTED" : "-", signals});
    }
    if (!options.json) {
      if (rows.empty()) out.line("no filters");
      out.reply.out += columns(rows);
    }
    return {};
  }

  std::string filter_info(const std::string& name, Out& out) {
    const Filter* f = monitor().find_filter(name);
    const FilterRegistry::Entry* entry = registry.find(f != nullptr ? std::string_view(f->type()) : std::string_view(name));
    if (entry == nullptr) return "no filter or filter type '" + name + "' (see filter list)";
    const FilterManifest& m = entry->manifest;
    if (options.json) {
      Json head;
      head.opt("filter", f != nullptr ? f->name() : std::string()).str("type", m.type).str("doc", m.doc)
          .raw("inputs", json_list(m.inputs)).raw("outputs", json_list(m.outputs))
          .boolean("generates_events", m.generates_events);
      if (f != nullptr) {
        std::vector<std::string> in, outs;
        for (const Signal* s : f->inputs()) if (s != nullptr) in.push_back(s->name());
        for (const Signal* s : f->outputs()) if (s != nullptr) outs.push_back(s->name());
        head.str("target", f->target() == kNoMachine ? "" : co().address_of(f->target()))
            .str("execution", f->execution() == ExecutionMode::Active ? "ACTIVE" : "PASSIVE")
            .str("detection", f->detection() == DetectionMode::Edge ? "EDGE" : "LEVEL")
            .boolean("enabled", f->enabled()).boolean("detected", f->detected())
            .integer("missed_samples", static_cast<long long>(f->missed_samples()))
            .raw("input_signals", json_list(in)).raw("output_signals", json_list(outs));
      }
      out.line(head.text());
      for (const ParamSpec& p : m.params) {
        Json j;
        j.str("param", p.name).str("type", to_string(p.type))
            .raw("default", p.default_value ? param_json(*p.default_value) : "null")
            .boolean("required", !p.default_value && !p.optional);
        if (p.type == ParamType::Number || p.type == ParamType::Integer) {
          j.raw("min", p.min > -1e299 ? json_number(p.min) : "null").raw("max", p.max < 1e299 ? json_number(p.max) : "null");
        }
        if (p.type == ParamType::Choice) j.raw("choices", json_list(p.choices));
        if (f != nullptr) {
          const auto it = f->config().params.find(p.name);
          j.raw("value", it == f->config().params.end() ? "null" : param_json(it->second));
        }
        out.line(j.str("doc", p.doc).text());
      }
      return {};
    }
    if (f != nullptr) {
      out.line("filter " + f->name() + ": " + m.type + " - " + m.doc);
      std::string in, outs;
      for (const Signal* s : f->inputs()) if (s != nullptr) in += (in.empty() ? "" : ", ") + s->name() + " (size " + std::to_string(s->size()) + ")";
      for (const Signal* s : f->outputs()) if (s != nullptr) outs += (outs.empty() ? "" : ", ") + s->name() + " (size " + std::to_string(s->size()) + ")";
      out.line("  target " + (f->target() == kNoMachine ? std::string("-") : co().address_of(f->target())) + ", " +
               (f->execution() == ExecutionMode::Active ? "ACTIVE" : "PASSIVE") + ", " +
               (f->detection() == DetectionMode::Edge ? "EDGE" : "LEVEL"));
      out.line(std::string("  ") + (f->enabled() ? "enabled" : "disabled") + ", " +
               (f->detected() ? "detected (onset sent, no completion yet)" : "not detected") + ", " +
               std::to_string(f->missed_samples()) + " missed samples");
      out.line("  inputs:  " + (in.empty() ? std::string("-") : in));
      out.line("  outputs: " + (outs.empty() ? std::string("-") : outs));
    } else {
      out.line("filter type " + m.type + ": " + m.doc);
      std::string in, outs;
      for (const std::string& s : m.inputs) in += (in.empty() ? "" : ", ") + s;
      for (const std::string& s : m.outputs) outs += (outs.empty() ? "" : ", ") + s;
      out.line("  inputs:  " + (in.empty() ? std::string("-") : in));
      out.line("  outputs: " + (outs.empty() ? std::string("-") : outs));
    }
    out.line("  parameters:");
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"    name", "type", f != nullptr ? "value" : "", "default", "range", "doc"});
    for (const ParamSpec& p : m.params) {
      std::string value;
      if (f != nullptr) {
        const auto it = f->config().params.find(p.name);
        value = it == f->config().params.end() ? "-" : param_text(it->second);
      }
      const std::string range = range_text(p);
      rows.push_back({"    " + p.name, std::string(to_string(p.type)), value, default_text(p), range.empty() ? "-" : range, p.doc});
    }
    if (f == nullptr) {
      for (auto& r : rows) r.erase(r.begin() + 2);
    }
    out.reply.out += columns(rows);
    return {};
  }

  std::string filter_inject(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    auto samples = parse_samples({args.begin() + 1, args.end()});
    if (!samples) return samples.error().message;
    if (monitor().find_filter(args[0]) == nullptr) return "no filter '" + args[0] + "' (see filter list)";
    if (auto r = monitor().inject_shallow(args[0], *samples); !r) return r.error().message;
    write_done(out, c, Json().str("filter", args[0]).integer("samples", static_cast<long long>(samples->size())),
               "queued " + count_text(samples->size()) + " into filter " + args[0] +
                   " (seen by that filter alone on its next runs: use watch)");
    return {};
  }

  std::string deep_inject(const CommandSpec& c, const std::string& signal, const std::vector<std::vector<double>>& samples,
                          Out& out) {
    Signal* s = monitor().signals().find(signal);
    if (s == nullptr) return "no signal '" + signal + "' (signals are written Component.signal)";
    if (samples.size() > s->buffer().capacity()) {
      return count_text(samples.size()) + " would overflow the history of '" + signal + "' (" +
             std::to_string(s->buffer().capacity()) + " samples): inject fewer at once";
    }
    if (auto r = monitor().inject_deep(signal, samples, now()); !r) return r.error().message;
    write_done(out, c, Json().str("signal", signal).integer("samples", static_cast<long long>(samples.size())),
               "wrote " + count_text(samples.size()) + " into signal " + signal + " at t=" + seconds_text(now()) +
                   " (seen by every consumer on its next run: use watch)");
    return {};
  }

  std::string filter_dinject(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    auto samples = parse_samples({args.begin() + 1, args.end()});
    if (!samples) return samples.error().message;
    return deep_inject(c, args[0], *samples, out);
  }

  std::string filter_dinload(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    std::string text;
    std::string error;
    if (!spec::read_file(args[1], text, error)) return error;
    auto samples = parse_sample_file(args[1], text);
    if (!samples) return samples.error().message;
    return deep_inject(c, args[0], *samples, out);
  }

  std::string event_list(Out& out) {
    const Coordinator& c = co();
    std::vector<std::vector<std::string>> rows;
    for (EventId id = 0; id < c.event_count(); ++id) {
      const Event& e = c.event(id);
      const std::string kind = e.is_broadcast() ? "broadcast" : e.is_onset ? "onset" : "completion";
      const std::string counterpart = e.counterpart == kNoEvent ? std::string() : c.event(e.counterpart).name;
      const bool framework = id < framework_event::kCount;
      if (options.json) {
        out.line(Json().str("event", e.name).integer("severity", e.severity).str("kind", kind)
                     .str("transitions", transitions_text(e.transitions)).opt(e.is_onset ? "completion" : "completes", counterpart)
                     .boolean("latched", e.latched).boolean("framework", framework).opt("hazard", e.hazard)
                     .opt("description", e.description).text());
        continue;
      }
      std::string extra;
      if (!counterpart.empty()) extra += (e.is_onset ? "cleared by " : "clears ") + counterpart;
      if (e.latched) extra += (extra.empty() ? "" : ", ") + std::string("latched");
      if (framework) extra += (extra.empty() ? "" : ", ") + std::string("framework");
      if (!e.hazard.empty()) extra += (extra.empty() ? "" : ", ") + std::string("hazard ") + e.hazard;
      if (!e.description.empty()) extra += (extra.empty() ? "" : " - ") + e.description;
      rows.push_back({e.name, std::to_string(e.severity), kind, transitions_text(e.transitions), extra});
    }
    if (!options.json) out.reply.out += columns(rows);
    return {};
  }

  std::string event_history(const std::vector<std::string>& args, Out& out) {
    long last = kDefaultHistory;
    if (!args.empty()) {
      const auto n = parse_count(args[0]);
      if (!n) return "N must be a positive whole number, not '" + args[0] + "'";
      last = *n;
    }
    print_records(merged_history(Address{}, true), last, out, "no events yet");
    return {};
  }

  std::string event_generate(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    if (auto r = co().generate(args[0], args[1]); !r) return r.error().message;
    write_done(out, c, Json().str("event", args[0]).str("target", args[1]),
               "generated " + args[0] + " on " + args[1] + " at t=" + seconds_text(now()));
    return {};
  }

  std::string event_broadcast(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    if (auto r = co().broadcast(args[0]); !r) return r.error().message;
    write_done(out, c, Json().str("event", args[0]), "broadcast " + args[0] + " at t=" + seconds_text(now()));
    return {};
  }

  std::string connection_list(Out& out) {
    const Coordinator& c = co();
    std::vector<std::vector<std::string>> rows;
    for (const Connection& k : c.connections()) {
      const MachineId required = c.required_machines(k.client)[k.required];
      const MachineId provided = c.provided_machines(k.provider)[k.provided];
      const std::string client = std::string(c.component_name(k.client)) + "." + std::string(c.interface_name(required));
      const std::string provider = std::string(c.component_name(k.provider)) + "." + std::string(c.interface_name(provided));
      const State required_state = c.state(required);
      const State service_state = c.service_state(k.provider, k.provided);
      const State propagate = c.service(k.provider, k.provided).propagate;
      if (options.json) {
        out.line(Json().str("required", client).str("provided", provider).str("required_state", to_string(required_state))
                     .str("service_state", to_string(service_state)).str("propagates", to_string(propagate)).text());
      } else {
        rows.push_back({client, "->", provider, "s_R " + std::string(to_string(required_state)),
                        "s_S " + std::string(to_string(service_state)),
                        "propagates " + std::string(propagate == State::Warning ? "Warning and Error" : "Error")});
      }
    }
    if (!options.json) {
      if (rows.empty()) out.line("no connections");
      out.reply.out += columns(rows);
    }
    return {};
  }

  std::string service_list(Out& out) {
    const Coordinator& c = co();
    std::vector<std::vector<std::string>> rows;
    for (ComponentId id = 0; id < c.component_count(); ++id) {
      const auto& provided = c.provided_machines(id);
      for (std::uint32_t i = 0; i < provided.size(); ++i) {
        const std::string p(c.interface_name(provided[i]));
        const ServiceDependency& d = c.service(id, i);
        std::vector<std::string> terms{"s_P." + p};
        if (d.framework) terms.emplace_back("s_F");
        if (d.application) terms.emplace_back("s_A");
        if (d.all_required) {
          for (MachineId r : c.required_machines(id)) terms.push_back("s_R." + std::string(c.interface_name(r)));
        } else {
          for (const std::string& r : d.required) terms.push_back("s_R." + r);
        }
        std::string formula;
        for (const std::string& t : terms) formula += (formula.empty() ? "" : " * ") + t;
        const std::string address = std::string(c.component_name(id)) + ".s_S." + p;
        const State s = c.service_state(id, i);
        if (options.json) {
          out.line(Json().str("service", address).str("state", to_string(s)).raw("depends_on", json_list(terms))
                       .str("propagates", to_string(d.propagate)).text());
        } else {
          rows.push_back({address, std::string(to_string(s)), "= " + formula,
                          "(propagates " + std::string(d.propagate == State::Warning ? "Warning and Error" : "Error") + ")"});
        }
      }
    }
    if (!options.json) {
      if (rows.empty()) out.line("no provided interfaces");
      out.reply.out += columns(rows);
    }
    return {};
  }

  std::string explain(const std::string& address, Out& out) {
    auto a = co().resolve(address);
    if (!a) return a.error().message;
    print_explanations(co().explain(*a), address, to_string(co().state_of(*a)), options.json, true, out);
    return {};
  }

  std::string watch(const std::vector<std::string>& args, Out& out) {
    double seconds = 1.0;
    if (!args.empty()) {
      const auto v = parse_number(args[0]);
      if (!v || !std::isfinite(*v) || *v <= 0 || *v > kMaxWatchSeconds) {
        return "SECONDS must be a number of seconds above 0 and at most " + number_text(kMaxWatchSeconds) + ", not '" + args[0] + "'";
      }
      seconds = *v;
    }
    const Time start = now();
    const Time target = start + seconds_to_time(seconds);
    const Time tick = seconds_to_time(runner->scenario().period);
    const std::size_t transitions_before = transitions;
    for (Time t = runner->now() + tick; t <= target; t += tick) {
      runner->advance_to(t, run_result);
      flush_captured(out);
      for (; failures_reported < run_result.failures.size(); ++failures_reported) {
        const std::string& f = run_result.failures[failures_reported];
        out.line(options.json ? Json().str("kind", "expectation").str("failure", f).text() : f);
      }
    }
    const std::size_t seen = transitions - transitions_before;
    if (options.json) {
      out.line(Json().str("command", "watch").num("from", to_seconds(start)).num("t", to_seconds(now()))
                   .integer("transitions", static_cast<long long>(seen)).text());
    } else {
      out.line("t=" + seconds_text(now()) + "  watched " + number_text(seconds) + " s: " + std::to_string(seen) +
               (seen == 1 ? " transition" : " transitions"));
    }
    return {};
  }

  std::string reset(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    std::string reason;
    for (std::size_t i = 1; i < args.size(); ++i) reason += (reason.empty() ? "" : " ") + args[i];
    if (reason.empty()) reason = "reset from the console";
    if (auto r = co().reset(args[0], "console", reason); !r) return r.error().message;
    write_done(out, c, Json().str("target", args[0]).str("reason", reason),
               "reset " + args[0] + " at t=" + seconds_text(now()) + " (" + reason + ")");
    return {};
  }

  std::string time(Out& out) {
    const spec::Scenario& s = runner->scenario();
    if (options.json) {
      Json j;
      j.num("t", to_seconds(now())).num("period", s.period);
      if (!scenario_path.empty()) j.str("scenario", scenario_path).num("duration", s.duration);
      out.line(j.text());
      return {};
    }
    std::string line = "t=" + seconds_text(now()) + " s (simulated; tick " + number_text(s.period) + " s";
    if (!scenario_path.empty()) {
      line += "; scenario " + scenario_path + " lasts " + number_text(s.duration) + " s" +
              (now() > seconds_to_time(s.duration) ? ", ended" : "");
    }
    out.line(line + ")");
    return {};
  }

  std::string banner() const override {
    const Coordinator& c = co();
    return "safecass console: system " + system_path + " (" + std::to_string(c.component_count()) + " components" +
           (scenario_path.empty() ? "" : ", scenario " + scenario_path) + "), simulated time t=" + seconds_text(now()) +
           ", " + (options.allow_write ? "writes allowed" : "read-only") + ". Type help, or TAB to complete.";
  }
};

}  // namespace

// ---- Console -------------------------------------------------------------------------------------

Expected<std::unique_ptr<Console>> Console::open(const std::string& system, const std::string& scenario,
                                                 ConsoleOptions options) {
  auto impl = std::make_unique<InProcessBackend>();
  impl->options = options;
  register_builtin_filters(impl->registry);
  auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{scenario, system}, impl->registry);
  if (!opened) return fail(ErrorCode::InvalidArgument, runner::to_text(opened.error()));
  impl->runner = std::move(*opened);
  impl->scenario_path = scenario;
  impl->system_path = impl->runner->scenario().system;
  InProcessBackend* self = impl.get();
  impl->subscription = impl->runner->coordinator().subscribe([self](const Record& r) {
    if (!shown_record(r)) return;
    if (r.kind == RecordKind::Transition) ++self->transitions;
    self->captured.push_back(self->options.json ? record_to_json(r, self->co()) : record_to_text(r, self->co()));
  });
  impl->runner->advance_to(Time{0}, impl->run_result);
  impl->captured.clear();  // what happened at t = 0 is in the histories
  return std::make_unique<Console>(std::move(impl), options);
}

// ---- terminal front end --------------------------------------------------------------------------

namespace {

void print(const ConsoleReply& reply) {
  std::fputs(reply.out.c_str(), stdout);
  std::fflush(stdout);
  std::fputs(reply.err.c_str(), stderr);
  std::fflush(stderr);
}

/// Runs commands one after the other; 2 when any failed, 0 otherwise.
int run_batch(Console& console, const std::vector<std::string>& lines) {
  bool failed = false;
  for (const std::string& line : lines) {
    const ConsoleReply reply = console.execute(line);
    print(reply);
    failed = failed || !reply.ok;
    if (reply.quit) break;
  }
  return failed ? 2 : 0;
}

// libedit calls plain C functions: these statics connect them to the one interactive console.
Console* g_console = nullptr;
std::vector<std::string> g_matches;
std::size_t g_next_match = 0;

char* next_match(const char* /*text*/, int state) {
  if (state == 0) g_next_match = 0;
  if (g_next_match >= g_matches.size()) return nullptr;
  return strdup(g_matches[g_next_match++].c_str());
}

char** attempt_completion(const char* text, int start, int /*end*/) {
  const std::string line = rl_line_buffer != nullptr ? std::string(rl_line_buffer) : std::string();
  const std::string before = line.substr(0, std::min(line.size(), static_cast<std::size_t>(std::max(start, 0))));
  if (g_console->completes_file(before)) return nullptr;  // libedit completes the file name
  rl_attempted_completion_over = 1;
  g_matches = g_console->complete(before, text);
  if (g_matches.empty()) return nullptr;
  return rl_completion_matches(text, next_match);
}

int run_interactive(Console& console) {
  g_console = &console;
  rl_readline_name = "safecass";
  rl_attempted_completion_function = attempt_completion;
  using_history();
  stifle_history(1000);
  std::printf("%s\n", console.banner().c_str());
  std::fflush(stdout);
  std::string previous;
  for (;;) {
    char* raw = readline("safecass> ");
    if (raw == nullptr) {  // end of input (Ctrl-D)
      std::printf("\n");
      break;
    }
    const std::string line(raw);
    std::free(raw);
    const std::string entry(trim(line));
    if (!entry.empty() && entry != previous) {
      add_history(entry.c_str());
      previous = entry;
    }
    const ConsoleReply reply = console.execute(line);
    print(reply);
    if (reply.quit) break;
  }
  g_console = nullptr;
  return 0;
}

/// "a; b\nc" -> {"a", "b", "c"}.
std::vector<std::string> split_commands(const std::string& text) {
  std::vector<std::string> out;
  std::string current;
  for (const char c : text) {
    if (c == ';' || c == '\n') {
      out.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  out.push_back(current);
  return out;
}

}  // namespace

int run_console(const ConsoleArgs& args) {
  std::vector<std::string> script;
  if (!args.script.empty()) {
    std::string text;
    std::string error;
    if (!spec::read_file(args.script, text, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 2;
    }
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) script.push_back(line);
  }
  Expected<std::unique_ptr<Console>> console = fail(ErrorCode::InvalidArgument, "no console");
  if (!args.ice.empty()) {
#ifdef SAFECASS_WITH_ICE
    console = connect_console(args);
#else
    std::fprintf(stderr, "console: --ice needs the middleware, and this safecass was built without it (SAFECASS_WITH_ICE)\n");
    return 2;
#endif
  } else {
    console = Console::open(args.system, args.scenario, ConsoleOptions{args.json, args.allow_write});
  }
  if (!console) {
    std::fprintf(stderr, "%s\n", console.error().message.c_str());
    return 2;
  }
  if (!args.commands.empty()) return run_batch(**console, split_commands(args.commands));
  if (!args.script.empty()) return run_batch(**console, script);
  if (isatty(STDIN_FILENO) != 0) return run_interactive(**console);
  std::vector<std::string> lines;
  for (std::string line; std::getline(std::cin, line);) lines.push_back(line);
  return run_batch(**console, lines);
}

void add_console_command(CLI::App& app, int& code) {
  auto args = std::make_shared<ConsoleArgs>();
  auto* cmd = app.add_subcommand("console", "Read and write the component model of a system, interactively or from commands");
  cmd->footer(
      "Runs the system in-process in simulated time (as `safecass run` does); with --scenario its steps are "
      "applied as `watch` advances time. With --ice HOST:PORT --coordinator NAME it works on a live coordinator "
      "process instead (`safecass run ... --coordinator NAME --ice ...`), found through IceStorm; writes then also "
      "need the coordinator's token (--token-file), and `watch SECONDS` polls its states. Write commands (filter "
      "inject/dinject/dinload, event generate/broadcast, reset) are refused unless --allow-write is given. Without "
      "-c or --script, commands are read from the terminal (line editing, history, TAB completion) or from stdin. "
      "Exit code 2 when the system cannot be loaded or the coordinator cannot be reached, or, with "
      "-c/--script/stdin, when any command failed; 0 otherwise. Type `help` inside the console for the commands.");
  cmd->add_option("--system", args->system, "system file (default: the scenario's \"system\")");
  cmd->add_option("--scenario,-s", args->scenario, "scenario file whose steps are applied as simulated time advances");
  auto* commands = cmd->add_option("-c,--command", args->commands, "commands to run, separated by ';'");
  cmd->add_option("--script", args->script, "file of commands, one per line ('#' starts a comment)")->excludes(commands);
  cmd->add_flag("--json", args->json, "print one JSON object per result line");
  cmd->add_flag("--allow-write", args->allow_write, "accept write commands (inject, generate, broadcast, reset)");
  cmd->add_option("--ice", args->ice, "work on a live coordinator: IceStorm at HOST:PORT (with --coordinator)");
  cmd->add_option("--coordinator", args->coordinator, "with --ice: the coordinator's name");
  cmd->add_option("--keys", args->keys,
                  "with --ice: the system's bus keys (only the keyring is read; default $SAFECASS_KEYS)");
  cmd->add_flag("--insecure", args->insecure,
                "with --ice: accept a coordinator not on this host although requests and the token are not encrypted");
  cmd->add_option("--read-token-file", args->read_token_file,
                  "with --ice: the coordinator's read credential file (when it was started with one)");
  cmd->add_option("--tls", args->tls, "with --ice: mutual TLS; DIR holds ca.pem and console.pem/.key (scripts/setup-tls)");
  cmd->add_option("--token-file", args->token_file, "with --ice: the coordinator's token file (writes need it)");
  cmd->add_option("--timeout", args->timeout_ms, "with --ice: milliseconds to wait for the coordinator and each answer (default 2000)")
      ->check(CLI::Range(100, 600000));
  cmd->callback([args, &code] {
    const bool remote = !args->ice.empty() || !args->coordinator.empty() || !args->token_file.empty();
    std::string usage;
    if (remote && (args->ice.empty() || args->coordinator.empty())) {
      usage = "console: --ice HOST:PORT and --coordinator NAME go together";
    } else if (remote && (!args->system.empty() || !args->scenario.empty())) {
      usage = "console: --ice works on a live coordinator: --system and --scenario are for the in-process console";
    } else if (!remote && args->system.empty() && args->scenario.empty()) {
      usage = "console: --system (or --scenario, or --ice with --coordinator) is required";
    }
    if (!usage.empty()) {
      std::fprintf(stderr, "%s\n", usage.c_str());
      code = 2;
      return;
    }
    code = run_console(*args);
  });
}

}  // namespace safecass::tools
