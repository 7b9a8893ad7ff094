#include "safecass/ros_common/mapping.hpp"

#include <set>

#include "safecass/json/read.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::ros_common {

bool IngestRule::matches(std::string_view status_name) const noexcept {
  if (!name.empty() && name.back() == '*') {
    const std::string_view prefix(name.data(), name.size() - 1);
    return status_name.substr(0, prefix.size()) == prefix;
  }
  return status_name == name;
}

const std::string* Mapping::node_of(std::string_view component) const noexcept {
  for (const auto& n : nodes) {
    if (n.first == component) return &n.second;
  }
  return nullptr;
}

std::vector<EventDef> default_ros_events() {
  auto def = [](std::string name, int severity, TransitionSet t, std::string description) {
    EventDef e;
    e.name = std::move(name);
    e.severity = severity;
    e.transitions = t;
    e.description = std::move(description);
    return e;
  };
  using T = Transition;
  return {def("EVT_ROS_DIAG_WARN", 206, {T::N2W}, "a ROS diagnostic status reports WARN"),
          def("/EVT_ROS_DIAG_WARN", 206, {T::W2N}, ""),
          def("EVT_ROS_DIAG_ERROR", 207, {T::N2E, T::W2E}, "a ROS diagnostic status reports ERROR"),
          def("/EVT_ROS_DIAG_ERROR", 207, {T::E2N, T::E2W}, ""),
          def("EVT_ROS_GRAPH_MISSING", 235, {T::N2E, T::W2E},
              "a node, publisher or subscriber declared in the ROS mapping is missing from the live graph"),
          def("/EVT_ROS_GRAPH_MISSING", 235, {T::E2N, T::E2W}, ""),
          def("EVT_ROS_TOPIC_RATE", 204, {T::N2W}, "a topic's message rate is outside its bounds"),
          def("/EVT_ROS_TOPIC_RATE", 204, {T::W2N}, "")};
}

namespace {

using json::JsonValue;
using spec::Diagnostic;

class Reader {
public:
  Reader(std::string file, std::vector<Diagnostic>& out) : file_(std::move(file)), out_(out) {}

  spec::Position at(const JsonValue& v) const { return spec::Position{file_, v.position.line, v.position.column}; }
  void error(const JsonValue& v, const std::string& pointer, const std::string& message) {
    out_.push_back(Diagnostic{Diagnostic::Severity::Error, at(v), message, pointer});
  }
  bool expect(const JsonValue& v, JsonValue::Type type, const std::string& pointer, const char* what) {
    if (v.type == type) return true;
    error(v, pointer,
          std::string(what) + " must be a " + std::string(json::type_name(type)) + ", not a " +
              std::string(json::type_name(v.type)));
    return false;
  }
  /// Reports every key of `object` that is not in `known`.
  void known_keys(const JsonValue& object, const std::string& pointer, std::initializer_list<const char*> known) {
    for (const json::JsonMember& m : object.object) {
      bool ok = false;
      for (const char* k : known) ok = ok || m.key == k;
      if (!ok) {
        std::string list;
        for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        out_.push_back(Diagnostic{Diagnostic::Severity::Error,
                                  spec::Position{file_, m.key_position.line, m.key_position.column},
                                  "unknown key '" + m.key + "' (known: " + list + ")", pointer + "/" + m.key});
      }
    }
  }
  bool string(const JsonValue& object, const char* key, const std::string& pointer, std::string& out, bool required) {
    const JsonValue* v = object.find(key);
    if (v == nullptr) {
      if (required) error(object, pointer, std::string("missing '") + key + "'");
      return false;
    }
    if (!expect(*v, JsonValue::Type::String, pointer + "/" + key, key)) return false;
    if (v->string.empty()) {
      error(*v, pointer + "/" + key, std::string("'") + key + "' must not be empty");
      return false;
    }
    out = v->string;
    return true;
  }
  bool number(const JsonValue& object, const char* key, const std::string& pointer, double& out, double min,
              double max) {
    const JsonValue* v = object.find(key);
    if (v == nullptr) return false;
    if (!expect(*v, JsonValue::Type::Number, pointer + "/" + key, key)) return false;
    if (!(v->number >= min && v->number <= max)) {
      error(*v, pointer + "/" + key,
            std::string("'") + key + "' = " + std::to_string(v->number) + " is outside [" + std::to_string(min) + ", " +
                std::to_string(max) + "]");
      return false;
    }
    out = v->number;
    return true;
  }
  /// "C.x" with both parts non-empty (machines may have more dots: "C.s_P.p").
  bool dotted(const JsonValue& v, const std::string& pointer, const std::string& text, const char* what) {
    const std::size_t dot = text.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size()) {
      error(v, pointer, std::string(what) + " '" + text + "' must be written Component.name");
      return false;
    }
    return true;
  }

private:
  std::string file_;
  std::vector<Diagnostic>& out_;
};

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

void read_check(Reader& r, const JsonValue& v, const std::string& pointer, bool watchdog,
                std::optional<TopicCheck>& out) {
  if (!r.expect(v, JsonValue::Type::Object, pointer, watchdog ? "watchdog" : "frequency")) return;
  if (watchdog) {
    r.known_keys(v, pointer, {"timeout", "target", "event"});
  } else {
    r.known_keys(v, pointer, {"min_rate", "max_rate", "window", "target", "event"});
  }
  TopicCheck c;
  c.event = watchdog ? "EVT_STALE" : "EVT_ROS_TOPIC_RATE";
  r.string(v, "event", pointer, c.event, false);
  bool ok = r.string(v, "target", pointer, c.target, true);
  if (watchdog) {
    if (!r.number(v, "timeout", pointer, c.timeout, 1e-6, 1e6)) {
      if (v.find("timeout") == nullptr) r.error(v, pointer, "missing 'timeout'");
      ok = false;
    }
  } else {
    r.number(v, "min_rate", pointer, c.min_rate, 0, 1e9);
    r.number(v, "max_rate", pointer, c.max_rate, 0, 1e9);
    double window = c.window;
    if (r.number(v, "window", pointer, window, 1, 1e6)) c.window = static_cast<int>(window);
    if (c.min_rate == 0 && c.max_rate == 0) {
      r.error(v, pointer, "a frequency check needs 'min_rate' or 'max_rate'");
      ok = false;
    }
  }
  if (ok) out = c;
}

void read_topic(Reader& r, const JsonValue& v, const std::string& pointer, Mapping& m) {
  if (!r.expect(v, JsonValue::Type::Object, pointer, "a topic")) return;
  r.known_keys(
      v, pointer,
      {"topic", "type", "provided", "required", "signals", "rate_signal", "age_signal", "watchdog", "frequency"});
  TopicMapping t;
  t.where = r.at(v);
  bool ok = r.string(v, "topic", pointer, t.topic, true);
  if (ok && t.topic.front() != '/') {
    r.error(*v.find("topic"), pointer + "/topic", "topic '" + t.topic + "' must be a global name (start with '/')");
    ok = false;
  }
  std::string type;
  bool typed = false;
  if (r.string(v, "type", pointer, type, true)) {
    auto parsed = parse_message_type(type);
    if (parsed) {
      t.type = *parsed;
      typed = true;
    } else {
      r.error(*v.find("type"), pointer + "/type", parsed.error().message);
    }
  }
  ok = ok && typed;
  if (r.string(v, "provided", pointer, t.provided, false))
    ok = r.dotted(*v.find("provided"), pointer + "/provided", t.provided, "interface") && ok;
  if (const JsonValue* req = v.find("required")) {
    if (r.expect(*req, JsonValue::Type::Array, pointer + "/required", "'required'")) {
      for (std::size_t i = 0; i < req->array.size(); ++i) {
        const JsonValue& e = req->array[i];
        const std::string p = pointer + "/required/" + std::to_string(i);
        if (r.expect(e, JsonValue::Type::String, p, "an interface") && r.dotted(e, p, e.string, "interface")) {
          t.required.push_back(e.string);
        } else {
          ok = false;
        }
      }
    } else {
      ok = false;
    }
  }
  if (const JsonValue* sig = v.find("signals")) {
    if (r.expect(*sig, JsonValue::Type::Object, pointer + "/signals", "'signals'")) {
      for (const json::JsonMember& member : sig->object) {
        const std::string p = pointer + "/signals/" + member.key;
        FieldBinding b;
        b.signal = member.key;
        b.where = r.at(member.value);
        if (!r.dotted(member.value, p, member.key, "signal")) {
          ok = false;
          continue;
        }
        std::string path;
        if (member.value.is_string()) {
          path = member.value.string;
        } else if (member.value.is_object()) {
          r.known_keys(member.value, p, {"field", "size"});
          double size = 0;
          if (!r.string(member.value, "field", p, path, true)) {
            ok = false;
            continue;
          }
          if (r.number(member.value, "size", p, size, 1, 4096)) b.size = static_cast<std::size_t>(size);
        } else {
          r.error(member.value, p, "a signal's field must be a path string or {\"field\": ..., \"size\": N}");
          ok = false;
          continue;
        }
        if (!typed) continue;
        auto fp = parse_field_path(t.type, path);
        if (!fp) {
          r.error(member.value, p, fp.error().message);
          ok = false;
          continue;
        }
        b.path = *fp;
        t.signals.push_back(std::move(b));
      }
    } else {
      ok = false;
    }
  }
  if (r.string(v, "rate_signal", pointer, t.rate_signal, false))
    ok = r.dotted(*v.find("rate_signal"), pointer + "/rate_signal", t.rate_signal, "signal") && ok;
  if (r.string(v, "age_signal", pointer, t.age_signal, false))
    ok = r.dotted(*v.find("age_signal"), pointer + "/age_signal", t.age_signal, "signal") && ok;
  if (const JsonValue* w = v.find("watchdog")) read_check(r, *w, pointer + "/watchdog", true, t.watchdog);
  if (const JsonValue* f = v.find("frequency")) read_check(r, *f, pointer + "/frequency", false, t.frequency);
  if ((t.watchdog || t.frequency) && t.rate_signal.empty()) {
    r.error(v, pointer, "'watchdog' and 'frequency' judge the topic's arrivals: name a 'rate_signal'");
    ok = false;
  }
  if (ok) m.topics.push_back(std::move(t));
}

void read_event(Reader& r, const JsonValue& v, const std::string& pointer, Mapping& m) {
  if (!r.expect(v, JsonValue::Type::Object, pointer, "an event")) return;
  r.known_keys(v, pointer, {"name", "severity", "state_transition", "completes", "latched", "hazard", "description"});
  EventDef e;
  bool ok = r.string(v, "name", pointer, e.name, true);
  double severity = 0;
  if (!r.number(v, "severity", pointer, severity, kMinSeverity, kMaxSeverity)) {
    if (v.find("severity") == nullptr) r.error(v, pointer, "missing 'severity'");
    ok = false;
  }
  e.severity = static_cast<int>(severity);
  const JsonValue* ts = v.find("state_transition");
  if (ts == nullptr) {
    r.error(v, pointer, "missing 'state_transition'");
    ok = false;
  } else if (r.expect(*ts, JsonValue::Type::Array, pointer + "/state_transition", "'state_transition'")) {
    for (std::size_t i = 0; i < ts->array.size(); ++i) {
      const JsonValue& x = ts->array[i];
      auto t = x.is_string() ? parse_transition(x.string) : std::nullopt;
      if (!t) {
        r.error(x, pointer + "/state_transition/" + std::to_string(i),
                "not a transition (N2W, N2E, W2E, W2N, E2N, E2W)");
        ok = false;
      } else {
        e.transitions.insert(*t);
      }
    }
  } else {
    ok = false;
  }
  r.string(v, "completes", pointer, e.completes, false);
  r.string(v, "hazard", pointer, e.hazard, false);
  r.string(v, "description", pointer, e.description, false);
  if (const JsonValue* l = v.find("latched")) {
    if (r.expect(*l, JsonValue::Type::Bool, pointer + "/latched", "'latched'")) e.latched = l->boolean;
  }
  if (ok) m.events.push_back(std::move(e));
}

void read_diagnostics(Reader& r, const JsonValue& v, Mapping& m) {
  const std::string pointer = "/diagnostics";
  if (!r.expect(v, JsonValue::Type::Object, pointer, "'diagnostics'")) return;
  r.known_keys(v, pointer, {"publish", "period", "prefix", "hardware_id", "ingest_topic", "ingest"});
  r.string(v, "publish", pointer, m.publish_topic, false);
  r.number(v, "period", pointer, m.publish_period, 0.01, 3600);
  r.string(v, "prefix", pointer, m.prefix, false);
  r.string(v, "hardware_id", pointer, m.hardware_id, false);
  r.string(v, "ingest_topic", pointer, m.ingest_topic, false);
  const JsonValue* in = v.find("ingest");
  if (in == nullptr || !r.expect(*in, JsonValue::Type::Array, pointer + "/ingest", "'ingest'")) return;
  for (std::size_t i = 0; i < in->array.size(); ++i) {
    const JsonValue& e = in->array[i];
    const std::string p = pointer + "/ingest/" + std::to_string(i);
    if (!r.expect(e, JsonValue::Type::Object, p, "an ingest rule")) continue;
    r.known_keys(e, p, {"name", "target", "warn", "error", "stale", "stale_after"});
    IngestRule rule;
    rule.where = r.at(e);
    bool ok = r.string(e, "name", p, rule.name, true);
    ok = r.string(e, "target", p, rule.target, true) && ok;
    r.string(e, "warn", p, rule.warn, false);
    r.string(e, "error", p, rule.error, false);
    r.string(e, "stale", p, rule.stale, false);
    r.number(e, "stale_after", p, rule.stale_after, 0, 3600);
    if (ok) m.ingest.push_back(std::move(rule));
  }
}

}  // namespace

MappingLoad load_mapping(const std::string& path) {
  std::string text, error;
  if (!spec::read_file(path, text, error)) {
    MappingLoad out;
    out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, spec::Position{path, 0, 0}, error, ""});
    return out;
  }
  return load_mapping_from_text(text, path);
}

MappingLoad load_mapping_from_text(std::string_view text, const std::string& name) {
  MappingLoad out;
  json::JsonParse parsed = json::parse_json(text);
  if (!parsed.value) {
    const json::JsonError& e = *parsed.error;
    out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error,
                                         spec::Position{name, e.position.line, e.position.column}, e.message, ""});
    return out;
  }
  const JsonValue& root = *parsed.value;
  Reader r(name, out.diagnostics);
  if (!r.expect(root, JsonValue::Type::Object, "", "a ROS mapping")) return out;
  r.known_keys(
      root, "",
      {"safecass_ros1", "safecass_ros2", "system", "coordinator", "nodes", "events", "topics", "diagnostics", "graph"});
  Mapping m;
  m.path = name;
  // One format for both frameworks; the header says which graph it was written for.
  const JsonValue* v1 = root.find("safecass_ros1");
  const JsonValue* v2 = root.find("safecass_ros2");
  const JsonValue* version = v1 != nullptr ? v1 : v2;
  if (v1 != nullptr && v2 != nullptr) {
    r.error(*v2, "/safecass_ros2", "a ROS mapping has one header, \"safecass_ros1\": 1 or \"safecass_ros2\": 1");
  } else if (version == nullptr || !version->is_number() || version->number != 1) {
    r.error(version ? *version : root, version ? (v1 ? "/safecass_ros1" : "/safecass_ros2") : "",
            "a ROS mapping starts with \"safecass_ros1\": 1 or \"safecass_ros2\": 1");
  } else {
    m.ros_version = v1 != nullptr ? 1 : 2;
  }
  if (r.string(root, "system", "", m.system, true) && m.system.front() != '/') m.system = directory_of(name) + m.system;
  r.string(root, "coordinator", "", m.coordinator, false);
  if (const JsonValue* nodes = root.find("nodes")) {
    if (r.expect(*nodes, JsonValue::Type::Object, "/nodes", "'nodes'")) {
      std::set<std::string> seen;
      for (const json::JsonMember& n : nodes->object) {
        const std::string p = "/nodes/" + n.key;
        if (!r.expect(n.value, JsonValue::Type::String, p, "a node name")) continue;
        if (n.value.string.empty() || n.value.string.front() != '/') {
          r.error(n.value, p, "node '" + n.value.string + "' must be a global name (start with '/')");
        } else if (!seen.insert(n.key).second) {
          r.error(n.value, p, "component '" + n.key + "' is mapped twice");
        } else {
          m.nodes.emplace_back(n.key, n.value.string);
        }
      }
    }
  }
  if (const JsonValue* events = root.find("events")) {
    if (r.expect(*events, JsonValue::Type::Array, "/events", "'events'")) {
      for (std::size_t i = 0; i < events->array.size(); ++i)
        read_event(r, events->array[i], "/events/" + std::to_string(i), m);
    }
  }
  if (const JsonValue* topics = root.find("topics")) {
    if (r.expect(*topics, JsonValue::Type::Array, "/topics", "'topics'")) {
      std::set<std::string> seen;
      for (std::size_t i = 0; i < topics->array.size(); ++i) {
        const std::size_t before = m.topics.size();
        read_topic(r, topics->array[i], "/topics/" + std::to_string(i), m);
        if (m.topics.size() > before && !seen.insert(m.topics.back().topic).second) {
          r.error(topics->array[i], "/topics/" + std::to_string(i),
                  "topic '" + m.topics.back().topic + "' is mapped twice");
        }
      }
    }
  }
  if (const JsonValue* d = root.find("diagnostics")) read_diagnostics(r, *d, m);
  if (const JsonValue* g = root.find("graph")) {
    if (r.expect(*g, JsonValue::Type::Object, "/graph", "'graph'")) {
      r.known_keys(*g, "/graph", {"period", "grace", "event"});
      r.number(*g, "period", "/graph", m.graph_period, 0, 3600);
      r.number(*g, "grace", "/graph", m.graph_grace, 0, 3600);
      r.string(*g, "event", "/graph", m.graph_event, false);
    }
  }
  bool errors = false;
  for (const Diagnostic& d : out.diagnostics) errors = errors || d.severity == Diagnostic::Severity::Error;
  if (!errors) out.mapping = std::move(m);
  return out;
}

}  // namespace safecass::ros_common
