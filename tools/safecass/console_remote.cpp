// `safecass console --ice` / `safecass timeline --ice`: a live coordinator through RemoteClient.

#include "console_remote.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <thread>

#include "console_shell.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/spec/scenario.hpp"
#include "timeline.hpp"

namespace safecass::tools {

using namespace console;
using middleware::HistoryRow;
using middleware::RemoteClient;
using middleware::StateRow;

namespace {

constexpr auto kWatchPoll = std::chrono::milliseconds(100);

std::string state_text(State s) { return std::string(to_string(s)); }

/// The in-process console's names for the kinds of rows of `state list`.
std::string kind_text(const std::string& wire_kind) {
  if (wire_kind == "s_F") return "framework";
  if (wire_kind == "s_A") return "application";
  if (wire_kind == "s_P") return "provided";
  if (wire_kind == "s_R") return "required";
  if (wire_kind == "s_S") return "service";
  return wire_kind;
}

bool is_machine_row(const StateRow& r) { return r.kind == "s_F" || r.kind == "s_A" || r.kind == "s_P" || r.kind == "s_R"; }

std::string component_of(const std::string& address) { return address.substr(0, address.find('.')); }

/// The worst state of the components of `rows`: the SYSTEM row of this coordinator.
State system_state(const std::vector<StateRow>& rows) {
  State worst = State::Normal;
  for (const StateRow& r : rows) {
    if (r.kind == "component" && static_cast<int>(r.state) > static_cast<int>(worst)) worst = r.state;
  }
  return worst;
}

/// One history record as `state history` prints it in-process (record_to_text's shape; the
/// coordinator does not send the root's sample).
std::string history_text(const HistoryRow& r) {
  std::string out = "t=" + seconds_text(r.time) + "  " + (r.address.empty() ? std::string("-") : r.address);
  if (r.kind == "transition" || r.kind == "component-transition") {
    out += "  " + state_text(r.from) + " -> " + state_text(r.to);
    if (!r.event.empty()) out += "  " + r.event;
  } else if (r.kind == "event") {
    out += "  " + r.outcome + " " + r.event;
  } else {
    out += "  " + r.kind;
  }
  if (!r.root_event.empty() && !r.root_origin.empty() && !(r.root_origin == r.address && r.root_event == r.event)) {
    out += "  <- " + r.root_origin + ":" + r.root_event;
  }
  if (!r.text.empty()) out += "  (" + r.text + ")";
  return out;
}

/// One history record as a history-file line (record_to_json's fields, without severity and the
/// root's time and sample, which the coordinator does not send).
std::string history_json(const HistoryRow& r) {
  Json j;
  j.integer("seq", static_cast<long long>(r.seq)).num("t", to_seconds(r.time)).str("kind", r.kind);
  if (!r.outcome.empty()) j.str("outcome", r.outcome);
  if (!r.address.empty()) {
    j.str("component", component_of(r.address));
    if (r.address.find('.') != std::string::npos && r.kind != "component-transition") j.str("machine", r.address);
  }
  if (!r.event.empty()) j.str("event", r.event);
  if (r.kind != "injection") j.str("from", to_string(r.from)).str("to", to_string(r.to));
  if (r.kind == "event") j.str("level", to_string(r.level));
  if (r.mirror) j.boolean("mirror", true);
  if (!r.root_event.empty() && !r.root_origin.empty()) {
    j.raw("root", Json().str("event", r.root_event).str("origin", r.root_origin).text());
  }
  if (!r.text.empty()) j.str("text", r.text);
  return j.text();
}

/// Every record in `scope` (SYSTEM, a component, a service — its component — or a machine), merged
/// from the coordinator's component and machine histories in stream order. `rows`: its state list.
Expected<std::vector<HistoryRow>> merged_history(RemoteClient& client, const std::string& scope,
                                                 const std::vector<StateRow>& rows) {
  std::vector<std::string> addresses;  // each asked for its whole history
  std::string component;               // a component: its component-transitions and resets
  bool known = scope == "SYSTEM";
  for (const StateRow& r : rows) {
    if (r.address == scope) {
      known = true;
      if (r.kind == "component") component = r.address;
      else if (r.kind == "s_S") component = component_of(r.address);
      else addresses.push_back(r.address);
    }
  }
  if (!known) {  // not one of this coordinator's own names: let the coordinator say what is wrong
    return client.state_history(scope, 0);
  }
  std::vector<HistoryRow> all;
  auto add = [&](const std::string& address) -> Expected<void> {
    auto h = client.state_history(address, 0);
    if (!h) return tl::unexpected(h.error());
    all.insert(all.end(), h->begin(), h->end());
    return {};
  };
  if (scope == "SYSTEM" || !component.empty()) {
    if (auto r = add(scope == "SYSTEM" ? std::string() : component); !r) return tl::unexpected(r.error());
    for (const StateRow& r : rows) {
      if (is_machine_row(r) && (scope == "SYSTEM" || component_of(r.address) == component)) addresses.push_back(r.address);
    }
  }
  for (const std::string& a : addresses) {
    if (auto r = add(a); !r) return tl::unexpected(r.error());
  }
  std::sort(all.begin(), all.end(), [](const HistoryRow& a, const HistoryRow& b) { return a.seq < b.seq; });
  all.erase(std::unique(all.begin(), all.end(), [](const HistoryRow& a, const HistoryRow& b) { return a.seq == b.seq; }),
            all.end());
  return all;
}

// ---- the remote backend --------------------------------------------------------------------------

class RemoteBackend final : public Backend {
public:
  RemoteBackend(std::unique_ptr<RemoteClient> client, ConsoleOptions options, std::string coordinator, std::string ice,
                std::string token_file)
      : client_(std::move(client)), options_(options), coordinator_(std::move(coordinator)), ice_(std::move(ice)),
        token_file_(std::move(token_file)) {
    load_names();
  }

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
      case Id::Time:
        return "in-process only: coordinator '" + coordinator_ + "' runs in real time (use watch SECONDS to follow it)";
      case Id::Help:
      case Id::Quit: break;  // the Console answers these itself
    }
    return "not available against a live coordinator";
  }

  std::vector<std::string> names(Arg kind) const override {
    switch (kind) {
      case Arg::Component: return components_;
      case Arg::Machine: return machines_;
      case Arg::Address: return addresses_;
      case Arg::Event: return events_;
      case Arg::Filter:
      case Arg::FilterOrType: return filters_;
      case Arg::Signal: return signals_;
      case Arg::Command:
      case Arg::None:
      case Arg::File: break;
    }
    return {};
  }

  std::string banner() const override {
    std::string access = "read-only";
    if (options_.allow_write) {
      access = token_file_.empty() ? "writes allowed, but no --token-file: the coordinator will refuse them"
                                   : "writes allowed (token from " + token_file_ + ")";
    }
    return "safecass console: coordinator " + coordinator_ + " on IceStorm " + ice_ + " (" +
           std::to_string(components_.size()) + " components), live, " + access + ". Type help, or TAB to complete.";
  }

private:
  /// The names TAB completes, fetched once: a coordinator's structure does not change while it runs.
  void load_names() {
    addresses_.emplace_back("SYSTEM");
    if (auto rows = client_->state_list(); rows) {
      for (const StateRow& r : *rows) {
        addresses_.push_back(r.address);
        if (r.kind == "component") components_.push_back(r.address);
        if (is_machine_row(r)) machines_.push_back(r.address);
      }
    }
    if (auto events = client_->event_list(); events) {
      for (const auto& e : *events) events_.push_back(e.name);
    }
    if (auto filters = client_->filter_list(); filters) {
      std::set<std::string> signals;
      for (const auto& f : *filters) {
        filters_.push_back(f.name);
        signals.insert(f.inputs.begin(), f.inputs.end());
        signals.insert(f.outputs.begin(), f.outputs.end());
      }
      signals_.assign(signals.begin(), signals.end());
    }
  }

  std::string state_list(const std::vector<std::string>& args, Out& out) {
    auto rows = client_->state_list(args.empty() ? std::string() : args[0]);
    if (!rows) return rows.error().message;
    std::vector<std::vector<std::string>> table;
    auto row = [&](const std::string& indent, const std::string& address, const std::string& kind, State state,
                   const std::string& outstanding) {
      if (options_.json) {
        out.line(Json().str("address", address).str("kind", kind).str("state", to_string(state)).opt("outstanding", outstanding).text());
      } else {
        table.push_back({indent + address, state_text(state), outstanding.empty() ? "-" : outstanding});
      }
    };
    if (args.empty()) row("", "SYSTEM", "system", system_state(*rows), "");
    for (const StateRow& r : *rows) row(r.kind == "component" ? "" : "  ", r.address, kind_text(r.kind), r.state, r.outstanding);
    if (!options_.json) out.reply.out += columns(table);
    return {};
  }

  void print_history(const std::vector<HistoryRow>& records, long last, Out& out, std::string_view empty) const {
    const std::size_t n = std::min(records.size(), static_cast<std::size_t>(last));
    for (std::size_t i = records.size() - n; i < records.size(); ++i) {
      out.line(options_.json ? history_json(records[i]) : history_text(records[i]));
    }
    if (n == 0 && !options_.json) out.line(std::string(empty));
  }

  std::string state_history(const std::vector<std::string>& args, Out& out) {
    std::string scope = "SYSTEM";
    long last = kDefaultHistory;
    std::size_t next = 0;
    if (!args.empty() && !parse_count(args[0])) {
      scope = args[0];
      next = 1;
    }
    if (next < args.size()) {
      const auto n = parse_count(args[next]);
      if (!n) return "N must be a positive whole number, not '" + args[next] + "'";
      last = *n;
      ++next;
    }
    if (next < args.size()) return "too many arguments";
    auto rows = client_->state_list();
    if (!rows) return rows.error().message;
    auto records = merged_history(*client_, scope, *rows);
    if (!records) return records.error().message;
    print_history(*records, last, out, "no records");
    return {};
  }

  std::string filter_list(Out& out) {
    auto filters = client_->filter_list();
    if (!filters) return filters.error().message;
    std::vector<std::vector<std::string>> rows;
    for (const auto& f : *filters) {
      if (options_.json) {
        out.line(Json().str("filter", f.name).str("type", f.type).str("target", f.target).str("execution", f.execution)
                     .str("detection", f.detection).boolean("enabled", f.enabled).boolean("detected", f.detected)
                     .raw("inputs", json_list(f.inputs)).raw("outputs", json_list(f.outputs)).text());
        continue;
      }
      std::string signals;
      for (const std::string& s : f.inputs) signals += (signals.empty() ? "" : ",") + s;
      if (!f.outputs.empty()) {
        signals += " ->";
        for (std::size_t i = 0; i < f.outputs.size(); ++i) signals += (i ? "," : " ") + f.outputs[i];
      }
      rows.push_back({f.name, f.type, f.target, f.execution, f.detection, f.enabled ? "enabled" : "disabled",
                      f.detected ? "DETECTED" : "-", signals});
    }
    if (!options_.json) {
      if (rows.empty()) out.line("no filters");
      out.reply.out += columns(rows);
    }
    return {};
  }

  static std::string joined(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
    return out.empty() ? "-" : out;
  }

  std::string filter_info(const std::string& name, Out& out) {
    auto details = client_->filter_info(name);
    if (!details) return details.error().message;
    const middleware::FilterDetails& d = *details;
    const middleware::FilterRow& f = d.filter;
    const bool instance = !f.name.empty();
    if (options_.json) {
      Json head;
      head.opt("filter", f.name).str("type", f.type).str("doc", d.doc);
      if (instance) {
        head.str("target", f.target == "-" ? "" : f.target).str("execution", f.execution).str("detection", f.detection)
            .boolean("enabled", f.enabled).boolean("detected", f.detected)
            .integer("missed_samples", static_cast<long long>(d.missed_samples))
            .raw("input_signals", json_list(f.inputs)).raw("output_signals", json_list(f.outputs));
      }
      out.line(head.text());
      for (const auto& p : d.params) {
        Json j;
        j.str("param", p.name).str("type", p.type).opt("default", p.default_value);
        if (instance) j.opt("value", p.value);
        out.line(j.str("doc", p.doc).text());
      }
      return {};
    }
    if (instance) {
      out.line("filter " + f.name + ": " + f.type + " - " + d.doc);
      out.line("  target " + f.target + ", " + f.execution + ", " + f.detection);
      out.line(std::string("  ") + (f.enabled ? "enabled" : "disabled") + ", " +
               (f.detected ? "detected (onset sent, no completion yet)" : "not detected") + ", " +
               std::to_string(d.missed_samples) + " missed samples");
      out.line("  inputs:  " + joined(f.inputs));
      out.line("  outputs: " + joined(f.outputs));
    } else {
      out.line("filter type " + f.type + ": " + d.doc);
    }
    out.line("  parameters:");
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"    name", "type", instance ? "value" : "", "default", "doc"});
    for (const auto& p : d.params) {
      rows.push_back({"    " + p.name, p.type, p.value.empty() ? "-" : p.value,
                      p.default_value.empty() ? "-" : p.default_value, p.doc});
    }
    if (!instance) {
      for (auto& r : rows) r.erase(r.begin() + 2);
    }
    out.reply.out += columns(rows);
    return {};
  }

  void done(Out& out, const CommandSpec& c, Json json, const std::string& text) const {
    write_done(out, options_.json, c, std::move(json), text, std::nullopt);
  }

  std::string filter_inject(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    auto samples = parse_samples({args.begin() + 1, args.end()});
    if (!samples) return samples.error().message;
    if (auto r = client_->filter_inject(args[0], *samples); !r) return r.error().message;
    done(out, c, Json().str("filter", args[0]).integer("samples", static_cast<long long>(samples->size())),
         "queued " + count_text(samples->size()) + " into filter " + args[0] + " of coordinator " + coordinator_ +
             " (seen by that filter alone on its next runs)");
    return {};
  }

  std::string deep_done(const CommandSpec& c, const std::string& signal, std::size_t n, Out& out) const {
    done(out, c, Json().str("signal", signal).integer("samples", static_cast<long long>(n)),
         "wrote " + count_text(n) + " into signal " + signal + " of coordinator " + coordinator_ +
             " (seen by every consumer on its next run)");
    return {};
  }

  std::string filter_dinject(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    auto samples = parse_samples({args.begin() + 1, args.end()});
    if (!samples) return samples.error().message;
    if (auto r = client_->filter_dinject(args[0], *samples); !r) return r.error().message;
    return deep_done(c, args[0], samples->size(), out);
  }

  std::string filter_dinload(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    std::string text;
    std::string error;
    if (!spec::read_file(args[1], text, error)) return error;
    auto samples = parse_sample_file(args[1], text);  // checked here, so that errors name the file's lines
    if (!samples) return samples.error().message;
    if (auto r = client_->filter_dinload(args[0], text); !r) return r.error().message;
    return deep_done(c, args[0], samples->size(), out);
  }

  std::string event_list(Out& out) {
    auto events = client_->event_list();
    if (!events) return events.error().message;
    std::vector<std::vector<std::string>> rows;
    for (std::size_t i = 0; i < events->size(); ++i) {
      const middleware::EventRow& e = (*events)[i];
      const std::string kind = e.severity >= kMinBroadcastSeverity ? "broadcast" : e.onset ? "onset" : "completion";
      std::string counterpart = e.completes;
      if (e.onset) {
        for (const auto& other : *events) {
          if (!other.onset && other.completes == e.name) counterpart = other.name;
        }
      }
      std::string transitions;
      for (const std::string& t : e.transitions) transitions += (transitions.empty() ? "" : ",") + t;
      const bool framework = i < framework_event::kCount;
      if (options_.json) {
        out.line(Json().str("event", e.name).integer("severity", e.severity).str("kind", kind).str("transitions", transitions)
                     .opt(e.onset ? "completion" : "completes", counterpart).boolean("latched", e.latched)
                     .boolean("framework", framework).opt("hazard", e.hazard).opt("description", e.description).text());
        continue;
      }
      std::string extra;
      if (!counterpart.empty()) extra += (e.onset ? "cleared by " : "clears ") + counterpart;
      if (e.latched) extra += (extra.empty() ? "" : ", ") + std::string("latched");
      if (framework) extra += (extra.empty() ? "" : ", ") + std::string("framework");
      if (!e.hazard.empty()) extra += (extra.empty() ? "" : ", ") + std::string("hazard ") + e.hazard;
      if (!e.description.empty()) extra += (extra.empty() ? "" : " - ") + e.description;
      rows.push_back({e.name, std::to_string(e.severity), kind, transitions, extra});
    }
    if (!options_.json) out.reply.out += columns(rows);
    return {};
  }

  std::string event_history(const std::vector<std::string>& args, Out& out) {
    long last = kDefaultHistory;
    if (!args.empty()) {
      const auto n = parse_count(args[0]);
      if (!n) return "N must be a positive whole number, not '" + args[0] + "'";
      last = *n;
    }
    auto all = client_->event_history(0);
    if (!all) return all.error().message;
    std::vector<HistoryRow> events;
    for (HistoryRow& r : *all) {
      if (r.kind == "event") events.push_back(std::move(r));
    }
    print_history(events, last, out, "no events yet");
    return {};
  }

  std::string event_generate(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    if (auto r = client_->generate(args[0], args[1]); !r) return r.error().message;
    done(out, c, Json().str("event", args[0]).str("target", args[1]), "generated " + args[0] + " on " + args[1]);
    return {};
  }

  std::string event_broadcast(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    if (auto r = client_->broadcast(args[0]); !r) return r.error().message;
    done(out, c, Json().str("event", args[0]), "broadcast " + args[0]);
    return {};
  }

  static std::string propagates_text(const std::string& level) {
    return level == "Warning" ? "Warning and Error" : "Error";
  }

  std::string connection_list(Out& out) {
    auto connections = client_->connection_list();
    if (!connections) return connections.error().message;
    auto rows = client_->state_list();
    if (!rows) return rows.error().message;
    auto services = client_->service_list();
    if (!services) return services.error().message;
    std::map<std::string, State> states;
    for (const StateRow& r : *rows) states[r.address] = r.state;
    std::map<std::string, std::string> propagate;
    for (const auto& s : *services) propagate[s.address] = s.propagate;
    auto machine = [](const std::string& end, const char* kind) {
      const auto dot = end.find('.');
      return dot == std::string::npos ? end : end.substr(0, dot) + "." + kind + "." + end.substr(dot + 1);
    };
    std::vector<std::vector<std::string>> table;
    for (const auto& k : *connections) {
      const auto required = states.find(machine(k.required, "s_R"));
      const auto service = states.find(machine(k.provided, "s_S"));
      const auto level = propagate.find(machine(k.provided, "s_S"));
      const std::string required_state = required == states.end() ? std::string() : state_text(required->second);
      const std::string service_state = service == states.end() ? std::string() : state_text(service->second);
      const std::string propagates = level == propagate.end() ? std::string() : level->second;
      if (options_.json) {
        out.line(Json().str("required", k.required).str("provided", k.provided).opt("required_state", required_state)
                     .opt("service_state", service_state).opt("propagates", propagates).boolean("remote", k.remote).text());
        continue;
      }
      table.push_back({k.required, "->", k.provided, "s_R " + (required_state.empty() ? "?" : required_state),
                       service_state.empty() ? "s_S ? (in another process)" : "s_S " + service_state,
                       propagates.empty() ? (k.remote ? "remote provider" : "-") : "propagates " + propagates_text(propagates)});
    }
    if (!options_.json) {
      if (table.empty()) out.line("no connections");
      out.reply.out += columns(table);
    }
    return {};
  }

  std::string service_list(Out& out) {
    auto services = client_->service_list();
    if (!services) return services.error().message;
    std::vector<std::vector<std::string>> rows;
    for (const auto& s : *services) {
      std::vector<std::string> terms;
      const std::string prefix = component_of(s.address) + ".";
      for (const std::string& d : s.depends_on) terms.push_back(d.rfind(prefix, 0) == 0 ? d.substr(prefix.size()) : d);
      if (options_.json) {
        out.line(Json().str("service", s.address).str("state", to_string(s.state)).raw("depends_on", json_list(terms))
                     .str("propagates", s.propagate).text());
        continue;
      }
      std::string formula;
      for (const std::string& t : terms) formula += (formula.empty() ? "" : " * ") + t;
      rows.push_back({s.address, state_text(s.state), "= " + formula, "(propagates " + propagates_text(s.propagate) + ")"});
    }
    if (!options_.json) {
      if (rows.empty()) out.line("no provided interfaces");
      out.reply.out += columns(rows);
    }
    return {};
  }

  std::string explain(const std::string& address, Out& out) {
    auto all = client_->explain(address);
    if (!all) return all.error().message;
    std::string state;
    if (all->empty() && !options_.json) {
      if (auto rows = client_->state_list(); rows) {
        if (address == "SYSTEM") state = state_text(system_state(*rows));
        for (const StateRow& r : *rows) {
          if (r.address == address) state = state_text(r.state);
        }
      }
    }
    print_explanations(*all, address, state, options_.json, false, out);
    return {};
  }

  std::string reset(const CommandSpec& c, const std::vector<std::string>& args, Out& out) {
    std::string reason;
    for (std::size_t i = 1; i < args.size(); ++i) reason += (reason.empty() ? "" : " ") + args[i];
    if (reason.empty()) reason = "reset from the console";
    if (auto r = client_->reset(args[0], "console", reason); !r) return r.error().message;
    done(out, c, Json().str("target", args[0]).str("reason", reason), "reset " + args[0] + " (" + reason + ")");
    return {};
  }

  /// Polls the coordinator's states every 100 ms for SECONDS and prints each change.
  std::string watch(const std::vector<std::string>& args, Out& out) {
    double seconds = 1.0;
    if (!args.empty()) {
      const auto v = parse_number(args[0]);
      if (!v || !std::isfinite(*v) || *v <= 0 || *v > kMaxWatchSeconds) {
        return "SECONDS must be a number of seconds above 0 and at most " + number_text(kMaxWatchSeconds) + ", not '" + args[0] + "'";
      }
      seconds = *v;
    }
    auto before = client_->state_list();
    if (!before) return before.error().message;
    std::map<std::string, StateRow> last;
    for (StateRow& r : *before) last[r.address] = std::move(r);
    const auto start = std::chrono::steady_clock::now();
    const auto until = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
    std::size_t changes = 0;
    while (std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(kWatchPoll, until - std::chrono::steady_clock::now()));
      auto now = client_->state_list();
      if (!now) return now.error().message;
      const double after = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      for (StateRow& r : *now) {
        auto it = last.find(r.address);
        const State from = it == last.end() ? State::Normal : it->second.state;
        const std::string was = it == last.end() ? std::string() : it->second.outstanding;
        if (it != last.end() && from == r.state && was == r.outstanding) continue;
        ++changes;
        if (options_.json) {
          out.line(Json().str("kind", "change").num("after", after).str("address", r.address).str("from", to_string(from))
                       .str("to", to_string(r.state)).opt("outstanding", r.outstanding).text());
        } else {
          char when[32];
          std::snprintf(when, sizeof when, "+%.1fs", after);
          out.line(std::string(when) + "  " + r.address + "  " + state_text(from) + " -> " + state_text(r.state) +
                   (r.outstanding.empty() ? std::string() : "  " + r.outstanding));
        }
        last[r.address] = std::move(r);
      }
    }
    if (options_.json) {
      out.line(Json().str("command", "watch").num("seconds", seconds).integer("changes", static_cast<long long>(changes)).text());
    } else {
      out.line("watched coordinator " + coordinator_ + " for " + number_text(seconds) + " s: " + std::to_string(changes) +
               (changes == 1 ? " change" : " changes"));
    }
    return {};
  }

  std::unique_ptr<RemoteClient> client_;
  ConsoleOptions options_;
  std::string coordinator_;
  std::string ice_;
  std::string token_file_;
  std::vector<std::string> components_, machines_, addresses_, events_, filters_, signals_;
};

Expected<std::unique_ptr<RemoteClient>> connect_client(const std::string& ice, const std::string& coordinator,
                                                       const std::string& token, int timeout_ms,
                                                       const std::string& keys, bool insecure,
                                                       const std::string& tls = {}, const std::string& read_token = {}) {
  auto endpoint = middleware::parse_ice_endpoint(ice);
  if (!endpoint) return fail(ErrorCode::Parse, endpoint.error().message);  // names --ice and its text
  middleware::ClientOptions o;
  o.ice = *endpoint;
  o.coordinator = coordinator;
  o.token = token;
  o.keys_dir = keys;
  o.insecure = insecure;
  o.tls.dir = tls;
  o.read_token = read_token;
  o.timeout = std::chrono::milliseconds(timeout_ms);
  auto client = RemoteClient::connect(o);
  if (!client) return tl::unexpected(client.error());
  return client;
}

}  // namespace

Expected<std::unique_ptr<Console>> connect_console(const ConsoleArgs& args) {
  std::string token;
  if (!args.token_file.empty()) {
    auto t = middleware::read_token_file(args.token_file);
    if (!t) return fail(t.error().code, "console: --token-file: " + t.error().message);
    token = *t;
  }
  std::string read_token;
  if (!args.read_token_file.empty()) {
    auto t = middleware::read_token_file(args.read_token_file);
    if (!t) return fail(t.error().code, "console: --read-token-file: " + t.error().message);
    read_token = *t;
  }
  auto client = connect_client(args.ice, args.coordinator, token, args.timeout_ms, args.keys, args.insecure, args.tls,
                               read_token);
  if (!client) return fail(client.error().code, "console: " + client.error().message);
  const ConsoleOptions options{args.json, args.allow_write};
  auto backend = std::make_unique<RemoteBackend>(std::move(*client), options, args.coordinator, args.ice, args.token_file);
  return std::make_unique<Console>(std::move(backend), options);
}

int run_timeline_ice(const std::string& ice, const std::string& coordinator, const std::string& html_out, int timeout_ms,
                     const std::string& keys, const std::string& tls, const std::string& read_token_file) {
  std::string read_token;
  if (!read_token_file.empty()) {
    auto t = middleware::read_token_file(read_token_file);
    if (!t) {
      std::fprintf(stderr, "safecass timeline: --read-token-file: %s\n", t.error().message.c_str());
      return 2;
    }
    read_token = *t;
  }
  auto client = connect_client(ice, coordinator, {}, timeout_ms, keys, false, tls, read_token);
  if (!client) {
    std::fprintf(stderr, "safecass timeline: %s\n", client.error().message.c_str());
    return 2;
  }
  auto rows = (*client)->state_list();
  Expected<std::vector<HistoryRow>> records = rows ? merged_history(**client, "SYSTEM", *rows)
                                                   : Expected<std::vector<HistoryRow>>(tl::unexpected(rows.error()));
  if (!records) {
    std::fprintf(stderr, "safecass timeline: %s\n", records.error().message.c_str());
    return 2;
  }
  std::string text;
  for (const HistoryRow& r : *records) text += history_json(r) + "\n";
  const HistoryParse parsed = parse_history(text);
  if (!parsed.errors.empty()) {  // a record the page cannot draw: say which, write nothing
    for (const HistoryError& e : parsed.errors) {
      std::fprintf(stderr, "safecass timeline: coordinator '%s', record %d: %s\n", coordinator.c_str(), e.line, e.message.c_str());
    }
    return 2;
  }
  const int written = write_timeline_page(parsed.records, "coordinator " + coordinator + " (live, IceStorm " + ice + ")", html_out);
  if (written != 0) return written;
  std::fprintf(stderr, "safecass timeline: %zu records of coordinator '%s' drawn in %s\n", parsed.records.size(),
               coordinator.c_str(), html_out.c_str());
  return 0;
}

}  // namespace safecass::tools
