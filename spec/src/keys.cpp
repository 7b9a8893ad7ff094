#include "keys.hpp"

namespace safecass::spec {

namespace {

const std::vector<std::string_view> kTransitions = {"N2W", "N2E", "W2E", "W2N", "E2N", "E2W"};

Key text(std::string_view name, std::string_view doc, bool required = false) {
  Key k;
  k.name = name;
  k.shape = Shape::String;
  k.required = required;
  k.doc = doc;
  return k;
}

Key boolean(std::string_view name, std::string_view doc, std::string_view def = {}) {
  Key k = text(name, doc);
  k.shape = Shape::Bool;
  k.default_json = def;
  return k;
}

Key choice(std::string_view name, std::string_view doc, std::vector<std::string_view> choices,
           std::string_view def = {}, bool required = false) {
  Key k = text(name, doc, required);
  k.shape = Shape::Choice;
  k.choices = std::move(choices);
  k.default_json = def;
  return k;
}

Key object(std::string_view name, std::string_view doc, std::string_view ref, bool required = false) {
  Key k = text(name, doc, required);
  k.shape = Shape::Object;
  k.ref = ref;
  return k;
}

Key objects(std::string_view name, std::string_view doc, std::string_view ref, bool required = false) {
  Key k = object(name, doc, ref, required);
  k.shape = Shape::ObjectList;
  return k;
}

Key strings(std::string_view name, std::string_view doc) {
  Key k = text(name, doc);
  k.shape = Shape::StringList;
  return k;
}

const Key kSchemaKey = text("$schema", "URI of this schema, for editors (ignored by SAFECASS)");
const Key kVersionKey = [] {
  Key k = text("safecass", "format version (1)");
  k.shape = Shape::Integer;
  k.min = 1;
  k.max = 1;
  return k;
}();
const Key kDescriptionKey = text("description", "free text for people");

}  // namespace

const Key* ObjectKind::find(std::string_view key) const noexcept {
  for (const Key& k : keys) {
    if (k.name == key) return &k;
  }
  return nullptr;
}

const RenamedKey* find_renamed(const ObjectKind& kind, std::string_view key) noexcept {
  static const std::pair<std::string_view, RenamedKey> kRenamed[] = {
      {"component", {"component_name", "the original's key for the name: write \"component\""}},
      {"filter", {"target_component", "the original's key: write \"target\": {\"component\": ...}"}},
      {"filter", {"Arguments", "the original's key: write \"argument\""}},
      {"filter", {"category", "the original's filter category: it has no equivalent; remove it"}},
  };
  for (const auto& [kind_name, renamed] : kRenamed) {
    if (kind_name == kind.name && renamed.old_name == key) return &renamed;
  }
  return nullptr;
}

namespace {
bool same_ignoring_case(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}
}  // namespace

std::string_view canonical_choice(const Key& key, std::string_view value) noexcept {
  const auto same = [&](std::string_view a, std::string_view b) {
    return key.any_case ? same_ignoring_case(a, b) : a == b;
  };
  for (const std::string_view c : key.choices) {
    if (same(value, c)) return c;
  }
  for (const auto& [synonym, choice] : key.synonyms) {
    if (same(value, synonym)) return choice;
  }
  return {};
}

const ObjectKind& system_kind() {
  static const ObjectKind kind{
      "system",
      "a system file: components (inline or included), connections and coordinators",
      {kSchemaKey, kVersionKey, text("system", "name of the system", true), kDescriptionKey,
       objects("components",
               "the components: {\"include\": \"file.json\"} (a component or system file, "
               "relative to this file) or a component object",
               "component_entry", true),
       objects("connections", "connections from a required interface to a provided interface", "connection"),
       object("coordinators", "coordinator (process) name -> the components it runs", "coordinators"),
       objects("hazards", "the hazards of the hazard analysis and the reaction each requires", "hazard"),
       objects("invariants", "named LTL formulas over addresses and levels, checked by safecass verify", "invariant"),
       object("reliability", "failure rates or probabilities of the failure modes, for safecass analyze's fault trees",
              "reliability")}};
  return kind;
}

const ObjectKind& include_kind() {
  static const ObjectKind kind{"include",
                               "a component or system file to include",
                               {text("include", "path of the file, relative to the including file", true)}};
  return kind;
}

const ObjectKind& component_kind() {
  static const ObjectKind kind{
      "component",
      "a component: its interfaces, signals, events, filters and services",
      {kSchemaKey, kVersionKey,
       text("component",
            "name of the component (no dots or spaces; \"\" makes the file a framework filter template, "
            "applied to every component)",
            true),
       kDescriptionKey, object("interfaces", "provided and required interfaces", "interfaces"),
       objects("signals", "signals of the component (Component.signal), scalar or vector", "signal"),
       objects("event", "event definitions (names are unique in the system)", "event"),
       objects("filter", "filters and pipelines", "filter_entry"),
       objects("service", "what the service state of each provided interface depends on", "service"), [] {
         Key k = text("period", "period of the component's loop in seconds (runs its ACTIVE filters)");
         k.shape = Shape::Number;
         k.min = 0;
         k.exclusive_min = true;
         return k;
       }()}};
  return kind;
}

const ObjectKind& interfaces_kind() {
  static const ObjectKind kind{"interfaces",
                               "the interfaces of a component",
                               {strings("provided", "names of the provided interfaces (machines C.s_P.name)"),
                                strings("required", "names of the required interfaces (machines C.s_R.name)")}};
  return kind;
}

const ObjectKind& signal_kind() {
  static const ObjectKind kind{"signal",
                               "a signal: a scalar or a fixed-size vector of doubles",
                               {text("name", "name of the signal within its component", true),
                                [] {
                                  Key k = text("size", "number of doubles per sample (1: a scalar)");
                                  k.shape = Shape::Integer;
                                  k.min = 1;
                                  k.max = kMaxSignalSize;
                                  k.default_json = "1";
                                  return k;
                                }(),
                                kDescriptionKey}};
  return kind;
}

const ObjectKind& event_kind() {
  static const ObjectKind kind{
      "event",
      "an event: an onset (worsening transitions) or a completion (improving transitions)",
      {text("name", "unique name; a completion is usually named /ONSET", true),
       [] {
         Key k = text("severity", "1-200 application, 201-250 framework, 251-255 broadcast", true);
         k.shape = Shape::Integer;
         k.min = 1;
         k.max = 255;
         return k;
       }(),
       [] {
         Key k = text("state_transition", "onset: N2W, N2E, W2E; completion: W2N, E2N, E2W", true);
         k.shape = Shape::ChoiceList;
         k.choices = kTransitions;
         return k;
       }(),
       text("completes", "completion only: the onset it clears (default: the name without its leading '/')"),
       boolean("latched", "onset only: a completion does not clear it, only a reset", "false"),
       text("hazard", "onset: the id of the hazard it detects (from the system's \"hazards\")"), kDescriptionKey}};
  return kind;
}

const ObjectKind& filter_kind() {
  static const ObjectKind kind{
      "filter",
      "a filter: reads signals, may write signals, generates events to a target state machine",
      {text("name", "unique name in the system (default: Component.Type_index)"),
       text("class_name", "filter type, e.g. Threshold (2016 names such as FilterThreshold are accepted)", true),
       [] {
         Key k = choice("type",
                        "ACTIVE: runs in the component's loop; PASSIVE: runs in the monitor thread "
                        "(any letter case; the 2016 INTERNAL and EXTERNAL mean ACTIVE and PASSIVE)",
                        {"ACTIVE", "PASSIVE"}, "\"ACTIVE\"");
         k.any_case = true;
         k.synonyms = {{"INTERNAL", "ACTIVE"}, {"EXTERNAL", "PASSIVE"}};
         return k;
       }(),
       [] {
         Key k = choice("event_type",
                        "EDGE: one onset per crossing; LEVEL: an onset every sample while detected (any letter case)",
                        {"EDGE", "LEVEL"}, "\"EDGE\"");
         k.any_case = true;
         return k;
       }(),
       boolean("enabled", "a disabled filter skips its runs", "true"),
       object("target", "the state machine that receives the events (default: s_A of this component)", "target"),
       object("argument", "the parameters of the filter type", ""), kDescriptionKey,
       [] {
         Key k = boolean("debug",
                         "2016: printed the filter's debug log; accepted and ignored (SAFECASS records every event)",
                         "false");
         k.ignored = true;
         return k;
       }(),
       [] {
         Key k =
             boolean("last_filter",
                     "2016: marked the last filter of a chain; accepted and ignored (a \"pipeline\" says it)", "false");
         k.ignored = true;
         return k;
       }()}};
  return kind;
}

const ObjectKind& pipeline_kind() {
  static const ObjectKind kind{
      "pipeline",
      "a chain of filters: a stage without an input reads the previous stage's output",
      {text("name", "name of the pipeline (no dots or spaces); unnamed stages are called name.1, name.2...", true),
       objects("pipeline", "the stages, in order", "stage", true),
       object("target", "default target of the stages", "target"), kDescriptionKey}};
  return kind;
}

const ObjectKind& target_kind() {
  static const ObjectKind kind{"target",
                               "a state machine: C.s_F, C.s_A, C.s_P.interface or C.s_R.interface",
                               {choice("type", "which machine", {"s_F", "s_A", "s_P", "s_R"}, "\"s_A\""),
                                text("component", "the component (default: the component that declares the filter)"),
                                text("interface", "the interface, for s_P and s_R")}};
  return kind;
}

const ObjectKind& service_kind() {
  static const ObjectKind kind{
      "service",
      "what the service state of a provided interface depends on (no entry: s_F, s_A and every required interface)",
      {text("name", "the provided interface", true),
       object("dependency", "the terms of the service state; {} means s_P alone", "dependency"),
       choice("propagate", "lowest level that crosses connections to clients", {"error", "warning"}, "\"error\"")}};
  return kind;
}

const ObjectKind& dependency_kind() {
  static const ObjectKind kind{
      "dependency",
      "s_S.p = s_P.p x [s_F] x [s_A] x the listed required interfaces",
      {boolean("s_F", "include the framework state", "false"), boolean("s_A", "include the application state", "false"),
       strings("s_R", "required interfaces included")}};
  return kind;
}

const ObjectKind& connection_kind() {
  static const ObjectKind kind{
      "connection",
      "a required interface connected to a provided interface; errors flow from provider to client",
      {text("required", "the client's required interface, Component.interface", true),
       text("provided", "the provider's provided interface, Component.interface", true), kDescriptionKey}};
  return kind;
}

const ObjectKind& hazard_kind() {
  static const ObjectKind kind{
      "hazard",
      "a hazard: events name it in their \"hazard\" field; its reaction is what must hold while one of them is active",
      {text("id", "the hazard's id, e.g. H-3", true), kDescriptionKey,
       object("reaction", "address -> the least level it must be at whenever an onset linked to the hazard is active",
              "reaction")}};
  return kind;
}

const ObjectKind& invariant_kind() {
  static const ObjectKind kind{
      "invariant",
      "a named LTL formula over addresses and levels (docs/verify.md)",
      {text("name", "unique name of the invariant (no spaces)", true),
       text("formula", "e.g. [] (JR3.s_A == Error -> CONTROL == Error)", true), kDescriptionKey}};
  return kind;
}

const ObjectKind& reliability_kind() {
  static const ObjectKind kind{
      "reliability",
      "failure rates or probabilities of the failure modes (docs/analyze.md): SCRAM then computes each top "
      "event's probability and the importance of each mode",
      {[] {
         Key k = text("mission_time", "hours over which rates become probabilities (default 8760, a year)");
         k.shape = Shape::Number;
         k.min = 0;
         k.exclusive_min = true;
         return k;
       }(),
       object("modes",
              "failure mode name (EVT_X@C.s_A, EVT_X for every machine it is raised at, C.s_F, C.s_A, "
              "stale:C.signal, fault:filter, lost:coordinator, lost:supervisor) -> its rate or probability",
              "mode_rates", true),
       kDescriptionKey}};
  return kind;
}

const ObjectKind& mode_rate_kind() {
  static const ObjectKind kind{"mode_rate",
                               "one failure mode's rate or probability (exactly one of the two)",
                               {[] {
                                  Key k =
                                      text("rate", "failures per hour (exponential: 1 - exp(-rate * mission_time))");
                                  k.shape = Shape::Number;
                                  k.min = 0;
                                  k.exclusive_min = true;
                                  return k;
                                }(),
                                [] {
                                  Key k = text("probability", "the probability that it happens within the mission");
                                  k.shape = Shape::Number;
                                  k.min = 0;
                                  k.max = 1;
                                  return k;
                                }()}};
  return kind;
}

std::vector<const ObjectKind*> all_kinds() {
  return {&system_kind(), &include_kind(),   &component_kind(),   &interfaces_kind(),
          &signal_kind(), &event_kind(),     &filter_kind(),      &pipeline_kind(),
          &target_kind(), &service_kind(),   &dependency_kind(),  &connection_kind(),
          &hazard_kind(), &invariant_kind(), &reliability_kind(), &mode_rate_kind()};
}

}  // namespace safecass::spec
