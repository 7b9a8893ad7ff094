#include "safecass/filters/params.hpp"
#include "safecass/core/text.hpp"

#include <cmath>
#include <cstdio>

namespace safecass {

std::string_view to_string(ParamType t) noexcept {
  switch (t) {
    case ParamType::Number: return "number";
    case ParamType::Integer: return "integer";
    case ParamType::Bool: return "boolean";
    case ParamType::String: return "string";
    case ParamType::Choice: return "choice";
    case ParamType::Signal: return "signal";
    case ParamType::SignalList: return "signal list";
    case ParamType::Event: return "event";
    case ParamType::NumberList: return "number list";
  }
  return "?";
}

ParamSpec ParamSpec::number(std::string name, std::string doc, std::optional<double> def, double min, double max) {
  ParamSpec p;
  p.name = std::move(name);
  p.type = ParamType::Number;
  p.doc = std::move(doc);
  if (def) p.default_value = *def;
  p.min = min;
  p.max = max;
  return p;
}

ParamSpec ParamSpec::integer(std::string name, std::string doc, std::optional<double> def, double min, double max) {
  ParamSpec p = number(std::move(name), std::move(doc), def, min, max);
  p.type = ParamType::Integer;
  return p;
}

ParamSpec ParamSpec::boolean(std::string name, std::string doc, bool def) {
  ParamSpec p;
  p.name = std::move(name);
  p.type = ParamType::Bool;
  p.doc = std::move(doc);
  p.default_value = def;
  return p;
}

ParamSpec ParamSpec::choice(std::string name, std::string doc, std::vector<std::string> choices, std::string def) {
  ParamSpec p;
  p.name = std::move(name);
  p.type = ParamType::Choice;
  p.doc = std::move(doc);
  p.choices = std::move(choices);
  p.default_value = std::move(def);
  return p;
}

ParamSpec ParamSpec::signal(std::string name, std::string doc, bool optional) {
  ParamSpec p;
  p.name = std::move(name);
  p.type = ParamType::Signal;
  p.doc = std::move(doc);
  p.optional = optional;
  return p;
}

ParamSpec ParamSpec::signals(std::string name, std::string doc, bool optional) {
  ParamSpec p = signal(std::move(name), std::move(doc), optional);
  p.type = ParamType::SignalList;
  return p;
}

ParamSpec ParamSpec::event(std::string name, std::string doc, std::optional<std::string> def, bool optional) {
  ParamSpec p;
  p.name = std::move(name);
  p.type = ParamType::Event;
  p.doc = std::move(doc);
  if (def) p.default_value = *def;
  p.optional = optional;
  return p;
}

const ParamSpec* FilterManifest::find(std::string_view name) const noexcept {
  for (const ParamSpec& p : params) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

namespace {

std::string describe(const ParamValue& v) {
  switch (v.index()) {
    case 0: return "a number";
    case 1: return "a boolean";
    case 2: return "a string";
    case 3: return "a list of strings";
    case 4: return "a list of numbers";
  }
  return "a value";
}

}  // namespace

std::string_view FilterManifest::canonical(std::string_view name) const noexcept {
  for (const auto& [alias, param] : aliases) {
    if (alias == name) return param;
  }
  return name;
}

std::string default_output_name(std::string_view filter, std::string_view component) {
  std::string_view bare = filter;
  if (bare.size() > component.size() && bare.substr(0, component.size()) == component &&
      bare[component.size()] == '.') {
    bare.remove_prefix(component.size() + 1);
  }
  std::string out(component);
  out += '.';
  for (const char c : bare) out += c == '.' ? '_' : c;
  return out;
}

[[nodiscard]] Expected<Params> check_params(const FilterManifest& manifest, const Params& given_as_written,
                                            std::string_view filter) {
  const std::string where = "filter '" + std::string(filter) + "' (" + manifest.type + ")";
  // Aliases (the 2016 names) stand for their parameter; both at once is ambiguous.
  Params renamed;
  const Params* given_ptr = &given_as_written;
  if (!manifest.aliases.empty()) {
    for (const auto& [name, value] : given_as_written) {
      const std::string_view canonical = manifest.canonical(name);
      if (canonical != name && given_as_written.count(canonical) > 0) {
        return fail(ErrorCode::InvalidArgument, where + ": parameters '" + name + "' and '" + std::string(canonical) +
                                                    "' are the same parameter; give one");
      }
      renamed.emplace(std::string(canonical), value);
    }
    given_ptr = &renamed;
  }
  const Params& given = *given_ptr;
  for (const auto& [name, value] : given) {
    if (manifest.find(name) == nullptr) {
      std::string known;
      for (const ParamSpec& p : manifest.params) known += (known.empty() ? "" : ", ") + p.name;
      return fail(ErrorCode::InvalidArgument, where + ": unknown parameter '" + name + "' (known: " + known + ")");
    }
  }
  Params out;
  for (const ParamSpec& spec : manifest.params) {
    const auto it = given.find(spec.name);
    if (it == given.end()) {
      if (spec.default_value) {
        out.emplace(spec.name, *spec.default_value);
      } else if (!spec.optional) {
        return fail(ErrorCode::InvalidArgument, where + ": missing parameter '" + spec.name + "' (" + spec.doc + ")");
      }
      continue;
    }
    const ParamValue& v = it->second;
    const std::string bad = where + ": parameter '" + spec.name + "' must be ";
    switch (spec.type) {
      case ParamType::Number:
      case ParamType::Integer: {
        const double* d = std::get_if<double>(&v);
        if (d == nullptr)
          return fail(ErrorCode::InvalidArgument, bad + to_string(spec.type).data() + ", not " + describe(v));
        if (!std::isfinite(*d)) return fail(ErrorCode::InvalidArgument, bad + "finite");
        if (spec.type == ParamType::Integer && std::floor(*d) != *d) {
          return fail(ErrorCode::InvalidArgument, bad + "a whole number, not " + number_text(*d));
        }
        if (*d < spec.min || *d > spec.max) {
          return fail(ErrorCode::InvalidArgument, bad + "within [" + number_text(spec.min) + ", " +
                                                      number_text(spec.max) + "], not " + number_text(*d));
        }
        break;
      }
      case ParamType::Bool:
        if (!std::holds_alternative<bool>(v))
          return fail(ErrorCode::InvalidArgument, bad + "a boolean, not " + describe(v));
        break;
      case ParamType::String:
      case ParamType::Signal:
      case ParamType::Event:
        if (!std::holds_alternative<std::string>(v) || std::get<std::string>(v).empty()) {
          return fail(ErrorCode::InvalidArgument,
                      bad + "a non-empty string (" + std::string(to_string(spec.type)) + "), not " + describe(v));
        }
        break;
      case ParamType::Choice: {
        const std::string* s = std::get_if<std::string>(&v);
        bool ok = false;
        std::string list;
        for (const std::string& c : spec.choices) {
          ok = ok || (s != nullptr && *s == c);
          list += (list.empty() ? "" : ", ") + c;
        }
        if (!ok) return fail(ErrorCode::InvalidArgument, bad + "one of " + list);
        break;
      }
      case ParamType::SignalList: {
        const auto* l = std::get_if<std::vector<std::string>>(&v);
        if (l == nullptr || l->empty()) {
          return fail(ErrorCode::InvalidArgument, bad + "a non-empty list of signal names, not " + describe(v));
        }
        break;
      }
      case ParamType::NumberList:
        if (!std::holds_alternative<std::vector<double>>(v)) {
          return fail(ErrorCode::InvalidArgument, bad + "a list of numbers, not " + describe(v));
        }
        break;
    }
    out.emplace(spec.name, v);
  }
  return out;
}

}  // namespace safecass
