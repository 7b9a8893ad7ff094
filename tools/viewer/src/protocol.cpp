#include "safecass/viewer/protocol.hpp"

#include "safecass/middleware/token.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <utility>

#include <fmt/format.h>

#include "safecass/introspect/format.hpp"
#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"

namespace safecass::viewer {

namespace {

constexpr std::size_t kMaxString = 256;         ///< longest name, address or reason accepted
constexpr std::size_t kMaxSamples = 1000;       ///< samples in one injection
constexpr std::size_t kMaxSampleSize = 64;      ///< doubles in one sample
constexpr long long kTimeIntervalMs = 250;      ///< clock-only messages at most this often
constexpr long long kCoverageIntervalMs = 250;  ///< the hazards' coverage judged at most this often, but on records

std::string quote(std::string_view s) { return json::json_string(s); }

std::string number(double v) { return json::json_number(v); }

/// Seconds with six decimals (the history-file format of times).
std::string seconds(double v) { return json::json_seconds(seconds_to_time(v)); }

std::string state_text(State s) { return quote(to_string(s)); }

/// The one JSON writer's object (json/write.hpp).
using Object = json::JsonObject;

template <class Range, class F>
std::string array(const Range& items, F&& each) {
  json::JsonArray out;
  for (const auto& item : items) out.raw(each(item));
  return out.text();
}

using StateMap = std::map<std::string, std::pair<State, std::string>>;

StateMap states_of(const SystemView& v) {
  StateMap m;
  m["SYSTEM"] = {v.state, {}};
  for (const CoordinatorView& co : v.coordinators) {
    m["coordinator:" + co.name] = {co.state, co.status};  // a live coordinator's status as its "event"
    for (const ComponentView& c : co.components) {
      m[c.name] = {c.state, c.outstanding};
      for (const MachineView& mv : c.machines) m[mv.address] = {mv.state, mv.outstanding};
    }
  }
  return m;
}

std::string replay_json(const ReplayView& r) {
  return Object()
      .raw("start", seconds(r.start))
      .raw("end", seconds(r.end))
      .raw("period", seconds(r.period))
      .boolean("playing", r.playing)
      .num("speed", r.speed)
      .str("busy", r.busy)
      .text();
}

/// How the page shows times: scenario seconds, or (a live system) wall-clock time, the host
/// clock's time + the offset, in milliseconds since the Unix epoch.
std::string clock_json(const SystemView& v) {
  if (!v.host_clock) return Object().str("base", "simulated").text();
  return Object()
      .str("base", "host")
      .raw("wall_offset_ms", fmt::format("{}.{:06d}", v.wall_offset_ns / 1000000, std::abs(v.wall_offset_ns % 1000000)))
      .text();
}

std::string view_to_json(const SystemView& v, const std::optional<ReplayView>& replay) {
  const std::string coordinators = array(v.coordinators, [](const CoordinatorView& co) {
    const std::string components = array(co.components, [](const ComponentView& c) {
      const std::string machines = array(c.machines, [](const MachineView& m) {
        return Object()
            .str("address", m.address)
            .str("kind", to_string(m.kind))
            .str("name", m.name)
            .raw("state", state_text(m.state))
            .str("outstanding", m.outstanding)
            .text();
      });
      return Object()
          .str("name", c.name)
          .str("address", c.name)
          .raw("state", state_text(c.state))
          .str("outstanding", c.outstanding)
          .raw("machines", machines)
          .text();
    });
    return Object()
        .str("name", co.name)
        .str("address", "coordinator:" + co.name)
        .raw("state", state_text(co.state))
        .str("status", co.status)
        .raw("components", components)
        .text();
  });
  Object o;
  o.str("system", v.system)
      .str("description", v.description)
      .raw("t", seconds(v.t))
      .boolean("running", v.running)
      .raw("state", state_text(v.state))
      .raw("coordinators", coordinators)
      .raw("connections", array(v.connections,
                                [](const ConnectionView& c) {
                                  return Object().str("required", c.required).str("provided", c.provided).text();
                                }))
      .raw("clock", clock_json(v));
  if (replay) o.raw("replay", replay_json(*replay));
  return o.text();
}

/// A request being checked: the parsed object, its echoed id and op, and the first error found.
struct Request {
  const json::JsonValue* object = nullptr;
  std::string id;  ///< the id as JSON, or empty
  std::string op;
};

std::string error_reply(const std::string& id, std::string_view op, std::string_view message) {
  Object o;
  o.str("type", "error");
  if (!id.empty()) o.raw("id", id);
  if (!op.empty()) o.str("op", op);
  return o.str("error", message).text();
}

Object reply(const Request& r) {
  Object o;
  o.str("type", "reply");
  if (!r.id.empty()) o.raw("id", r.id);
  o.str("op", r.op);
  return o;
}

/// Checks that every key of the request is one of `allowed` (and appears once).
std::string check_keys(const json::JsonValue& object, std::initializer_list<std::string_view> allowed) {
  std::set<std::string_view> seen;
  for (const json::JsonMember& m : object.object) {
    bool ok = false;
    for (const std::string_view a : allowed) ok = ok || m.key == a;
    if (!ok) {
      std::string list;
      for (const std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      return "unknown key '" + m.key + "' (this op takes " + list + ")";
    }
    if (!seen.insert(m.key).second) return "key '" + m.key + "' given twice";
  }
  return {};
}

/// A required (or optional, when `required` is false) non-empty string member.
std::string get_string(const json::JsonValue& object, std::string_view key, std::string& out, bool required = true) {
  const json::JsonValue* v = object.find(key);
  if (v == nullptr) return required ? "missing key '" + std::string(key) + "'" : std::string();
  if (!v->is_string())
    return "'" + std::string(key) + "' must be a string, not " + std::string(json::type_name(v->type));
  if (v->string.empty()) return "'" + std::string(key) + "' must not be empty";
  if (v->string.size() > kMaxString)
    return "'" + std::string(key) + "' is longer than " + std::to_string(kMaxString) + " characters";
  out = v->string;
  return {};
}

std::string get_samples(const json::JsonValue& object, std::vector<std::vector<double>>& out) {
  const json::JsonValue* v = object.find("samples");
  if (v == nullptr) return "missing key 'samples' (an array of samples, each a number or an array of numbers)";
  if (!v->is_array() || v->array.empty()) return "'samples' must be a non-empty array of samples";
  if (v->array.size() > kMaxSamples) return "'samples' holds more than " + std::to_string(kMaxSamples) + " samples";
  for (std::size_t i = 0; i < v->array.size(); ++i) {
    const json::JsonValue& s = v->array[i];
    const std::string where = "samples[" + std::to_string(i) + "]";
    std::vector<double> sample;
    if (s.is_number()) {
      sample.push_back(s.number);
    } else if (s.is_array() && !s.array.empty() && s.array.size() <= kMaxSampleSize) {
      for (const json::JsonValue& x : s.array) {
        if (!x.is_number()) return where + " must hold numbers only";
        sample.push_back(x.number);
      }
    } else {
      return where + " must be a number or an array of 1 to " + std::to_string(kMaxSampleSize) + " numbers";
    }
    for (const double x : sample) {
      if (!std::isfinite(x)) return where + " holds a number out of range";
    }
    out.push_back(std::move(sample));
  }
  return {};
}

}  // namespace

bool listed_record(std::string_view record_json) {
  const json::JsonParse p = json::parse_json(record_json, 8);
  if (!p.value || !p.value->is_object()) return false;
  const json::JsonValue* kind = p.value->find("kind");
  if (kind == nullptr || !kind->is_string()) return false;
  if (kind->string == "event") {
    const json::JsonValue* outcome = p.value->find("outcome");
    return outcome != nullptr && outcome->is_string() && (outcome->string == "masked" || outcome->string == "ignored");
  }
  return true;  // transitions, component transitions, resets, injections, overflow
}

Protocol::Protocol(ViewSource& source, ProtocolOptions options) : source_(source), options_(std::move(options)) {
  sent_ = states_of(source_.view());
  generation_ = source_.generation();
}

std::string Protocol::view_json() const { return view_to_json(source_.view(), source_.replay()); }

std::string Protocol::hello() const {
  return Object()
      .str("type", "hello")
      .boolean("write", options_.allow_write)
      .integer("max_message", static_cast<long long>(options_.max_message))
      .raw("view", view_json())
      .raw("coverage", introspect::coverage_now_json(source_.coverage()))
      .raw("recent", array(recent_, [](const std::string& r) { return r; }))
      .text();
}

std::string Protocol::update(long long now_ms) {
  source_.poll();
  std::vector<std::string> records = source_.take_records();
  const std::optional<ReplayView> replay = source_.replay();
  if (source_.generation() != generation_) {
    // The picture started over (a replay went back in time): every page starts over with it.
    generation_ = source_.generation();
    recent_.clear();
    for (std::string& r : records) {
      if (!listed_record(r)) continue;
      recent_.push_back(std::move(r));
      if (recent_.size() > options_.recent) recent_.pop_front();
    }
    sent_ = states_of(source_.view());
    last_time_ms_ = now_ms;
    return hello();
  }
  json::JsonArray listed;
  for (std::string& r : records) {
    if (!listed_record(r)) continue;
    listed.raw(r);
    recent_.push_back(std::move(r));
    if (recent_.size() > options_.recent) recent_.pop_front();
  }
  json::JsonObject changed;
  std::size_t changes = 0;
  // A change of state comes with a record, or (a live system's state list, fetched after the
  // records that announced it) with a new view_version(): a state list that arrives in a later
  // poll than its records must still reach the page.
  if (!records.empty() || source_.view_version() != view_version_) {
    view_version_ = source_.view_version();
    StateMap now = states_of(source_.view());
    for (const auto& [address, state] : now) {
      const auto it = sent_.find(address);
      if (it != sent_.end() && it->second == state) continue;
      changed.raw(address, json::JsonArray().raw(state_text(state.first)).str(state.second).text());
      ++changes;
    }
    sent_ = std::move(now);
  }
  // The hazards' coverage, judged a few times a second (a filter's facts change without a record:
  // its first sample, a signal going stale) and pushed when it changed.
  std::string coverage;
  if (now_ms - coverage_ms_ >= kCoverageIntervalMs || !records.empty()) {
    coverage_ms_ = now_ms;
    introspect::CoverageNow c = source_.coverage();
    if (c.hazards != sent_coverage_) {
      coverage = introspect::coverage_now_json(c);
      sent_coverage_ = std::move(c.hazards);
    }
  }
  if (changes > 0 || !listed.empty() || !coverage.empty()) {
    last_time_ms_ = now_ms;
    last_replay_ = replay ? replay_json(*replay) : std::string();
    Object o;
    o.str("type", "update")
        .raw("t", seconds(source_.now()))
        .boolean("running", source_.running())
        .raw("states", changed.text())
        .raw("records", listed.text());
    if (!coverage.empty()) o.raw("coverage", coverage);
    if (replay) o.raw("replay", last_replay_);
    return o.text();
  }
  // A replay's controls changed (paused, arrived where it was sent): said at once.
  const std::string replay_now = replay ? replay_json(*replay) : std::string();
  if (now_ms - last_time_ms_ >= kTimeIntervalMs || replay_now != last_replay_) {
    last_time_ms_ = now_ms;
    last_replay_ = replay_now;
    Object o;
    o.str("type", "time").raw("t", seconds(source_.now())).boolean("running", source_.running());
    if (replay) o.raw("replay", replay_now);
    return o.text();
  }
  return {};
}

std::string Protocol::refuse_write(std::string_view id, std::string_view op, std::string_view token) const {
  if (!options_.allow_write) {
    return error_reply(std::string(id), op,
                       "refused: this viewer is read-only (start it with --allow-write to " + std::string(op) + ")");
  }
  if (token.empty()) {
    return error_reply(
        std::string(id), op,
        "refused: a write needs the token (key 'token'), in the token file named when the viewer started");
  }
  if (!middleware::token_matches(options_.token, token))
    return error_reply(std::string(id), op, "refused: wrong token");
  return {};
}

namespace {

/// A "replay" message's action ("play", "pause", "next"; "seek" with 't'; "speed" with 'speed')
/// into `control`. Returns the problem, or empty.
std::string replay_control(const json::JsonValue& object, ReplayControl& control) {
  std::string problem = check_keys(object, {"id", "op", "action", "t", "speed"});
  std::string action;
  if (problem.empty()) problem = get_string(object, "action", action);
  if (problem.empty()) {
    const json::JsonValue* t = object.find("t");
    const json::JsonValue* speed = object.find("speed");
    if (action == "play" || action == "pause" || action == "next") {
      control.op = action == "play"    ? ReplayControl::Op::Play
                   : action == "pause" ? ReplayControl::Op::Pause
                                       : ReplayControl::Op::Next;
      if (t != nullptr || speed != nullptr) problem = "action '" + action + "' takes neither 't' nor 'speed'";
    } else if (action == "seek") {
      control.op = ReplayControl::Op::Seek;
      if (speed != nullptr)
        problem = "action 'seek' takes 't' (seconds), not 'speed'";
      else if (t == nullptr || !t->is_number())
        problem = "action 'seek' needs 't', a number of seconds";
      else
        control.t = t->number;
    } else if (action == "speed") {
      control.op = ReplayControl::Op::Speed;
      if (t != nullptr)
        problem = "action 'speed' takes 'speed', not 't'";
      else if (speed == nullptr || !speed->is_number())
        problem = "action 'speed' needs 'speed', a number";
      else
        control.speed = speed->number;
    } else {
      problem = "unknown action '" + action + "' (play, pause, speed, seek, next)";
    }
  }
  return problem;
}

}  // namespace

std::string Protocol::handle(std::string_view message) {
  if (message.size() > options_.max_message) {
    return error_reply({}, {},
                       "message too long (" + std::to_string(message.size()) + " bytes; at most " +
                           std::to_string(options_.max_message) + ")");
  }
  const json::JsonParse parsed = json::parse_json(message, 8);
  if (!parsed.value) {
    const json::JsonError& e = *parsed.error;
    return error_reply(
        {}, {},
        "not JSON: " + std::to_string(e.position.line) + ":" + std::to_string(e.position.column) + ": " + e.message);
  }
  const json::JsonValue& object = *parsed.value;
  if (!object.is_object())
    return error_reply({}, {}, "a message must be a JSON object, not " + std::string(json::type_name(object.type)));
  Request r;
  r.object = &object;
  if (const json::JsonValue* id = object.find("id")) {
    if (id->is_number() && std::isfinite(id->number)) {
      r.id = number(id->number);
    } else if (id->is_string() && id->string.size() <= 64) {
      r.id = quote(id->string);
    } else {
      return error_reply({}, {}, "'id' must be a number or a string of at most 64 characters");
    }
  }
  const json::JsonValue* op = object.find("op");
  if (op == nullptr)
    return error_reply(r.id, {}, "missing key 'op' (view, explain, generate, broadcast, inject, reset, replay)");
  if (!op->is_string()) return error_reply(r.id, {}, "'op' must be a string");
  r.op = op->string;
  std::string problem;
  std::string token;
  auto token_of = [&]() -> std::string {
    const json::JsonValue* t = object.find("token");
    if (t == nullptr) return {};
    if (!t->is_string()) {
      problem = "'token' must be a string";
      return {};
    }
    return t->string;
  };

  if (r.op == "view") {
    if (problem = check_keys(object, {"id", "op"}); !problem.empty()) return error_reply(r.id, r.op, problem);
    return reply(r).raw("view", view_json()).text();
  }
  if (r.op == "explain") {
    std::string address;
    if (problem = check_keys(object, {"id", "op", "address"}); !problem.empty())
      return error_reply(r.id, r.op, problem);
    if (problem = get_string(object, "address", address); !problem.empty()) return error_reply(r.id, r.op, problem);
    auto conditions = source_.explain(address);
    if (!conditions) return error_reply(r.id, r.op, conditions.error().message);
    const StateMap states = states_of(source_.view());
    const auto it = states.find(address);
    Object o = reply(r);
    o.str("address", address);
    if (it != states.end()) o.raw("state", state_text(it->second.first)).str("outstanding", it->second.second);
    return o
        .raw("conditions",
             array(*conditions, [&](const Explanation& e) { return introspect::explanation_json(address, e); }))
        .text();
  }
  if (r.op == "generate" || r.op == "broadcast") {
    std::string event;
    std::string target;
    const bool broadcast = r.op == "broadcast";
    problem = broadcast ? check_keys(object, {"id", "op", "event", "token"})
                        : check_keys(object, {"id", "op", "event", "target", "token"});
    if (problem.empty()) problem = get_string(object, "event", event);
    if (problem.empty() && !broadcast) problem = get_string(object, "target", target);
    if (problem.empty()) token = token_of();
    if (!problem.empty()) return error_reply(r.id, r.op, problem);
    if (std::string refused = refuse_write(r.id, r.op, token); !refused.empty()) return refused;
    auto done = broadcast ? source_.apply(introspect::BroadcastEvent{event})
                          : source_.apply(introspect::GenerateEvent{event, target});
    if (!done) return error_reply(r.id, r.op, done.error().message);
    return reply(r).str("text", *done).text();
  }
  if (r.op == "inject") {
    bool deep = false;
    std::string target;
    std::vector<std::vector<double>> samples;
    problem = check_keys(object, {"id", "op", "filter", "signal", "samples", "token"});
    const bool has_filter = object.find("filter") != nullptr;
    const bool has_signal = object.find("signal") != nullptr;
    if (problem.empty() && has_filter == has_signal) {
      problem =
          "give either 'filter' (shallow injection into one filter) or 'signal' (deep injection into a signal's "
          "history)";
    }
    if (problem.empty()) {
      deep = has_signal;
      problem = get_string(object, has_signal ? "signal" : "filter", target);
    }
    if (problem.empty()) problem = get_samples(object, samples);
    if (problem.empty()) token = token_of();
    if (!problem.empty()) return error_reply(r.id, r.op, problem);
    if (std::string refused = refuse_write(r.id, r.op, token); !refused.empty()) return refused;
    auto done = deep ? source_.apply(introspect::InjectDeep{target, std::move(samples)})
                     : source_.apply(introspect::InjectShallow{target, std::move(samples)});
    if (!done) return error_reply(r.id, r.op, done.error().message);
    return reply(r).str("text", *done).text();
  }
  if (r.op == "reset") {
    std::string target;
    std::string reason = "reset from the viewer";
    problem = check_keys(object, {"id", "op", "target", "reason", "token"});
    if (problem.empty()) problem = get_string(object, "target", target);
    if (problem.empty()) problem = get_string(object, "reason", reason, false);
    if (problem.empty()) token = token_of();
    if (!problem.empty()) return error_reply(r.id, r.op, problem);
    if (std::string refused = refuse_write(r.id, r.op, token); !refused.empty()) return refused;
    auto done = source_.apply(introspect::ResetState{target, "viewer", reason});
    if (!done) return error_reply(r.id, r.op, done.error().message);
    return reply(r).str("text", *done).text();
  }
  if (r.op == "replay") {
    // Moving a replay in time changes what is shown, never the system or the log: no token.
    ReplayControl control;
    problem = replay_control(object, control);
    if (!problem.empty()) return error_reply(r.id, r.op, problem);
    auto done = source_.control(control);
    if (!done) return error_reply(r.id, r.op, done.error().message);
    return reply(r).str("text", *done).text();
  }
  return error_reply(r.id, r.op,
                     "unknown op '" + r.op + "' (view, explain, generate, broadcast, inject, reset, replay)");
}

}  // namespace safecass::viewer
