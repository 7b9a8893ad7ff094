// Reading specification files: bytes -> JSON -> the loader's model, with the file, syntax and
// schema checks (unknown, duplicate, missing and mistyped keys). Cross-references are checked
// afterwards by validate.cpp.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "safecass/spec/file.hpp"

#include "keys.hpp"
#include "model.hpp"
#include "text.hpp"

namespace safecass::spec {

namespace {

constexpr std::size_t kMaxFileBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxIncludeDepth = 16;
constexpr std::size_t kMaxFiles = 100000;
constexpr int kMaxJsonDepth = 64;

std::vector<std::string> to_strings(const std::vector<std::string_view>& views) { return {views.begin(), views.end()}; }

bool whole(double d) noexcept { return std::isfinite(d) && std::floor(d) == d; }

/// The members of one object, checked against the table of its kind: duplicate keys, unknown
/// keys (with the nearest known one), mistyped values and missing required keys are reported;
/// get() then returns only members that are present and of the right shape.
class Fields {
public:
  Fields(Sink& sink, int file, const json::JsonValue& object, std::string pointer, const ObjectKind& kind,
         std::string context)
      : sink_(sink),
        file_(file),
        object_(object),
        pointer_(std::move(pointer)),
        kind_(kind),
        context_(std::move(context)) {
    std::set<std::string_view> seen;
    for (const json::JsonMember& m : object.object) {
      const Site key_site{file_, m.key_position, pointer_join(pointer_, m.key)};
      if (!seen.insert(m.key).second) {
        const json::JsonMember* first = object.find_member(m.key);
        sink_.error(key_site, context_ + ": duplicate key " + quote_name(m.key) + " (first at line " +
                                  std::to_string(first->key_position.line) + ", column " +
                                  std::to_string(first->key_position.column) + ")");
        continue;
      }
      const Key* key = kind_.find(m.key);
      if (const RenamedKey* renamed = key == nullptr ? find_renamed(kind_, m.key) : nullptr) {
        // A key of the original format with a new name or place: say what to write.
        sink_.error(key_site,
                    context_ + ": unknown key " + quote_name(m.key) + " (" + std::string(renamed->advice) + ")");
        continue;
      }
      if (key == nullptr) {
        std::vector<std::string> known;
        for (const Key& k : kind_.keys) known.emplace_back(k.name);
        const auto near = nearest(m.key, known);
        std::string message = context_ + ": unknown key " + quote_name(m.key);
        if (near) {
          message += "; did you mean " + quote_name(*near) + "?";
        } else {
          std::string list;
          for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
          message += " (known keys: " + list + ")";
        }
        sink_.error(key_site, std::move(message));
        continue;
      }
      if (check(*key, m)) {
        good_.push_back(&m);
        if (key->ignored) {
          sink_.note(key_site, context_ + ": " + quote_name(m.key) + " is accepted for the 2016 files and ignored");
        }
      }
    }
    for (const Key& k : kind_.keys) {
      if (k.required && object.find_member(k.name) == nullptr) {
        sink_.error(object_site(),
                    context_ + ": missing required key " + quote_name(k.name) + " (" + std::string(k.doc) + ")");
      }
    }
  }

  const json::JsonValue* get(std::string_view key) const noexcept {
    for (const json::JsonMember* m : good_) {
      if (m->key == key) return &m->value;
    }
    return nullptr;
  }
  /// A Choice member as its canonical choice ("active" and "INTERNAL" are "ACTIVE"), or "".
  std::string_view choice(std::string_view key) const noexcept {
    const json::JsonValue* v = get(key);
    const Key* k = kind_.find(key);
    return v == nullptr || k == nullptr ? std::string_view() : canonical_choice(*k, v->string);
  }
  const json::JsonMember* member(std::string_view key) const noexcept { return object_.find_member(key); }
  bool has(std::string_view key) const noexcept { return member(key) != nullptr; }
  Site site(std::string_view key) const {
    const json::JsonMember* m = member(key);
    if (m == nullptr) return object_site();
    return Site{file_, m->value.position, pointer(key)};
  }
  Site object_site() const { return Site{file_, object_.position, pointer_}; }
  std::string pointer(std::string_view key) const { return pointer_join(pointer_, key); }
  const std::string& context() const noexcept { return context_; }

  /// The string items of a StringList member, with their sites.
  std::vector<Name> names(std::string_view key) const {
    std::vector<Name> out;
    const json::JsonValue* v = get(key);
    if (v == nullptr) return out;
    for (std::size_t i = 0; i < v->array.size(); ++i) {
      const json::JsonValue& item = v->array[i];
      if (item.is_string()) out.push_back(Name{item.string, Site{file_, item.position, pointer_join(pointer(key), i)}});
    }
    return out;
  }

private:
  bool check(const Key& key, const json::JsonMember& m) {
    const json::JsonValue& v = m.value;
    const Site site{file_, v.position, pointer(m.key)};
    const std::string what = context_ + ": " + quote_name(m.key);
    const auto wrong = [&](const std::string& expected) {
      sink_.error(site, what + " must be " + expected + ", not " + a_type(v.type));
      return false;
    };
    switch (key.shape) {
      case Shape::String: return v.is_string() || wrong("a string");
      case Shape::Bool: return v.is_bool() || wrong("true or false");
      case Shape::Integer:
      case Shape::Number: {
        const bool integer = key.shape == Shape::Integer;
        if (!v.is_number() || (integer && !whole(v.number))) {
          if (v.is_number()) {
            sink_.error(site, what + " must be a whole number, not " + number_text(v.number));
            return false;
          }
          return wrong(integer ? "an integer" : "a number");
        }
        const double d = v.number;
        const bool low = key.exclusive_min ? !(d > key.min) : d < key.min;
        if (low || d > key.max) {
          std::string range;
          if (key.min == key.max) {
            range = "must be " + number_text(key.min);
          } else if (std::isinf(key.max)) {
            range =
                std::string("must be ") + (key.exclusive_min ? "greater than " : "at least ") + number_text(key.min);
          } else {
            range = "must be within " + number_text(key.min) + "-" + number_text(key.max);
          }
          sink_.error(site, what + " " + range + ", not " + number_text(d));
          return false;
        }
        return true;
      }
      case Shape::Choice: {
        if (!v.is_string()) return wrong("a string (" + join_or(to_strings(key.choices)) + ")");
        return check_choice(key, v, site, what);
      }
      case Shape::StringList:
      case Shape::ChoiceList: {
        if (!v.is_array())
          return wrong(key.shape == Shape::StringList ? "an array of strings"
                                                      : "an array of " + join_or(to_strings(key.choices)));
        for (std::size_t i = 0; i < v.array.size(); ++i) {
          const json::JsonValue& item = v.array[i];
          const Site item_site{file_, item.position, pointer_join(site.pointer, i)};
          if (!item.is_string()) {
            sink_.error(item_site, what + " items must be strings, not " + a_type(item.type));
          } else if (key.shape == Shape::ChoiceList) {
            check_choice(key, item, item_site, what + " item");
          }
        }
        return true;
      }
      case Shape::Object: return v.is_object() || wrong("an object");
      case Shape::ObjectList: return v.is_array() || wrong("an array");
    }
    return false;
  }

  bool check_choice(const Key& key, const json::JsonValue& v, const Site& site, const std::string& what) {
    if (!canonical_choice(key, v.string).empty()) return true;
    sink_.error(site, what + " must be " + join_or(to_strings(key.choices)) + ", not " + quote_name(v.string) +
                          did_you_mean(v.string, to_strings(key.choices)));
    return false;
  }

  Sink& sink_;
  int file_;
  const json::JsonValue& object_;
  std::string pointer_;
  const ObjectKind& kind_;
  std::string context_;
  std::vector<const json::JsonMember*> good_;
};

std::string named(std::string_view kind, const json::JsonValue& object, std::string_view name_key) {
  const json::JsonValue* n = object.find(name_key);
  if (n != nullptr && n->is_string()) return std::string(kind) + " " + quote_name(n->string);
  return std::string(kind);
}

/// A target given on a pipeline, inherited by its stages.
struct TargetDefault {
  bool given = false;
  FilterTarget target;
  Site site, type_site, component_site, interface_site;
  bool component_given = false;
  bool has_interface = false;
};

class Reader {
public:
  Reader(Sink& sink, Model& model) : sink_(sink), model_(model) {}

  void run(const std::string& path, const std::string* text) {
    model_.path = path;
    const int doc = open(path, text, nullptr);
    if (doc < 0) return;
    const json::JsonValue& root = *sink_.documents[static_cast<std::size_t>(doc)].root;
    switch (kind_of(doc, root)) {
      case FileKind::Component: {
        ComponentItem c;
        read_component(doc, root, "", c);
        model_.name = c.name;
        model_.components.push_back(std::move(c));
        break;
      }
      case FileKind::System:
        model_.system_file = true;
        read_system(doc, root, "", true);
        break;
      case FileKind::Invalid: break;
    }
    stack_.pop_back();
  }

private:
  enum class FileKind { System, Component, Invalid };

  /// What a file holds; reports files that are neither or both.
  FileKind kind_of(int doc, const json::JsonValue& root) {
    const bool system = root.find_member("system") != nullptr || root.find_member("components") != nullptr;
    const bool component = root.find_member("component") != nullptr;
    const Site site{doc, root.position, ""};
    if (const json::JsonMember* monitor = root.find_member("monitor"); monitor != nullptr && !system && !component) {
      refuse_monitor_targets(doc, *monitor);
      return FileKind::Invalid;
    }
    if (const json::JsonMember* old = root.find_member("component_name"); old != nullptr && !system && !component) {
      sink_.error(Site{doc, old->key_position, "/component_name"},
                  "'component_name' is the original's key for the component's name: write \"component\"");
      return FileKind::Invalid;
    }
    if (root.find_member("steps") != nullptr && !component) {
      sink_.error(site,
                  "this is a scenario (it has \"steps\"), not a system or component file: run it with "
                  "`safecass run` or `safecass test`");
      return FileKind::Invalid;
    }
    if (system && component) {
      sink_.error(site,
                  "a file is either a system (\"system\", \"components\") or a component (\"component\"), not both");
      return FileKind::Invalid;
    }
    if (!system && !component) {
      sink_.error(
          site,
          "not a specification: a system file has \"system\" and \"components\", a component file has \"component\"");
      return FileKind::Invalid;
    }
    return system ? FileKind::System : FileKind::Component;
  }

  /// The 2016 monitor-target file ({"monitor": [targets]}) is not loaded: its targets asked the
  /// framework to stream a measurement (a thread's period or duty cycle) at a sampling rate,
  /// without any limit, so nothing in it says what is a fault. Each target gets one error that
  /// names the filter that detects that fault once the limits are written down.
  void refuse_monitor_targets(int doc, const json::JsonMember& monitor) {
    const std::string base = "/monitor";
    const std::string intro =
        "the 2016 monitor-target file is not loaded (a target streams a measurement and sets no limit): ";
    if (!monitor.value.is_array() || monitor.value.array.empty()) {
      sink_.error(Site{doc, monitor.key_position, base},
                  intro + "write a Frequency filter for a thread's period and a DutyCycle filter for its duty cycle");
      return;
    }
    for (std::size_t i = 0; i < monitor.value.array.size(); ++i) {
      const json::JsonValue& target = monitor.value.array[i];
      const std::string p = pointer_join(base, i);
      std::string type;
      std::string component = "the component";
      if (target.is_object()) {
        if (const json::JsonValue* t = target.find("type"); t != nullptr && t->is_string()) type = t->string;
        if (const json::JsonValue* loc = target.find("location"); loc != nullptr && loc->is_object()) {
          if (const json::JsonValue* c = loc->find("component"); c != nullptr && c->is_string() && !c->string.empty()) {
            component = "component " + quote_name(c->string);
          }
        }
      }
      std::string advice;
      if (type == "THREAD_PERIOD") {
        advice = "for the period of " + component +
                 ", write a Frequency filter (min_rate, max_rate, max_jitter) on the "
                 "signal its framework extension writes every cycle";
      } else if (type == "THREAD_DUTYCYCLE_TOTAL" || type == "THREAD_DUTYCYCLE_USER") {
        advice = "for the duty cycle of " + component +
                 ", write a DutyCycle filter (period, max_duty) on its execution "
                 "time per cycle (" +
                 (type == "THREAD_DUTYCYCLE_USER" ? "the user's code alone" : "the whole cycle") + ")";
      } else {
        advice = "for " + (type.empty() ? std::string("this target") : "target " + quote_name(type)) + " of " +
                 component + ", write a filter on the signal it measures (Threshold, Range, Frequency, DutyCycle...)";
      }
      const json::TextPosition at = target.is_object() && target.find_member("type") != nullptr
                                        ? target.find_member("type")->key_position
                                        : target.position;
      sink_.error(
          Site{doc, at, target.is_object() && target.find_member("type") != nullptr ? pointer_join(p, "type") : p},
          intro + advice);
    }
  }

  /// Opens and parses a file. Returns its document index (pushed on the include stack), or -1.
  int open(const std::string& path, const std::string* given_text, const Site* include_site) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path p(path);
    std::string canonical = fs::weakly_canonical(p, ec).string();
    if (ec || canonical.empty()) canonical = fs::absolute(p, ec).lexically_normal().string();
    if (include_site != nullptr) {
      for (std::size_t i = 0; i < stack_.size(); ++i) {
        if (stack_[i].first == canonical) {
          std::string chain;
          for (std::size_t k = i; k < stack_.size(); ++k) chain += stack_[k].second + " -> ";
          sink_.error(*include_site, "include cycle: " + chain + path);
          return -1;
        }
      }
      if (const auto loaded = loaded_.find(canonical); loaded != loaded_.end()) {
        const auto it = included_at_.find(loaded->second);
        sink_.error(*include_site,
                    "file " + quote_name(path) + " is already included" +
                        (it != included_at_.end() ? " (at " + sink_.at(it->second) + ")" : std::string()));
        return -1;
      }
      if (stack_.size() >= kMaxIncludeDepth) {
        sink_.error(*include_site, "includes nested deeper than " + std::to_string(kMaxIncludeDepth) + " files");
        return -1;
      }
      if (sink_.documents.size() >= kMaxFiles) {
        sink_.error(*include_site, "more than " + std::to_string(kMaxFiles) + " files included");
        return -1;
      }
    }

    std::string text;
    std::string problem;
    if (given_text != nullptr) {
      text = *given_text;
    } else {
      auto read = read_regular_file(path, kMaxFileBytes);
      if (read) {
        text = std::move(*read);
      } else {
        problem = std::move(read.error().message);
      }
    }
    if (problem.empty() && text.size() > kMaxFileBytes) {
      problem = "file " + quote_name(path) + " is larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB";
    }
    if (!problem.empty()) {
      if (include_site != nullptr) {
        sink_.error(*include_site, problem);
      } else {
        sink_.documents.push_back(Document{path, canonical, {}, std::nullopt});
        sink_.error(Site{0, {}, ""}, problem);
      }
      return -1;
    }

    const int doc = static_cast<int>(sink_.documents.size());
    sink_.documents.push_back(Document{path, canonical, std::move(text), std::nullopt});
    loaded_.emplace(canonical, doc);
    if (include_site != nullptr) included_at_.emplace(doc, *include_site);
    Document& d = sink_.documents.back();
    std::string_view body = d.text;
    if (body.empty()) {
      sink_.error(Site{doc, json::TextPosition{1, 1}, ""}, "empty file: expected a JSON object");
      return -1;
    }
    if (body.substr(0, 3) == "\xEF\xBB\xBF") body.remove_prefix(3);  // a byte-order mark
    if (const auto bad = check_utf8(body)) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", bad->byte);
      sink_.error(Site{doc, bad->position, ""},
                  std::string("invalid UTF-8 (byte ") + hex + "): a specification is UTF-8 text");
      return -1;
    }
    json::JsonParse parsed = json::parse_json(body, kMaxJsonDepth);
    if (parsed.error) {
      sink_.error(Site{doc, parsed.error->position, ""}, parsed.error->message);
      return -1;
    }
    if (!parsed.value->is_object()) {
      sink_.error(Site{doc, parsed.value->position, ""},
                  "a specification file holds a JSON object, not " + a_type(parsed.value->type));
      return -1;
    }
    d.root = std::move(parsed.value);
    stack_.emplace_back(canonical, path);
    return doc;
  }

  void include(int from, const json::JsonValue& entry, const std::string& pointer) {
    Fields f(sink_, from, entry, pointer, include_kind(), "include");
    const json::JsonValue* path = f.get("include");
    if (path == nullptr) return;
    const Site site = f.site("include");
    if (path->string.empty()) {
      sink_.error(site, "include: the path is empty");
      return;
    }
    if (path->string.find('\0') != std::string::npos) {
      sink_.error(site, "include: the path contains a NUL character");
      return;
    }
    namespace fs = std::filesystem;
    const fs::path including(sink_.documents[static_cast<std::size_t>(from)].path);
    fs::path target(path->string);
    if (target.is_relative()) target = including.parent_path() / target;
    std::string resolved = target.lexically_normal().string();
    if (resolved.empty()) resolved = ".";
    const int doc = open(resolved, nullptr, &site);
    if (doc < 0) return;
    const json::JsonValue& root = *sink_.documents[static_cast<std::size_t>(doc)].root;
    switch (kind_of(doc, root)) {
      case FileKind::Component: {
        ComponentItem c;
        read_component(doc, root, "", c);
        model_.components.push_back(std::move(c));
        break;
      }
      case FileKind::System: read_system(doc, root, "", false); break;
      case FileKind::Invalid: break;
    }
    stack_.pop_back();
  }

  /// Calls `each(element, its pointer, its index)` for each element of the array `list` (at
  /// `pointer`) that is an object; any other element is an error at it: "`must`, not <its type>".
  template <class Each>
  void for_each_object(int doc, const json::JsonValue& list, const std::string& pointer, const std::string& must,
                       Each&& each) {
    for (std::size_t i = 0; i < list.array.size(); ++i) {
      const json::JsonValue& e = list.array[i];
      const std::string p = pointer_join(pointer, i);
      if (!e.is_object()) {
        sink_.error(Site{doc, e.position, p}, must + ", not " + a_type(e.type));
        continue;
      }
      each(e, p, i);
    }
  }

  void read_system(int doc, const json::JsonValue& root, const std::string& pointer, bool top) {
    Fields f(sink_, doc, root, pointer, system_kind(), named("system", root, "system"));
    if (top) {
      if (const json::JsonValue* n = f.get("system")) model_.name = n->string;
    }
    if (const json::JsonValue* list = f.get("components")) {
      if (top) {
        model_.component_entries = list->array.size();
        model_.has_components_key = true;
      }
      for (std::size_t i = 0; i < list->array.size(); ++i) {
        const json::JsonValue& entry = list->array[i];
        const std::string p = pointer_join(f.pointer("components"), i);
        const Site site{doc, entry.position, p};
        if (!entry.is_object()) {
          sink_.error(site,
                      "a 'components' entry must be an object ({\"include\": \"file.json\"} or a component), not " +
                          a_type(entry.type));
        } else if (entry.find_member("include") != nullptr) {
          include(doc, entry, p);
        } else if (entry.find_member("component") != nullptr) {
          ComponentItem c;
          read_component(doc, entry, p, c);
          model_.components.push_back(std::move(c));
        } else {
          sink_.error(
              site,
              "a 'components' entry must be {\"include\": \"file.json\"} or a component object with \"component\"");
        }
      }
    }
    if (const json::JsonValue* list = f.get("connections")) {
      for_each_object(doc, *list, f.pointer("connections"),
                      "a connection must be an object {\"required\": \"C.r\", \"provided\": \"P.p\"}",
                      [&](const json::JsonValue& entry, const std::string& p, std::size_t) {
                        Fields c(sink_, doc, entry, p, connection_kind(), "connection");
                        ConnectionItem item;
                        item.site = c.object_site();
                        item.required_site = c.site("required");
                        item.provided_site = c.site("provided");
                        const json::JsonValue* r = c.get("required");
                        const json::JsonValue* pr = c.get("provided");
                        if (r != nullptr) item.required = r->string;
                        if (pr != nullptr) item.provided = pr->string;
                        item.complete = r != nullptr && pr != nullptr;
                        model_.connections.push_back(std::move(item));
                      });
    }
    if (const json::JsonValue* list = f.get("hazards")) {
      model_.has_hazards = true;
      for_each_object(doc, *list, f.pointer("hazards"), "a hazard must be an object {\"id\": ..., \"reaction\": {...}}",
                      [&](const json::JsonValue& entry, const std::string& p, std::size_t) {
                        model_.hazards.push_back(read_hazard(doc, entry, p));
                      });
    }
    if (const json::JsonValue* list = f.get("invariants")) {
      for_each_object(doc, *list, f.pointer("invariants"),
                      "an invariant must be an object {\"name\": ..., \"formula\": ...}",
                      [&](const json::JsonValue& entry, const std::string& p, std::size_t) {
                        Fields fi(sink_, doc, entry, p, invariant_kind(), named("invariant", entry, "name"));
                        InvariantItem item;
                        item.site = fi.object_site();
                        item.name_site = fi.site("name");
                        item.formula_site = fi.site("formula");
                        if (const json::JsonValue* n = fi.get("name")) {
                          item.name = n->string;
                          item.has_name = true;
                        }
                        if (const json::JsonValue* t = fi.get("formula")) {
                          item.formula = t->string;
                          item.has_formula = true;
                        }
                        if (const json::JsonValue* d = fi.get("description")) item.description = d->string;
                        model_.invariants.push_back(std::move(item));
                      });
    }
    if (const json::JsonValue* reliability = f.get("reliability"))
      read_reliability(doc, *reliability, f.pointer("reliability"));
    if (const json::JsonValue* coordinators = f.get("coordinators")) {
      const std::string base = f.pointer("coordinators");
      std::set<std::string_view> seen;
      for (const json::JsonMember& m : coordinators->object) {
        const Site key_site{doc, m.key_position, pointer_join(base, m.key)};
        if (!seen.insert(m.key).second) {
          sink_.error(key_site, "coordinators: duplicate key " + quote_name(m.key));
          continue;
        }
        CoordinatorItem item;
        item.name = Name{m.key, key_site};
        const Site value_site{doc, m.value.position, key_site.pointer};
        if (!m.value.is_array()) {
          sink_.error(value_site, "coordinator " + quote_name(m.key) + " must list its components in an array, not " +
                                      a_type(m.value.type));
          continue;
        }
        for (std::size_t i = 0; i < m.value.array.size(); ++i) {
          const json::JsonValue& c = m.value.array[i];
          const Site item_site{doc, c.position, pointer_join(key_site.pointer, i)};
          if (!c.is_string()) {
            sink_.error(item_site, "coordinator " + quote_name(m.key) + ": components are named by strings, not " +
                                       a_type(c.type));
            continue;
          }
          item.components.push_back(Name{c.string, item_site});
        }
        model_.coordinators.push_back(std::move(item));
        model_.has_coordinators = true;
      }
    }
  }

  void read_component(int doc, const json::JsonValue& value, const std::string& pointer, ComponentItem& c) {
    Fields f(sink_, doc, value, pointer, component_kind(), named("component", value, "component"));
    c.site = f.object_site();
    c.name_site = f.site("component");
    if (const json::JsonValue* n = f.get("component")) {
      c.name = n->string;
      c.has_name = true;
    }
    const std::string& ctx = f.context();
    if (const json::JsonValue* interfaces = f.get("interfaces")) {
      c.has_interfaces = true;
      Fields fi(sink_, doc, *interfaces, f.pointer("interfaces"), interfaces_kind(), ctx);
      c.provided = fi.names("provided");
      c.required = fi.names("required");
    }
    if (const json::JsonValue* signals = f.get("signals")) {
      c.has_signals = true;
      for_each_object(
          doc, *signals, f.pointer("signals"), ctx + ": a signal must be an object {\"name\": ..., \"size\": ...}",
          [&](const json::JsonValue& s, const std::string& p, std::size_t) {
            Fields fs(sink_, doc, s, p, signal_kind(), named("signal", s, "name"));
            const json::JsonValue* name = fs.get("name");
            if (name == nullptr) return;
            SignalItem item;
            item.name = name->string.find('.') == std::string::npos ? c.name + "." + name->string : name->string;
            item.site = fs.site("name");
            if (const json::JsonValue* size = fs.get("size")) item.size = static_cast<std::size_t>(size->number);
            c.signals.push_back(std::move(item));
          });
    }
    if (const json::JsonValue* events = f.get("event")) {
      for_each_object(doc, *events, f.pointer("event"), ctx + ": an event must be an object",
                      [&](const json::JsonValue& e, const std::string& p, std::size_t) {
                        c.events.push_back(read_event(doc, e, p, c.name));
                      });
    }
    if (const json::JsonValue* filters = f.get("filter")) {
      for_each_object(doc, *filters, f.pointer("filter"), ctx + ": a filter must be an object",
                      [&](const json::JsonValue& e, const std::string& p, std::size_t) {
                        c.filters.push_back(read_filter_entry(doc, e, p, c.name));
                      });
    }
    if (const json::JsonValue* services = f.get("service")) {
      for_each_object(doc, *services, f.pointer("service"), ctx + ": a service must be an object",
                      [&](const json::JsonValue& s, const std::string& p, std::size_t) {
                        Fields fs(sink_, doc, s, p, service_kind(), named("service", s, "name"));
                        ServiceItem item;
                        item.site = fs.object_site();
                        item.name_site = fs.site("name");
                        if (const json::JsonValue* n = fs.get("name")) {
                          item.provided = n->string;
                          item.has_name = true;
                        }
                        if (const json::JsonValue* d = fs.get("dependency")) {
                          Fields fd(sink_, doc, *d, fs.pointer("dependency"), dependency_kind(),
                                    fs.context() + " dependency");
                          ServiceDependency dep = ServiceDependency::provided_only();
                          if (const json::JsonValue* b = fd.get("s_F")) dep.framework = b->boolean;
                          if (const json::JsonValue* b = fd.get("s_A")) dep.application = b->boolean;
                          item.required = fd.names("s_R");
                          for (const Name& r : item.required) dep.required.push_back(r.text);
                          item.dependency = std::move(dep);
                        }
                        if (const json::JsonValue* pr = fs.get("propagate")) {
                          item.dependency.propagate = pr->string == "warning" ? State::Warning : State::Error;
                        }
                        c.services.push_back(std::move(item));
                      });
    }
    if (const json::JsonValue* period = f.get("period")) c.period = period->number;
  }

  /// One entry of a component's "filter" list: a filter, or a pipeline of them.
  FilterEntryItem read_filter_entry(int doc, const json::JsonValue& e, const std::string& p,
                                    const std::string& component) {
    FilterEntryItem entry;
    entry.site = Site{doc, e.position, p};
    if (e.find_member("pipeline") == nullptr) {
      entry.stages.push_back(read_filter(doc, e, p, component, TargetDefault{}));
      return entry;
    }
    Fields fp(sink_, doc, e, p, pipeline_kind(), named("pipeline", e, "name"));
    entry.name_site = fp.site("name");
    const json::JsonValue* n = fp.get("name");
    entry.pipeline = n != nullptr ? n->string : "?";
    TargetDefault target;
    if (const json::JsonValue* t = fp.get("target")) {
      target = read_target(doc, *t, fp.pointer("target"), fp.context(), component);
    }
    if (const json::JsonValue* stages = fp.get("pipeline")) {
      for_each_object(doc, *stages, fp.pointer("pipeline"), fp.context() + ": a stage must be a filter object",
                      [&](const json::JsonValue& s, const std::string& sp, std::size_t k) {
                        FilterItem stage = read_filter(doc, s, sp, component, target);
                        stage.pipeline = entry.pipeline;
                        stage.stage = k;
                        entry.stages.push_back(std::move(stage));
                      });
    }
    return entry;
  }

  /// The "reliability" section: the mission time, and per failure mode name its rate or
  /// probability (the names and the one-of rule are checked by the validator).
  void read_reliability(int doc, const json::JsonValue& e, const std::string& pointer) {
    Fields f(sink_, doc, e, pointer, reliability_kind(), "reliability");
    if (model_.reliability) {
      sink_.error(f.object_site(), "reliability: a second \"reliability\" section (a system has one)");
      return;
    }
    ReliabilityItem item;
    item.site = f.object_site();
    if (const json::JsonValue* t = f.get("mission_time")) item.mission_time = t->number;
    if (const json::JsonValue* modes = f.get("modes")) {
      const std::string base = f.pointer("modes");
      std::set<std::string_view> seen;
      for (const json::JsonMember& m : modes->object) {
        const Site key_site{doc, m.key_position, pointer_join(base, m.key)};
        if (!seen.insert(m.key).second) {
          sink_.error(key_site, "reliability: duplicate failure mode " + quote_name(m.key));
          continue;
        }
        const Site value_site{doc, m.value.position, key_site.pointer};
        if (!m.value.is_object()) {
          sink_.error(value_site, "reliability: failure mode " + quote_name(m.key) +
                                      " must be an object {\"rate\": per hour} or {\"probability\": p}, not " +
                                      a_type(m.value.type));
          continue;
        }
        Fields r(sink_, doc, m.value, key_site.pointer, mode_rate_kind(), "reliability of " + quote_name(m.key));
        ReliabilityItem::Mode mode{m.key, {}, {}, 0, key_site, value_site};
        mode.given = (m.value.find("rate") != nullptr ? 1 : 0) + (m.value.find("probability") != nullptr ? 1 : 0);
        if (const json::JsonValue* rate = r.get("rate")) mode.rate = rate->number;
        if (const json::JsonValue* p = r.get("probability")) mode.probability = p->number;
        item.modes.push_back(std::move(mode));
      }
    }
    model_.reliability = std::move(item);
  }

  HazardItem read_hazard(int doc, const json::JsonValue& e, const std::string& pointer) {
    Fields f(sink_, doc, e, pointer, hazard_kind(), named("hazard", e, "id"));
    HazardItem item;
    item.site = f.object_site();
    item.id_site = f.site("id");
    if (const json::JsonValue* n = f.get("id")) {
      item.id = n->string;
      item.has_id = true;
    }
    if (const json::JsonValue* d = f.get("description")) item.description = d->string;
    if (const json::JsonValue* r = f.get("reaction")) {
      const std::string base = f.pointer("reaction");
      std::set<std::string_view> seen;
      for (const json::JsonMember& m : r->object) {
        const Site key_site{doc, m.key_position, pointer_join(base, m.key)};
        if (!seen.insert(m.key).second) {
          sink_.error(key_site, f.context() + ": reaction: duplicate address " + quote_name(m.key));
          continue;
        }
        const Site value_site{doc, m.value.position, key_site.pointer};
        if (!m.value.is_string()) {
          sink_.error(value_site, f.context() + ": reaction of " + quote_name(m.key) +
                                      " must be a level (\"Warning\" or \"Error\"), not " + a_type(m.value.type));
          continue;
        }
        item.reaction.push_back(HazardItem::Reaction{m.key, m.value.string, key_site, value_site});
      }
    }
    return item;
  }

  EventItem read_event(int doc, const json::JsonValue& e, const std::string& pointer, const std::string& component) {
    Fields f(sink_, doc, e, pointer, event_kind(), named("event", e, "name"));
    EventItem item;
    item.component = component;
    item.site = f.object_site();
    item.name_site = f.site("name");
    item.severity_site = f.site("severity");
    item.transitions_site = f.site("state_transition");
    item.completes_site = f.site("completes");
    item.latched_site = f.site("latched");
    item.hazard_site = f.site("hazard");
    if (const json::JsonValue* n = f.get("name")) {
      item.def.name = n->string;
      item.has_name = true;
    }
    if (const json::JsonValue* s = f.get("severity")) {
      item.def.severity = static_cast<int>(s->number);  // range checked: 1-255
      item.has_severity = true;
    }
    if (const json::JsonValue* t = f.get("state_transition")) {
      item.has_transitions = true;
      for (const json::JsonValue& x : t->array) {
        const auto tr = x.is_string() ? parse_transition(x.string) : std::nullopt;
        if (tr)
          item.def.transitions.insert(*tr);
        else
          item.transitions_valid = false;
      }
    } else if (f.has("state_transition")) {
      item.transitions_valid = false;
    }
    if (const json::JsonValue* c = f.get("completes")) item.def.completes = c->string;
    if (const json::JsonValue* l = f.get("latched")) item.def.latched = l->boolean;
    if (const json::JsonValue* h = f.get("hazard")) item.def.hazard = h->string;
    if (const json::JsonValue* d = f.get("description")) item.def.description = d->string;
    return item;
  }

  TargetDefault read_target(int doc, const json::JsonValue& t, const std::string& pointer, const std::string& context,
                            const std::string& owner) {
    Fields f(sink_, doc, t, pointer, target_kind(), context + " target");
    TargetDefault out;
    out.given = true;
    out.site = f.object_site();
    out.type_site = f.site("type");
    out.component_site = f.site("component");
    out.interface_site = f.site("interface");
    out.target.component = owner;
    if (const json::JsonValue* type = f.get("type")) {
      const std::string& s = type->string;
      out.target.kind = s == "s_F"   ? MachineKind::Framework
                        : s == "s_P" ? MachineKind::Provided
                        : s == "s_R" ? MachineKind::Required
                                     : MachineKind::Application;
    }
    if (const json::JsonValue* c = f.get("component")) {
      out.target.component = c->string;
      out.component_given = true;
    }
    if (const json::JsonValue* i = f.get("interface")) {
      out.target.interface = i->string;
      out.has_interface = true;
    }
    return out;
  }

  FilterItem read_filter(int doc, const json::JsonValue& e, const std::string& pointer, const std::string& owner,
                         const TargetDefault& inherited) {
    Fields f(sink_, doc, e, pointer, filter_kind(), named("filter", e, "name"));
    FilterItem item;
    item.owner = owner;
    item.site = f.object_site();
    item.name_site = f.site("name");
    item.class_site = f.site("class_name");
    if (const json::JsonValue* n = f.get("name")) {
      item.config.name = n->string;
      item.named = true;
    }
    if (const json::JsonValue* c = f.get("class_name")) {
      item.config.type = c->string;
      item.has_class = true;
    }
    if (f.get("type") != nullptr) {
      item.config.execution = f.choice("type") == "PASSIVE" ? ExecutionMode::Passive : ExecutionMode::Active;
    }
    if (f.get("event_type") != nullptr) {
      item.config.detection = f.choice("event_type") == "LEVEL" ? DetectionMode::Level : DetectionMode::Edge;
    }
    // A misspelled "argument" is reported once, as the unknown key: the parameters it holds are
    // then not reported missing as well.
    for (const json::JsonMember& m : e.object) {
      if (filter_kind().find(m.key) != nullptr) continue;
      if (m.key == "Arguments" || nearest(m.key, {"argument"}).has_value()) {
        item.argument_misspelled = true;
        item.misspelled_argument = &m.value;
      }
    }
    if (const json::JsonValue* b = f.get("enabled")) item.config.enabled = b->boolean;
    TargetDefault target = inherited;
    if (const json::JsonValue* t = f.get("target"))
      target = read_target(doc, *t, f.pointer("target"), f.context(), owner);
    if (target.given) {
      item.config.target = target.target;
      item.target_site = target.site;
      item.target_type_site = target.type_site;
      item.target_component_site = target.component_site;
      item.target_interface_site = target.interface_site;
      item.target_component_given = target.component_given;
      item.has_target_interface = target.has_interface;
    } else {
      item.config.target.kind = MachineKind::Application;
      item.config.target.component = owner;
      item.target_site = item.target_type_site = item.target_component_site = item.target_interface_site = item.site;
    }
    item.argument_site = f.site("argument");
    if (const json::JsonValue* a = f.get("argument")) {
      std::set<std::string_view> seen;
      const std::string base = f.pointer("argument");
      for (const json::JsonMember& m : a->object) {
        const Site key_site{doc, m.key_position, pointer_join(base, m.key)};
        if (!seen.insert(m.key).second) {
          sink_.error(key_site, f.context() + ": duplicate parameter " + quote_name(m.key));
          continue;
        }
        item.params.push_back(ParamItem{m.key, key_site, Site{doc, m.value.position, key_site.pointer}, &m.value, {}});
      }
    }
    return item;
  }

  Sink& sink_;
  Model& model_;
  std::vector<std::pair<std::string, std::string>> stack_;  ///< canonical path, path as opened
  std::map<int, Site> included_at_;
  std::map<std::string, int, std::less<>> loaded_;  ///< canonical path -> document
};

}  // namespace

void read_files(const std::string& path, const std::string* text, Sink& sink, Model& model) {
  Reader(sink, model).run(path, text);
}

}  // namespace safecass::spec
