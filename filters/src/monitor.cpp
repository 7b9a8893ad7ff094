#include "safecass/filters/monitor.hpp"

#include "safecass/core/address.hpp"
#include "safecass/core/text.hpp"

#include "banks.hpp"

#include <cmath>

#include <algorithm>
#include <cstdio>

namespace safecass {

Monitor::Monitor(Coordinator& coordinator, const FilterRegistry& registry, std::size_t signal_history, bool banks)
    : coordinator_(coordinator),
      registry_(registry),
      signals_(signal_history),
      banks_(banks),
      passive_(std::make_unique<detail::Banks>(banks)) {}

Monitor::~Monitor() { stop(); }

std::string Monitor::qualify(std::string_view signal, std::string_view component) const {
  if (signal.find('.') != std::string_view::npos) return std::string(signal);
  return std::string(component) + "." + std::string(signal);
}

Expected<Signal*> Monitor::add_signal(std::string_view name, std::size_t size) {
  const auto dot = name.find('.');
  if (dot == std::string_view::npos) {
    return fail(ErrorCode::InvalidArgument, "signal name '" + std::string(name) + "' must be Component.signal");
  }
  auto component = coordinator_.structure().find_component(name.substr(0, dot));
  if (!component) {
    return fail(ErrorCode::NotFound,
                "signal '" + std::string(name) + "': no component '" + std::string(name.substr(0, dot)) + "'");
  }
  auto s = signals_.add(name, *component, size);
  if (s && (*s)->name_id() == kNoName) (*s)->set_name_id(coordinator_.intern((*s)->name()));
  return s;
}

Filter* Monitor::find_filter(std::string_view name) const noexcept {
  const auto it = by_name_.find(name);
  return it == by_name_.end() ? nullptr : it->second;
}

Expected<FilterInit> Monitor::prepare(FilterConfig config,
                                      std::vector<std::pair<std::string, std::size_t>>& new_outputs) {
  const FilterRegistry::Entry* entry = registry_.find(config.type);
  // A filter is of its type, not of the alias it was asked for by ("Heartbeat" is a Watchdog), as a
  // specification's filters are: what reads its type (filter list, analyze) then knows it.
  if (entry != nullptr) config.type = entry->manifest.type;
  if (config.name.empty()) config.name = config.type + "_" + std::to_string(filters_.size() + 1);
  const std::string where = "filter '" + config.name + "'";
  if (entry == nullptr) {
    std::string known;
    for (const FilterManifest* m : registry_.manifests()) known += (known.empty() ? "" : ", ") + m->type;
    return fail(ErrorCode::NotFound, where + ": unknown filter type '" + config.type + "' (known: " + known + ")");
  }
  if (find_filter(config.name) != nullptr) return fail(ErrorCode::Duplicate, "duplicate " + where);
  const FilterManifest& manifest = entry->manifest;
  if (manifest.default_output && !manifest.outputs.empty() && config.params.count(manifest.outputs.front()) == 0) {
    config.params[manifest.outputs.front()] = default_output_name(config.name, config.target.component);
  }
  auto params = check_params(manifest, config.params, config.name);
  if (!params) return tl::unexpected(params.error());
  config.params = std::move(*params);

  FilterInit init;
  init.coordinator = &coordinator_;
  // Target machine.
  auto component = coordinator_.structure().find_component(config.target.component);
  if (!component) {
    return fail(ErrorCode::NotFound, where + ": target component '" + config.target.component + "' not found");
  }
  init.component = *component;
  switch (config.target.kind) {
    case MachineKind::Framework: init.target = coordinator_.structure().framework_machine(*component); break;
    case MachineKind::Application: init.target = coordinator_.structure().application_machine(*component); break;
    case MachineKind::Provided:
    case MachineKind::Required: {
      const std::string machine =
          address::machine(config.target.kind, config.target.component, config.target.interface);
      auto m = coordinator_.structure().find_machine(machine);
      if (!m) return fail(ErrorCode::NotFound, where + ": target " + machine + " does not exist");
      init.target = *m;
      break;
    }
  }
  // Inputs, in manifest order.
  for (const std::string& input : manifest.inputs) {
    const auto it = config.params.find(input);
    if (it == config.params.end()) continue;
    std::vector<std::string> names;
    if (const auto* one = std::get_if<std::string>(&it->second)) names.push_back(*one);
    if (const auto* many = std::get_if<std::vector<std::string>>(&it->second)) names = *many;
    for (const std::string& n : names) {
      const std::string full = qualify(n, config.target.component);
      Signal* s = signals_.find(full);
      if (s == nullptr) {
        return fail(ErrorCode::NotFound, where + ": parameter '" + input + "': '" + full + "' is not a signal");
      }
      init.inputs.push_back(s);
    }
  }
  bool has_input_param = false;
  for (const std::string& input : manifest.inputs) has_input_param = has_input_param || config.params.count(input) > 0;
  if (!manifest.inputs.empty() && !has_input_param) {
    return fail(ErrorCode::InvalidArgument, where + ": needs an input ('" + manifest.inputs.front() + "')");
  }
  auto sizes = entry->shape(FilterShape{config.name, config.params, init.inputs});
  if (!sizes) return tl::unexpected(sizes.error());
  // Outputs: existing signals must have the right size; the others are created after all checks.
  for (std::size_t k = 0; k < manifest.outputs.size(); ++k) {
    const auto it = config.params.find(manifest.outputs[k]);
    if (it == config.params.end()) {
      init.outputs.push_back(nullptr);
      continue;
    }
    const std::string full = qualify(std::get<std::string>(it->second), config.target.component);
    const std::size_t size = k < sizes->size() ? (*sizes)[k] : 1;
    if (Signal* s = signals_.find(full)) {
      if (std::find(init.inputs.begin(), init.inputs.end(), s) != init.inputs.end()) {
        // Each write would be a new sample to read in the same run: the run would never end.
        return fail(ErrorCode::InvalidArgument, where + ": parameter '" + manifest.outputs[k] + "': signal '" + full +
                                                    "' is also an input of this filter");
      }
      if (s->size() != size) {
        return fail(ErrorCode::InvalidArgument, where + ": parameter '" + manifest.outputs[k] + "': signal '" + full +
                                                    "' has size " + std::to_string(s->size()) +
                                                    " but this filter writes " + std::to_string(size));
      }
      init.outputs.push_back(s);
      continue;
    }
    const auto dot = full.find('.');
    if (!coordinator_.structure().find_component(std::string_view(full).substr(0, dot))) {
      return fail(ErrorCode::NotFound,
                  where + ": parameter '" + manifest.outputs[k] + "': no component for '" + full + "'");
    }
    new_outputs.emplace_back(full, size);
    init.outputs.push_back(nullptr);
  }
  // Events: the first Event parameter is the onset, the second the completion.
  std::vector<const ParamSpec*> event_params;
  for (const ParamSpec& p : manifest.params) {
    if (p.type == ParamType::Event) event_params.push_back(&p);
  }
  for (std::size_t k = 0; k < event_params.size() && k < 2; ++k) {
    const auto it = config.params.find(event_params[k]->name);
    if (it == config.params.end()) continue;
    const std::string& name = std::get<std::string>(it->second);
    auto e = coordinator_.structure().find_event(name);
    if (!e)
      return fail(ErrorCode::NotFound, where + ": parameter '" + event_params[k]->name + "': no event '" + name + "'");
    const bool want_onset = k == 0;
    if (coordinator_.structure().event(*e).is_onset != want_onset) {
      return fail(ErrorCode::InvalidArgument,
                  where + ": parameter '" + event_params[k]->name + "': event '" + name + "' is " +
                      (want_onset ? "a completion; an onset is needed" : "an onset; a completion is needed"));
    }
    (want_onset ? init.onset : init.completion) = *e;
  }
  if (init.onset != kNoEvent && init.completion == kNoEvent)
    init.completion = coordinator_.structure().event(init.onset).counterpart;
  if (init.completion != kNoEvent && init.onset != kNoEvent &&
      coordinator_.structure().event(init.completion).counterpart != init.onset) {
    return fail(ErrorCode::InvalidArgument,
                where + ": completion '" + coordinator_.structure().event(init.completion).name +
                    "' does not complete onset '" + coordinator_.structure().event(init.onset).name + "'");
  }
  init.name_id = coordinator_.intern(config.name);
  init.config = std::move(config);
  return init;
}

Expected<Filter*> Monitor::add_filter(FilterConfig config) {
  std::vector<std::pair<std::string, std::size_t>> new_outputs;
  auto init = prepare(std::move(config), new_outputs);
  if (!init) return tl::unexpected(init.error());
  // Every check passed: create the missing outputs, then the filter.
  std::size_t k = 0;
  for (std::size_t o = 0; o < init->outputs.size(); ++o) {
    if (init->outputs[o] != nullptr) continue;
    const auto it = init->config.params.find(registry_.find(init->config.type)->manifest.outputs[o]);
    if (it == init->config.params.end()) continue;
    auto s = add_signal(new_outputs[k].first, new_outputs[k].second);
    ++k;
    if (!s) return tl::unexpected(s.error());  // cannot happen: checked in prepare()
    init->outputs[o] = *s;
  }
  auto filter = registry_.find(init->config.type)->factory(std::move(*init));
  Filter* raw = filter.get();
  filters_.push_back(std::move(filter));
  by_name_.emplace(raw->name(), raw);
  group(*raw).add(raw);
  return raw;
}

detail::Banks& Monitor::group(const Filter& filter) {
  if (filter.execution() == ExecutionMode::Passive) return *passive_;
  const std::size_t c = to_index(filter.component());
  while (active_.size() <= c) active_.push_back(std::make_unique<detail::Banks>(banks_));
  return *active_[c];
}

void Monitor::regroup(std::size_t count) {
  // The new groups adopt the filters' states and positions from the old ones, which must live
  // until then.
  passive_->settle();
  for (auto& g : active_) g->settle();
  auto old_active = std::move(active_);
  auto old_passive = std::move(passive_);
  active_.clear();
  // The groups count on from the old ones' runs (Filter::facts()).
  for (const auto& g : old_active) active_.push_back(std::make_unique<detail::Banks>(banks_, g->runs()));
  passive_ = std::make_unique<detail::Banks>(banks_, old_passive->runs());
  for (std::size_t i = 0; i < count && i < filters_.size(); ++i) group(*filters_[i]).add(filters_[i].get());
}

std::size_t Monitor::banked_count() const noexcept {
  std::size_t n = passive_->banked();
  for (const auto& g : active_) n += g->banked();
  return n;
}

std::size_t Monitor::passive_count() const noexcept { return passive_->size(); }

Expected<std::vector<Filter*>> Monitor::add_pipeline(std::string_view name, std::vector<FilterConfig> stages) {
  const std::size_t filters_before = filters_.size();
  const std::size_t signals_before = signals_.all().size();
  std::vector<Filter*> created;
  std::string previous_output;
  for (std::size_t i = 0; i < stages.size(); ++i) {
    FilterConfig& stage = stages[i];
    if (stage.name.empty()) stage.name = std::string(name) + "." + std::to_string(i + 1);
    const FilterRegistry::Entry* entry = registry_.find(stage.type);
    if (entry != nullptr && i > 0 && !entry->manifest.inputs.empty()) {
      const std::string& in = entry->manifest.inputs.front();
      const bool has_input = std::any_of(entry->manifest.inputs.begin(), entry->manifest.inputs.end(),
                                         [&](const std::string& p) { return stage.params.count(p) > 0; });
      if (!has_input && !previous_output.empty()) stage.params[in] = previous_output;
    }
    if (entry != nullptr && !entry->manifest.outputs.empty() && i + 1 < stages.size() &&
        stage.params.count(entry->manifest.outputs.front()) == 0) {
      stage.params[entry->manifest.outputs.front()] = std::string(name) + "_" + std::to_string(i + 1);
    }
    previous_output.clear();
    if (entry != nullptr && !entry->manifest.outputs.empty()) {
      const auto it = stage.params.find(entry->manifest.outputs.front());
      if (it != stage.params.end())
        previous_output = qualify(std::get<std::string>(it->second), stage.target.component);
    }
    auto f = add_filter(stage);
    if (!f) {
      // All or nothing: undo the stages already created.
      regroup(filters_before);
      for (std::size_t k = filters_before; k < filters_.size(); ++k) by_name_.erase(filters_[k]->name());
      filters_.resize(filters_before);
      signals_.truncate(signals_before);
      return fail(f.error().code,
                  "pipeline '" + std::string(name) + "', stage " + std::to_string(i + 1) + ": " + f.error().message);
    }
    created.push_back(*f);
  }
  return created;
}

void Monitor::run_active(ComponentId component, Time now) noexcept {
  if (to_index(component) >= active_.size()) return;
  active_[to_index(component)]->run(now);
}

void Monitor::tick(Time now) noexcept { passive_->run(now); }

void Monitor::start(std::chrono::nanoseconds period) {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this, period] {
    auto next = std::chrono::steady_clock::now();
    while (!stop_.load(std::memory_order_acquire)) {
      tick(coordinator_.clock().now());
      next += period;
      std::this_thread::sleep_until(next);
    }
  });
}

void Monitor::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void Monitor::record_injection(MachineId machine, std::string text) {
  Record r;
  r.kind = RecordKind::Injection;
  r.time = coordinator_.clock().now();
  r.machine = machine;
  r.text = coordinator_.structure().name_of(coordinator_.intern(text));
  coordinator_.publish(r);
}

namespace {
std::string samples_text(const std::vector<std::vector<double>>& samples) {
  std::string out;
  for (const auto& s : samples) {
    out += out.empty() ? "" : " ";
    if (s.size() != 1) out += "[";
    for (std::size_t i = 0; i < s.size(); ++i) out += (i ? ", " : "") + number_text(s[i]);
    if (s.size() != 1) out += "]";
  }
  return out;
}

std::string value_text(double v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

/// The rule of every injection path (console, scenario, middleware, viewer): injected values are
/// finite. A NaN or infinite value is refused as a whole, naming the first one.
[[nodiscard]] Expected<void> check_finite(std::string_view what, const std::vector<std::vector<double>>& samples) {
  for (std::size_t i = 0; i < samples.size(); ++i) {
    for (std::size_t k = 0; k < samples[i].size(); ++k) {
      if (std::isfinite(samples[i][k])) continue;
      std::string where = "sample " + std::to_string(i + 1);
      if (samples[i].size() != 1) where += " value " + std::to_string(k + 1);
      return fail(ErrorCode::InvalidArgument, std::string(what) + ": " + where + " is " + value_text(samples[i][k]) +
                                                  ", not a finite number: injected values must be finite");
    }
  }
  return {};
}
}  // namespace

Expected<void> Monitor::check_inject_shallow(std::string_view filter,
                                             const std::vector<std::vector<double>>& samples) const {
  const Filter* f = find_filter(filter);
  if (f == nullptr) return fail(ErrorCode::NotFound, "no filter '" + std::string(filter) + "'");
  const std::string what = "shallow injection into filter " + f->name();
  if (samples.empty()) return fail(ErrorCode::InvalidArgument, what + ": no samples");
  if (auto ok = f->check_injection(samples); !ok) return ok;
  return check_finite(what, samples);
}

Expected<void> Monitor::check_inject_deep(std::string_view signal,
                                          const std::vector<std::vector<double>>& samples) const {
  const Signal* s = signals_.find(signal);
  if (s == nullptr) {
    return fail(ErrorCode::NotFound, "no signal '" + std::string(signal) + "' (signals are written Component.signal)");
  }
  const std::string what = "deep injection into signal " + s->name();
  if (samples.empty()) return fail(ErrorCode::InvalidArgument, what + ": no samples");
  if (samples.size() > s->buffer().capacity()) {
    return fail(ErrorCode::InvalidArgument,
                what + ": " + std::to_string(samples.size()) + (samples.size() == 1 ? " sample" : " samples") +
                    " would overflow its history (" + std::to_string(s->buffer().capacity()) +
                    " samples): inject fewer at once");
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].size() != s->size()) {
      return fail(ErrorCode::InvalidArgument, what + ": sample " + std::to_string(i + 1) + " has " +
                                                  std::to_string(samples[i].size()) + " values; the signal has size " +
                                                  std::to_string(s->size()));
    }
  }
  return check_finite(what, samples);
}

Expected<void> Monitor::inject_shallow(std::string_view filter, const std::vector<std::vector<double>>& samples) {
  if (auto ok = check_inject_shallow(filter, samples); !ok) return ok;
  Filter* f = find_filter(filter);
  if (auto r = f->inject(samples); !r) return r;
  record_injection(f->target(), "shallow injection into filter " + f->name() + ": " + samples_text(samples));
  return {};
}

Expected<void> Monitor::inject_deep(std::string_view signal, const std::vector<std::vector<double>>& samples, Time at) {
  if (auto ok = check_inject_deep(signal, samples); !ok) return ok;
  Signal* s = signals_.find(signal);
  for (const auto& v : samples) s->inject(at, v.data());
  const std::string text = "deep injection into signal " + s->name() + ": " + samples_text(samples);
  // One record on each machine whose filters read the signal (however many of them do), in the
  // order of their first filter; one without a machine when no filter reads it.
  std::vector<MachineId> machines;
  for (const auto& f : filters_) {
    if (std::find(f->inputs().begin(), f->inputs().end(), s) == f->inputs().end()) continue;
    if (std::find(machines.begin(), machines.end(), f->target()) == machines.end()) machines.push_back(f->target());
  }
  if (machines.empty()) machines.push_back(kNoMachine);
  for (MachineId m : machines) record_injection(m, text);
  return {};
}

}  // namespace safecass
