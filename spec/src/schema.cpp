#include "safecass/spec/schema.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "keys.hpp"
#include "safecass/json/read.hpp"
#include "safecass/json/write.hpp"
#include "text.hpp"

namespace safecass::spec {

namespace {

/// A JSON value under construction: members keep their insertion order, so the text is stable.
struct Node {
  enum class Kind { Scalar, Object, Array } kind = Kind::Object;
  std::string scalar;             ///< JSON text
  std::vector<std::string> keys;  ///< object: member names, in order
  std::vector<Node> values;       ///< object: member values
  std::vector<Node> items;        ///< array

  static Node text(std::string_view s) {
    Node n;
    n.kind = Kind::Scalar;
    n.scalar = json::json_string(s);
    return n;
  }
  static Node raw(std::string s) {
    Node n;
    n.kind = Kind::Scalar;
    n.scalar = std::move(s);
    return n;
  }
  static Node number(double d) { return raw(number_text(d)); }
  static Node array() {
    Node n;
    n.kind = Kind::Array;
    return n;
  }
  static Node ref(std::string_view def) {
    Node n;
    n.set("$ref", text("#/$defs/" + std::string(def)));
    return n;
  }
  /// Adds a member. The reference is valid until the next member is added.
  Node& set(std::string key, Node value) {
    keys.push_back(std::move(key));
    values.push_back(std::move(value));
    return values.back();
  }
  Node* member(std::string_view key) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] == key) return &values[i];
    }
    return nullptr;
  }
  Node& push(Node value) {
    items.push_back(std::move(value));
    return items.back();
  }

  bool flat() const {
    if (kind != Kind::Array) return kind == Kind::Scalar;
    for (const Node& i : items) {
      if (i.kind != Kind::Scalar) return false;
    }
    return true;
  }

  void write(std::string& out, int indent) const {
    const std::string pad(static_cast<std::size_t>(indent + 2), ' ');
    switch (kind) {
      case Kind::Scalar: out += scalar; return;
      case Kind::Array:
        if (items.empty()) {
          out += "[]";
          return;
        }
        if (flat()) {
          out += "[";
          for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i].scalar;
          out += "]";
          return;
        }
        out += "[\n";
        for (std::size_t i = 0; i < items.size(); ++i) {
          out += pad;
          items[i].write(out, indent + 2);
          out += i + 1 < items.size() ? ",\n" : "\n";
        }
        out += std::string(static_cast<std::size_t>(indent), ' ') + "]";
        return;
      case Kind::Object:
        if (keys.empty()) {
          out += "{}";
          return;
        }
        out += "{\n";
        for (std::size_t i = 0; i < keys.size(); ++i) {
          out += pad + json::json_string(keys[i]) + ": ";
          values[i].write(out, indent + 2);
          out += i + 1 < keys.size() ? ",\n" : "\n";
        }
        out += std::string(static_cast<std::size_t>(indent), ' ') + "}";
        return;
    }
  }
};

Node strings_of(const std::vector<std::string_view>& words) {
  Node a = Node::array();
  for (const std::string_view w : words) a.push(Node::text(w));
  return a;
}

Node key_schema(const Key& k) {
  Node n;
  switch (k.shape) {
    case Shape::String: n.set("type", Node::text("string")); break;
    case Shape::Bool: n.set("type", Node::text("boolean")); break;
    case Shape::Integer:
    case Shape::Number:
      n.set("type", Node::text(k.shape == Shape::Integer ? "integer" : "number"));
      if (std::isfinite(k.min)) n.set(k.exclusive_min ? "exclusiveMinimum" : "minimum", Node::number(k.min));
      if (std::isfinite(k.max)) n.set("maximum", Node::number(k.max));
      break;
    case Shape::Choice: {
      if (!k.any_case && k.synonyms.empty()) {
        n.set("enum", strings_of(k.choices));
        break;
      }
      // The spellings the loader accepts: the choices and synonyms, in upper and lower case.
      std::vector<std::string_view> spellings(k.choices.begin(), k.choices.end());
      for (const auto& [synonym, choice] : k.synonyms) spellings.push_back(synonym);
      std::vector<std::string> all;
      for (const std::string_view s : spellings) {
        all.emplace_back(s);
        if (!k.any_case) continue;
        std::string lower(s);
        for (char& c : lower) c = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
        if (lower != s) all.push_back(std::move(lower));
      }
      Node e = Node::array();
      for (const std::string& s : all) e.push(Node::text(s));
      n.set("enum", std::move(e));
      break;
    }
    case Shape::StringList: {
      n.set("type", Node::text("array"));
      Node items;
      items.set("type", Node::text("string"));
      n.set("items", std::move(items));
      break;
    }
    case Shape::ChoiceList: {
      n.set("type", Node::text("array"));
      Node items;
      items.set("enum", strings_of(k.choices));
      n.set("items", std::move(items));
      break;
    }
    case Shape::Object:
      if (k.ref.empty())
        n.set("type", Node::text("object"));
      else
        n.set("$ref", Node::text("#/$defs/" + std::string(k.ref)));
      break;
    case Shape::ObjectList:
      n.set("type", Node::text("array"));
      n.set("items", Node::ref(k.ref));
      break;
  }
  if (!k.default_json.empty()) n.set("default", Node::raw(std::string(k.default_json)));
  n.set("description", Node::text(k.doc));
  return n;
}

Node object_schema(const ObjectKind& kind) {
  Node n;
  n.set("type", Node::text("object"));
  n.set("description", Node::text(kind.doc));
  Node& properties = n.set("properties", Node{});
  Node required = Node::array();
  for (const Key& k : kind.keys) {
    properties.set(std::string(k.name), key_schema(k));
    if (k.required) required.push(Node::text(k.name));
  }
  if (!required.items.empty()) n.set("required", std::move(required));
  n.set("additionalProperties", Node::raw("false"));
  return n;
}

Node param_value(const ParamValue& v) {
  switch (v.index()) {
    case 0: return Node::number(std::get<double>(v));
    case 1: return Node::raw(std::get<bool>(v) ? "true" : "false");
    case 2: return Node::text(std::get<std::string>(v));
    case 3: {
      Node a = Node::array();
      for (const std::string& s : std::get<std::vector<std::string>>(v)) a.push(Node::text(s));
      return a;
    }
    case 4: {
      Node a = Node::array();
      for (const double d : std::get<std::vector<double>>(v)) a.push(Node::number(d));
      return a;
    }
  }
  return Node::raw("null");
}

Node param_schema(const ParamSpec& p) {
  Node n;
  switch (p.type) {
    case ParamType::Number:
    case ParamType::Integer:
      n.set("type", Node::text(p.type == ParamType::Integer ? "integer" : "number"));
      if (p.min > -1e300) n.set("minimum", Node::number(p.min));
      if (p.max < 1e300) n.set("maximum", Node::number(p.max));
      break;
    case ParamType::Bool: n.set("type", Node::text("boolean")); break;
    case ParamType::String:
    case ParamType::Signal:
    case ParamType::Event:
      n.set("type", Node::text("string"));
      n.set("minLength", Node::raw("1"));
      break;
    case ParamType::Choice: {
      Node e = Node::array();
      for (const std::string& c : p.choices) e.push(Node::text(c));
      n.set("enum", std::move(e));
      break;
    }
    case ParamType::SignalList: {
      n.set("type", Node::text("array"));
      Node items;
      items.set("type", Node::text("string"));
      items.set("minLength", Node::raw("1"));
      n.set("items", std::move(items));
      n.set("minItems", Node::raw("1"));
      break;
    }
    case ParamType::NumberList: {
      n.set("type", Node::text("array"));
      Node items;
      items.set("type", Node::text("number"));
      n.set("items", std::move(items));
      break;
    }
  }
  if (p.default_value) n.set("default", param_value(*p.default_value));
  std::string doc = p.doc;
  if (p.type == ParamType::Signal || p.type == ParamType::SignalList)
    doc += " (Component.signal, or a bare name for the target component)";
  if (p.type == ParamType::Event) doc += " (an event of the system)";
  n.set("description", Node::text(doc));
  return n;
}

bool is_signal_param(const FilterManifest& m, const std::string& name) {
  return std::find(m.inputs.begin(), m.inputs.end(), name) != m.inputs.end() ||
         std::find(m.outputs.begin(), m.outputs.end(), name) != m.outputs.end();
}

/// Required parameters, either those a pipeline can fill in (inputs, outputs) or the others.
Node required_params(const FilterManifest& m, bool signals) {
  Node required = Node::array();
  for (const ParamSpec& p : m.params) {
    if (!p.default_value && !p.optional && is_signal_param(m, p.name) == signals) required.push(Node::text(p.name));
  }
  return required;
}

/// The parameters of a filter type. Inputs and outputs are not required here: a pipeline
/// wires them; a standalone filter requires them (see filter_rules).
Node argument_schema(const FilterManifest& m) {
  Node n;
  n.set("type", Node::text("object"));
  n.set("description", Node::text(m.type + ": " + m.doc));
  Node& properties = n.set("properties", Node{});
  Node required = required_params(m, false);
  for (const ParamSpec& p : m.params) properties.set(p.name, param_schema(p));
  for (const auto& [alias, param] : m.aliases) {
    if (const ParamSpec* p = m.find(param)) {
      Node a = param_schema(*p);
      *a.member("description") = Node::text("the 2016 name of '" + param + "'");
      properties.set(alias, std::move(a));
    }
  }
  if (!required.items.empty()) n.set("required", std::move(required));
  n.set("additionalProperties", Node::raw("false"));
  return n;
}

/// A filter (or, with `stage`, a pipeline stage, whose input and output the pipeline may fill
/// in): class_name names every type and alias; argument follows the named type.
Node filter_schema(const FilterRegistry& registry, const std::vector<const FilterManifest*>& manifests, bool stage) {
  Node schema = object_schema(filter_kind());
  if (stage) {
    *schema.member("description") = Node::text(
        "a pipeline stage: a filter whose input may come from the previous stage and whose "
        "output may be named by the pipeline");
  }
  Node names = Node::array();
  Node all_of = Node::array();
  for (const FilterManifest* m : manifests) {
    Node these = Node::array();
    these.push(Node::text(m->type));
    for (const auto& [alias, type] : registry.aliases()) {
      const FilterRegistry::Entry* e = registry.find(alias);
      if (e != nullptr && &e->manifest == m) these.push(Node::text(alias));
    }
    for (const Node& n : these.items) names.push(n);
    Node rule;
    Node& condition = rule.set("if", Node{});
    condition.set("properties", Node{}).set("class_name", Node{}).set("enum", these);
    Node required = Node::array();
    required.push(Node::text("class_name"));
    condition.set("required", std::move(required));
    Node& then = rule.set("then", Node{});
    Node argument = Node::ref("argument_" + m->type);
    Node signal_params = required_params(*m, true);
    const bool needs_argument = !required_params(*m, false).items.empty() || (!stage && !signal_params.items.empty());
    if (!stage && !signal_params.items.empty()) argument.set("required", std::move(signal_params));
    then.set("properties", Node{}).set("argument", std::move(argument));
    if (needs_argument) {
      Node req = Node::array();
      req.push(Node::text("argument"));
      then.set("required", std::move(req));
    }
    all_of.push(std::move(rule));
  }
  if (Node* properties = schema.member("properties")) {
    if (Node* class_name = properties->member("class_name")) {
      // After "type", before "description".
      class_name->keys.insert(class_name->keys.begin() + 1, "enum");
      class_name->values.insert(class_name->values.begin() + 1, names);
    }
  }
  schema.set("allOf", std::move(all_of));
  return schema;
}

}  // namespace

std::string json_schema(const FilterRegistry& registry) {
  Node root;
  root.set("$schema", Node::text("https://json-schema.org/draft/2020-12/schema"));
  root.set("$id", Node::text("urn:safecass:spec:1"));
  root.set("title", Node::text("SAFECASS specification"));
  root.set("description",
           Node::text("A system file (\"system\") or a component file (\"component\"); comments (// and /* */) "
                      "are allowed by SAFECASS but not by JSON Schema tools. Generated from the format's key "
                      "tables and the filter manifests: see docs/spec-format.md."));
  Node& one_of = root.set("oneOf", Node::array());
  one_of.push(Node::ref("system"));
  one_of.push(Node::ref("component"));
  Node& defs = root.set("$defs", Node{});

  const std::vector<const FilterManifest*> manifests = registry.manifests();
  for (const ObjectKind* kind : all_kinds()) {
    if (kind == &filter_kind()) {
      defs.set("filter", filter_schema(registry, manifests, false));
      defs.set("stage", filter_schema(registry, manifests, true));
    } else {
      defs.set(std::string(kind->name), object_schema(*kind));
    }
  }
  {
    Node entry;
    entry.set("description", Node::text("an included file or an inline component"));
    Node& alternatives = entry.set("oneOf", Node::array());
    alternatives.push(Node::ref("include"));
    alternatives.push(Node::ref("component"));
    defs.set("component_entry", std::move(entry));
  }
  {
    Node entry;
    entry.set("description", Node::text("a filter, or a pipeline of filters"));
    Node& alternatives = entry.set("oneOf", Node::array());
    alternatives.push(Node::ref("filter"));
    alternatives.push(Node::ref("pipeline"));
    defs.set("filter_entry", std::move(entry));
  }
  {
    Node c;
    c.set("type", Node::text("object"));
    c.set("description",
          Node::text("coordinator (process) name -> the components it runs; each component in one coordinator"));
    Node& list = c.set("additionalProperties", Node{});
    list.set("type", Node::text("array"));
    Node items;
    items.set("type", Node::text("string"));
    list.set("items", std::move(items));
    list.set("uniqueItems", Node::raw("true"));
    defs.set("coordinators", std::move(c));
  }
  {
    Node r;
    r.set("type", Node::text("object"));
    r.set("description",
          Node::text("address (SYSTEM, C, C.s_F, C.s_A, C.s_P.p, C.s_R.r, C.s_S.p) -> the least level it must be at"));
    Node& level = r.set("additionalProperties", Node{});
    Node& choices = level.set("enum", Node::array());
    choices.push(Node::text("Warning"));
    choices.push(Node::text("Error"));
    defs.set("reaction", std::move(r));
  }
  {
    Node m;
    m.set("type", Node::text("object"));
    m.set("description", Node::text("failure mode name -> its rate or probability"));
    m.set("additionalProperties", Node::ref("mode_rate"));
    defs.set("mode_rates", std::move(m));
  }
  for (const FilterManifest* m : manifests) defs.set("argument_" + m->type, argument_schema(*m));

  std::string out;
  root.write(out, 0);
  out += '\n';
  return out;
}

}  // namespace safecass::spec
