#include "safecass/spec/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <optional>

#include "safecass/core/assert.hpp"
#include "safecass/core/state.hpp"
#include "safecass/json/read.hpp"
#include "safecass/spec/file.hpp"

#include "text.hpp"

namespace safecass::spec {

bool read_file(const std::string& path, std::string& out, std::string& error) {
  auto text = read_regular_file(path);
  if (!text) {
    error = text.error().message;
    return false;
  }
  out = std::move(*text);
  return true;
}

// ---- SampleList ------------------------------------------------------------------------------

namespace {

constexpr std::size_t kWord = sizeof(double);

void put_counts(double* word, std::uint32_t a, std::uint32_t b) noexcept {
  const std::uint32_t pair[2] = {a, b};
  static_assert(sizeof pair == kWord);
  std::memcpy(word, pair, kWord);
}

void get_counts(const double* word, std::uint32_t& a, std::uint32_t& b) noexcept {
  std::uint32_t pair[2];
  std::memcpy(pair, word, kWord);
  a = pair[0];
  b = pair[1];
}

std::size_t name_words(std::size_t length) noexcept { return (length + kWord - 1) / kWord; }

template <class Samples>
std::unique_ptr<double[]> build_block(const Samples& samples) {
  if (samples.size() == 0) return nullptr;
  std::size_t words = 1;
  for (const auto& [name, values] : samples) words += 1 + name_words(name.size()) + values.size();
  if (samples.size() > std::numeric_limits<std::uint32_t>::max() || words > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("SampleList: too many samples");
  }
  std::unique_ptr<double[]> block(new double[words]());
  double* at = block.get();
  put_counts(at++, static_cast<std::uint32_t>(samples.size()), static_cast<std::uint32_t>(words));
  for (const auto& [name, values] : samples) {
    put_counts(at++, static_cast<std::uint32_t>(name.size()), static_cast<std::uint32_t>(values.size()));
    std::memcpy(at, name.data(), name.size());
    at += name_words(name.size());
    for (const double v : values) *at++ = v;
  }
  return block;
}

}  // namespace

SampleList::SampleList(const std::vector<std::pair<std::string_view, std::vector<double>>>& samples)
    : block_(build_block(samples)) {}

SampleList::SampleList(std::initializer_list<std::pair<std::string_view, std::vector<double>>> samples)
    : block_(build_block(samples)) {}

SampleList::SampleList(const SampleList& other) { *this = other; }

SampleList& SampleList::operator=(const SampleList& other) {
  if (this == &other) return *this;
  if (other.block_ == nullptr) {
    block_.reset();
    return *this;
  }
  std::uint32_t count = 0;
  std::uint32_t words = 0;
  get_counts(other.block_.get(), count, words);
  std::unique_ptr<double[]> copy(new double[words]);
  std::memcpy(copy.get(), other.block_.get(), words * kWord);
  block_ = std::move(copy);
  return *this;
}

std::size_t SampleList::size() const noexcept {
  if (block_ == nullptr) return 0;
  std::uint32_t count = 0;
  std::uint32_t words = 0;
  get_counts(block_.get(), count, words);
  return count;
}

SampleList::const_iterator SampleList::begin() const noexcept {
  const std::size_t n = size();
  return n == 0 ? end() : const_iterator(block_.get() + 1, n);
}

Sample SampleList::const_iterator::operator*() const noexcept {
  std::uint32_t length = 0;
  std::uint32_t values = 0;
  get_counts(at_, length, values);
  const char* name = reinterpret_cast<const char*>(at_ + 1);
  return Sample{std::string_view(name, length), SampleValues(at_ + 1 + name_words(length), values)};
}

SampleList::const_iterator& SampleList::const_iterator::operator++() noexcept {
  std::uint32_t length = 0;
  std::uint32_t values = 0;
  get_counts(at_, length, values);
  at_ += 1 + name_words(length) + values;
  if (--left_ == 0) at_ = nullptr;
  return *this;
}

std::string_view step_key(ScenarioStep::Kind kind) noexcept {
  switch (kind) {
    case ScenarioStep::Kind::Sample: return "sample";
    case ScenarioStep::Kind::Ramp: return "ramp";
    case ScenarioStep::Kind::Generate: return "generate";
    case ScenarioStep::Kind::Inject: return "inject";
    case ScenarioStep::Kind::Reset: return "reset";
    case ScenarioStep::Kind::Expect: return "expect";
    case ScenarioStep::Kind::ExpectOutstanding: return "expect_outstanding";
    case ScenarioStep::Kind::ExpectCause: return "expect_cause";
  }
  return "?";
}

std::string ScenarioStep::pointer() const {
  return "/steps/" + std::to_string(index) + "/" + std::string(step_key(kind));
}

namespace {

/// Every step kind, in the order of ScenarioStep::Kind.
constexpr ScenarioStep::Kind kKinds[] = {ScenarioStep::Kind::Sample,
                                         ScenarioStep::Kind::Ramp,
                                         ScenarioStep::Kind::Generate,
                                         ScenarioStep::Kind::Inject,
                                         ScenarioStep::Kind::Reset,
                                         ScenarioStep::Kind::Expect,
                                         ScenarioStep::Kind::ExpectOutstanding,
                                         ScenarioStep::Kind::ExpectCause};
static_assert(std::size(kKinds) == static_cast<std::size_t>(ScenarioStep::Kind::ExpectCause) + 1,
              "a step kind is missing from kKinds");

}  // namespace

const std::vector<ScenarioKeySet>& scenario_keys() {
  static const std::vector<ScenarioKeySet> table = [] {
    std::vector<std::string_view> step{"at"};
    for (const ScenarioStep::Kind k : kKinds) step.push_back(step_key(k));
    return std::vector<ScenarioKeySet>{
        {"scenario", {"system", "period", "duration", "steps", "description"}},
        {"step", std::move(step)},
        {step_key(ScenarioStep::Kind::Ramp), {"signal", "from", "to", "until"}},
        {step_key(ScenarioStep::Kind::Generate), {"event", "target"}},
        {step_key(ScenarioStep::Kind::Inject), {"filter", "signal", "deep", "values"}},
        {step_key(ScenarioStep::Kind::Reset), {"target", "reason"}},
    };
  }();
  return table;
}

// ---- reading a scenario ------------------------------------------------------------------------

namespace {

/// The keys of `object` in scenario_keys().
const std::vector<std::string_view>& keys_of(std::string_view object) {
  for (const ScenarioKeySet& set : scenario_keys()) {
    if (set.object == object) return set.keys;
  }
  SAFECASS_ASSERT(false && "an object that scenario_keys() does not list");
  static const std::vector<std::string_view> none;
  return none;
}

/// The step kind whose key is `key`, if any.
std::optional<ScenarioStep::Kind> kind_of(std::string_view key) noexcept {
  for (const ScenarioStep::Kind k : kKinds) {
    if (step_key(k) == key) return k;
  }
  return std::nullopt;
}

class Reader {
public:
  Reader(std::string file, std::vector<Diagnostic>& out) : file_(std::move(file)), out_(out) {}

  void error(const json::TextPosition& p, const std::string& pointer, std::string message) {
    out_.push_back(
        Diagnostic{Diagnostic::Severity::Error, Position{file_, p.line, p.column}, std::move(message), pointer});
  }

  bool number(const json::JsonValue& v, const std::string& pointer, const char* what, double& out) {
    if (!v.is_number()) {
      error(v.position, pointer, std::string(what) + " must be a number, not " + std::string(json::type_name(v.type)));
      return false;
    }
    out = v.number;
    return true;
  }
  bool text(const json::JsonValue& v, const std::string& pointer, const char* what, std::string& out) {
    if (!v.is_string() || v.string.empty()) {
      error(v.position, pointer, std::string(what) + " must be a non-empty string");
      return false;
    }
    out = v.string;
    return true;
  }
  /// A number or a list of numbers.
  bool values(const json::JsonValue& v, const std::string& pointer, std::vector<double>& out) {
    if (v.is_number()) {
      out = {v.number};
      return true;
    }
    if (v.is_array() && !v.array.empty()) {
      for (std::size_t i = 0; i < v.array.size(); ++i) {
        if (!v.array[i].is_number()) {
          error(v.array[i].position, pointer + "/" + std::to_string(i), "sample values must be numbers");
          return false;
        }
        out.push_back(v.array[i].number);
      }
      return true;
    }
    error(v.position, pointer, "a sample must be a number or a non-empty list of numbers");
    return false;
  }
  /// Reports the keys of `obj` that are not those of `object` in scenario_keys(), with the
  /// nearest known one; returns the known keys suggested, so that a typo of a required key is not
  /// also reported missing.
  std::vector<std::string> unknown_keys(const json::JsonValue& obj, const std::string& pointer,
                                        std::string_view object) {
    const std::vector<std::string_view>& known = keys_of(object);
    std::vector<std::string> suggested;
    for (const json::JsonMember& m : obj.object) {
      if (std::find(known.begin(), known.end(), m.key) == known.end()) {
        std::string list;
        std::vector<std::string> candidates;
        for (std::string_view k : known) {
          list += (list.empty() ? "" : ", ") + std::string(k);
          candidates.emplace_back(k);
        }
        const std::string suggestion = did_you_mean(m.key, candidates);
        error(m.key_position, pointer + "/" + m.key,
              "unknown key \"" + m.key + "\"" + (suggestion.empty() ? " (expected one of: " + list + ")" : suggestion));
        if (const auto near = nearest(m.key, candidates)) suggested.push_back(*near);
      }
    }
    return suggested;
  }

  std::string file_;
  std::vector<Diagnostic>& out_;
};

/// Seconds as written in messages: "0.5", "0.001", "12".
std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

std::string escape_pointer(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

bool read_sample(Reader& r, const json::JsonValue& v, const std::string& p, ScenarioStep& s) {
  if (!v.is_object() || v.object.empty()) {
    r.error(v.position, p, "\"sample\" must be an object of signal: value");
    return false;
  }
  bool ok = true;
  std::vector<std::pair<std::string_view, std::vector<double>>> samples;
  samples.reserve(v.object.size());
  for (const json::JsonMember& sm : v.object) {
    std::vector<double> vals;
    ok = r.values(sm.value, p + "/" + escape_pointer(sm.key), vals) && ok;
    samples.emplace_back(sm.key, std::move(vals));
  }
  if (ok) s.samples = SampleList(samples);
  return ok;
}

bool read_ramp(Reader& r, const json::JsonValue& v, const std::string& p, double when, StepAction& a) {
  if (!v.is_object()) {
    r.error(v.position, p, "\"ramp\" must be an object {signal, from, to, until}");
    return false;
  }
  const auto typos = r.unknown_keys(v, p, step_key(ScenarioStep::Kind::Ramp));
  const json::JsonValue* sig = v.find("signal");
  const json::JsonValue* from = v.find("from");
  const json::JsonValue* to = v.find("to");
  const json::JsonValue* until = v.find("until");
  if (sig == nullptr || from == nullptr || to == nullptr || until == nullptr) {
    const auto typo = [&](const char* k) { return std::find(typos.begin(), typos.end(), k) != typos.end(); };
    const bool all_typos = (sig != nullptr || typo("signal")) && (from != nullptr || typo("from")) &&
                           (to != nullptr || typo("to")) && (until != nullptr || typo("until"));
    if (!all_typos) r.error(v.position, p, "\"ramp\" needs signal, from, to and until");
    return false;
  }
  bool ok = r.text(*sig, p + "/signal", "\"signal\"", a.signal);
  ok = r.number(*from, p + "/from", "\"from\"", a.from) && ok;
  ok = r.number(*to, p + "/to", "\"to\"", a.to) && ok;
  ok = r.number(*until, p + "/until", "\"until\"", a.until) && ok;
  if (ok && a.until < when) {
    r.error(until->position, p + "/until", "\"until\" must not be before \"at\"");
    return false;
  }
  return ok;
}

bool read_generate(Reader& r, const json::JsonValue& v, const std::string& p, StepAction& a) {
  if (!v.is_object()) {
    r.error(v.position, p, "\"generate\" must be an object {event, target}");
    return false;
  }
  const auto typos = r.unknown_keys(v, p, step_key(ScenarioStep::Kind::Generate));
  const json::JsonValue* e = v.find("event");
  const json::JsonValue* t = v.find("target");
  if (e == nullptr) {
    if (std::find(typos.begin(), typos.end(), "event") == typos.end())
      r.error(v.position, p, "\"generate\" needs \"event\"");
    return false;
  }
  bool ok = r.text(*e, p + "/event", "\"event\"", a.event);
  if (t != nullptr) ok = r.text(*t, p + "/target", "\"target\"", a.target) && ok;
  return ok;
}

bool read_inject(Reader& r, const json::JsonValue& v, const std::string& p, StepAction& a) {
  if (!v.is_object()) {
    r.error(v.position, p, "\"inject\" must be an object {filter|signal, deep, values}");
    return false;
  }
  const auto typos = r.unknown_keys(v, p, step_key(ScenarioStep::Kind::Inject));
  const auto typo = [&](const char* k) { return std::find(typos.begin(), typos.end(), k) != typos.end(); };
  const json::JsonValue* f = v.find("filter");
  const json::JsonValue* sig = v.find("signal");
  const json::JsonValue* deep = v.find("deep");
  const json::JsonValue* vals = v.find("values");
  if ((f == nullptr) == (sig == nullptr)) {
    if (f != nullptr || !(typo("filter") || typo("signal"))) {
      r.error(v.position, p, "\"inject\" needs exactly one of \"filter\" or \"signal\"");
    }
    return false;
  }
  bool ok = true;
  if (f != nullptr) ok = r.text(*f, p + "/filter", "\"filter\"", a.filter) && ok;
  if (sig != nullptr) ok = r.text(*sig, p + "/signal", "\"signal\"", a.signal) && ok;
  if (deep != nullptr) {
    if (!deep->is_bool()) {
      r.error(deep->position, p + "/deep", "\"deep\" must be true or false");
      ok = false;
    } else {
      a.deep = deep->boolean;
    }
  }
  if (sig != nullptr && !a.deep) {
    r.error(sig->position, p + "/signal", "a shallow injection goes into a filter: use \"filter\", or \"deep\": true");
    ok = false;
  }
  if (vals == nullptr || !vals->is_array() || vals->array.empty()) {
    if (vals != nullptr || !typo("values")) {
      r.error(vals == nullptr ? v.position : vals->position, p + "/values",
              "\"values\" must be a non-empty list of samples");
    }
    return false;
  }
  for (std::size_t i = 0; i < vals->array.size(); ++i) {
    std::vector<double> sample;
    ok = r.values(vals->array[i], p + "/values/" + std::to_string(i), sample) && ok;
    a.values.push_back(std::move(sample));
  }
  return ok;
}

bool read_reset(Reader& r, const json::JsonValue& v, const std::string& p, StepAction& a) {
  if (!v.is_object()) {
    r.error(v.position, p, "\"reset\" must be an object {target, reason}");
    return false;
  }
  const auto typos = r.unknown_keys(v, p, step_key(ScenarioStep::Kind::Reset));
  const json::JsonValue* t = v.find("target");
  const json::JsonValue* why = v.find("reason");
  if (t == nullptr) {
    if (std::find(typos.begin(), typos.end(), "target") == typos.end())
      r.error(v.position, p, "\"reset\" needs \"target\"");
    return false;
  }
  bool ok = r.text(*t, p + "/target", "\"target\"", a.target);
  a.reason = "scenario";
  if (why != nullptr) ok = r.text(*why, p + "/reason", "\"reason\"", a.reason) && ok;
  return ok;
}

/// "expect", "expect_outstanding" (`key`) or "expect_cause": an object of address: expected value.
bool read_expectations(Reader& r, const json::JsonValue& v, const std::string& p, const std::string& key,
                       ScenarioStep::Kind kind, StepAction& a) {
  if (!v.is_object() || v.object.empty()) {
    r.error(v.position, p, "\"" + key + "\" must be an object of address: expected value");
    return false;
  }
  bool ok = true;
  for (const json::JsonMember& em : v.object) {
    std::string expected;
    if (!r.text(em.value, p + "/" + escape_pointer(em.key), "an expectation", expected)) {
      ok = false;
      continue;
    }
    if (kind == ScenarioStep::Kind::Expect && !parse_state(expected)) {
      r.error(em.value.position, p + "/" + escape_pointer(em.key),
              "expected state must be Normal, Warning or Error, not \"" + expected + "\"");
      ok = false;
      continue;
    }
    if (kind == ScenarioStep::Kind::ExpectCause && expected.find(':') == std::string::npos) {
      r.error(em.value.position, p + "/" + escape_pointer(em.key),
              "a cause is written \"Component.s_X:EVENT\", not \"" + expected + "\"");
      ok = false;
      continue;
    }
    a.expectations.emplace_back(em.key, expected);
  }
  return ok;
}

/// The keys of the step kinds, for messages and suggestions.
const std::vector<std::string>& action_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (const ScenarioStep::Kind k : kKinds) out.emplace_back(step_key(k));
    return out;
  }();
  return keys;
}

/// The step's "at" (seconds, not negative) into `when`; false (reported) when it has none.
bool read_at(Reader& r, const json::JsonValue& step, const std::string& base, double& when) {
  const json::JsonValue* at = step.find("at");
  if (at == nullptr) {
    // A misspelled "at" is one error, the unknown key with its suggestion.
    for (const json::JsonMember& m : step.object) {
      if (kind_of(m.key)) continue;
      if (nearest(m.key, {"at"})) {
        r.error(m.key_position, base + "/" + escape_pointer(m.key),
                "unknown key \"" + m.key + "\"; did you mean 'at'?");
        return false;
      }
    }
    r.error(step.position, base, "step needs \"at\" (seconds)");
    return false;
  }
  if (!r.number(*at, base + "/at", "\"at\"", when)) return false;
  if (when < 0) {
    r.error(at->position, base + "/at", "\"at\" must not be negative");
    return false;
  }
  return true;
}

void read_step(Reader& r, const json::JsonValue& step, std::size_t index, std::deque<ScenarioStep>& steps) {
  const std::string base = "/steps/" + std::to_string(index);
  if (!step.is_object()) {
    r.error(step.position, base, "a step must be an object with \"at\" and one action");
    return;
  }
  double when = 0.0;
  if (!read_at(r, step, base, when)) return;
  int actions = 0;
  bool unknown_action = false;
  for (const json::JsonMember& m : step.object) {
    if (m.key == "at") continue;
    const std::optional<ScenarioStep::Kind> kind = kind_of(m.key);
    if (!kind) {
      const std::string suggestion = did_you_mean(m.key, action_keys());
      r.error(m.key_position, base + "/" + escape_pointer(m.key),
              "unknown step action \"" + m.key + "\"" +
                  (suggestion.empty() ? " (expected " + join_or(action_keys()) + ")" : suggestion));
      unknown_action = true;
      continue;
    }
    ++actions;
    const std::string p = base + "/" + m.key;
    const json::JsonValue& v = m.value;
    ScenarioStep s;
    s.at = when;
    s.index = static_cast<std::uint32_t>(index);
    s.line = v.position.line;
    s.column = v.position.column;
    s.kind = *kind;
    StepAction a;
    bool ok = true;
    switch (s.kind) {
      case ScenarioStep::Kind::Sample: ok = read_sample(r, v, p, s); break;
      case ScenarioStep::Kind::Ramp: ok = read_ramp(r, v, p, when, a); break;
      case ScenarioStep::Kind::Generate: ok = read_generate(r, v, p, a); break;
      case ScenarioStep::Kind::Inject: ok = read_inject(r, v, p, a); break;
      case ScenarioStep::Kind::Reset: ok = read_reset(r, v, p, a); break;
      case ScenarioStep::Kind::Expect:
      case ScenarioStep::Kind::ExpectOutstanding:
      case ScenarioStep::Kind::ExpectCause: ok = read_expectations(r, v, p, m.key, s.kind, a); break;
    }
    if (!ok) continue;
    if (s.kind != ScenarioStep::Kind::Sample) s.action = std::make_shared<const StepAction>(std::move(a));
    steps.push_back(std::move(s));
  }
  if (actions == 0 && !unknown_action) {
    r.error(step.position, base, "step has no action (sample, ramp, generate, inject, reset or expect...)");
  }
}

}  // namespace

ScenarioLoad load_scenario(const std::string& path) {
  auto read = read_regular_file(path);
  if (!read) {
    ScenarioLoad out;
    out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, Position{path, 1, 1}, read.error().message, ""});
    return out;
  }
  return load_scenario_text(std::move(*read), path);
}

ScenarioLoad load_scenario_text(std::string text, const std::string& path) {
  ScenarioLoad out;
  Reader r(path, out.diagnostics);
  // The steps are read one by one as the parser reaches them and their JSON is dropped at once:
  // a tree of the whole file took ten times its size (docs/spec-format.md, "Memory"). Their
  // diagnostics come after those of the scenario's other members, as they always did.
  Scenario sc;
  sc.path = path;
  std::vector<Diagnostic> step_diagnostics;
  Reader step_reader(path, step_diagnostics);
  const json::JsonParse parsed = json::parse_json_streaming(
      text, "steps", [&](std::size_t index, json::JsonValue&& step) { read_step(step_reader, step, index, sc.steps); });
  std::string().swap(text);
  if (parsed.error) {  // the syntax error alone, as for any file that is not JSON
    r.error(parsed.error->position, "", parsed.error->message);
    return out;
  }
  const json::JsonValue& root = *parsed.value;
  if (!root.is_object()) {
    r.error(root.position, "", "a scenario must be a JSON object");
    return out;
  }
  const auto typos = r.unknown_keys(root, "", "scenario");
  const auto typo = [&](const char* k) { return std::find(typos.begin(), typos.end(), k) != typos.end(); };
  const json::JsonValue* system = root.find("system");
  if (system == nullptr) {
    if (!typo("system"))
      r.error(root.position, "", "scenario needs \"system\" (the system file, relative to the scenario)");
  } else if (std::string s; r.text(*system, "/system", "\"system\"", s)) {
    const std::filesystem::path base = std::filesystem::path(path).parent_path();
    sc.system = (base / s).lexically_normal().string();
  }
  if (const json::JsonValue* period = root.find("period")) {
    if (r.number(*period, "/period", "\"period\"", sc.period) && !(sc.period > 0 && sc.period <= 10)) {
      r.error(period->position, "/period", "\"period\" must be in (0, 10] seconds");
    }
  }
  const json::JsonValue* duration = root.find("duration");
  if (duration == nullptr) {
    if (!typo("duration")) r.error(root.position, "", "scenario needs \"duration\" (seconds)");
  } else if (r.number(*duration, "/duration", "\"duration\"", sc.duration) &&
             !(sc.duration >= 0 && sc.duration <= 1e6)) {
    r.error(duration->position, "/duration", "\"duration\" must be in [0, 1e6] seconds");
  }
  if (sc.period > 0 && sc.duration / sc.period > 1e8) {
    r.error(root.position, "", "duration / period is more than 1e8 ticks");
  }
  const json::JsonValue* steps = root.find("steps");
  if (steps != nullptr && !steps->is_array()) r.error(steps->position, "/steps", "\"steps\" must be a list");
  if (duration != nullptr && duration->is_number() && sc.duration >= 0 && sc.duration <= 1e6) {
    // An expectation after the end would never be checked: say so now, with its position.
    for (const ScenarioStep& s : sc.steps) {
      const bool check = s.kind == ScenarioStep::Kind::Expect || s.kind == ScenarioStep::Kind::ExpectOutstanding ||
                         s.kind == ScenarioStep::Kind::ExpectCause;
      if (!check || !(s.at > sc.duration)) continue;
      step_diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, sc.where(s),
                                            "expectation at t=" + seconds_text(s.at) + " is after the duration (" +
                                                seconds_text(sc.duration) +
                                                " s): it would never be checked; move it or lengthen \"duration\"",
                                            s.pointer()});
    }
  }
  out.diagnostics.insert(out.diagnostics.end(), std::make_move_iterator(step_diagnostics.begin()),
                         std::make_move_iterator(step_diagnostics.end()));
  // Scenarios are usually written in time order: then nothing moves (a sort would need a buffer
  // of half the steps).
  const auto by_time = [](const ScenarioStep& a, const ScenarioStep& b) { return a.at < b.at; };
  if (!std::is_sorted(sc.steps.begin(), sc.steps.end(), by_time))
    std::stable_sort(sc.steps.begin(), sc.steps.end(), by_time);
  if (!out.diagnostics.empty()) {
    out.partial = std::move(sc);
    return out;
  }
  out.scenario = std::move(sc);
  return out;
}

}  // namespace safecass::spec
