#include "safecass/viewer/in_process_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "safecass/filters/registry.hpp"
#include "safecass/record/recorder.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::viewer {

std::string_view to_string(NodeKind kind) noexcept {
  switch (kind) {
    case NodeKind::Framework: return "framework";
    case NodeKind::Application: return "application";
    case NodeKind::Provided: return "provided";
    case NodeKind::Required: return "required";
    case NodeKind::Service: return "service";
  }
  return "?";
}

namespace {

/// Records waiting for take_records() beyond this are dropped and counted (a bound on memory if
/// nobody polls; in practice the server takes them every poll).
constexpr std::size_t kMaxPendingRecords = 100000;
/// At most this many ticks are processed per poll, so that a poll never holds the event loop
/// for long; the clock catches up over the next polls.
constexpr std::int64_t kMaxTicksPerPoll = 5000;

std::string seconds_text(Time t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3f", to_seconds(t));
  return buf;
}

std::string file_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

struct InProcessSource::Impl {
  FilterRegistry registry;  // outlives the runner's monitor
  std::unique_ptr<runner::ScenarioRunner> runner;
  runner::RunResult result;
  std::size_t failures_reported = 0;
  InProcessOptions options;
  std::string system_name;
  std::string description;
  std::vector<std::pair<std::string, std::vector<ComponentId>>> coordinators;
  Time duration{};
  Time tick{};
  // Real-time driving: simulated time = base_sim + (wall - base_wall) * speed.
  std::chrono::steady_clock::time_point base_wall;
  Time base_sim{};
  Coordinator::SubscriptionId subscription = 0;
  std::vector<std::string> pending;
  std::uint64_t dropped = 0;

  Coordinator& co() { return runner->coordinator(); }
  const Coordinator& co() const { return runner->coordinator(); }
  Time now() const { return runner->now() < Time{0} ? Time{0} : runner->now(); }

  void advance(Time target) {
    const Time limit = runner->now() + tick * kMaxTicksPerPoll;
    if (target > limit) target = limit;
    if (target <= runner->now()) return;
    runner->advance_to(target, result);
    for (; failures_reported < result.failures.size(); ++failures_reported) {
      if (options.log != nullptr) std::fprintf(options.log, "%s\n", result.failures[failures_reported].c_str());
    }
  }

  /// The components of a coordinator of the system file, or of every coordinator for "SYSTEM".
  const std::vector<ComponentId>* coordinator_components(std::string_view name) const {
    for (const auto& [n, ids] : coordinators) {
      if (n == name) return &ids;
    }
    return nullptr;
  }
};

InProcessSource::InProcessSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

InProcessSource::~InProcessSource() {
  if (impl_ && impl_->runner && impl_->subscription != 0) impl_->co().unsubscribe(impl_->subscription);
}

Expected<std::unique_ptr<InProcessSource>> InProcessSource::open(const InProcessOptions& options) {
  if (!std::isfinite(options.speed) || options.speed <= 0.0 || options.speed > 1000.0) {
    return fail(ErrorCode::InvalidArgument, "--speed must be above 0 and at most 1000 (simulated seconds per second)");
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  register_builtin_filters(impl->registry);

  auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{options.scenario, options.system}, impl->registry);
  if (!opened) return fail(ErrorCode::InvalidArgument, runner::to_text(opened.error()));
  impl->runner = std::move(*opened);
  const spec::SystemSpec& loaded = impl->runner->system().spec();
  const spec::Scenario& scenario = impl->runner->scenario();
  impl->system_name = loaded.name;
  impl->duration = seconds_to_time(scenario.duration);
  impl->tick = seconds_to_time(scenario.period);
  const auto& spec_coordinators = loaded.coordinators;
  std::vector<std::string> all_components;
  for (const spec::ComponentSpec& c : loaded.components) all_components.push_back(c.name);
  impl->description = "in-process: " + file_name(scenario.system) +
                      (options.scenario.empty() ? std::string() : ", scenario " + file_name(options.scenario));
  char speed[32];
  std::snprintf(speed, sizeof speed, "%g", options.speed);
  impl->description += std::string(", speed ") + speed;

  Coordinator& co = impl->co();
  auto ids_of = [&co](const std::vector<std::string>& names) {
    std::vector<ComponentId> ids;
    for (const std::string& n : names) {
      if (auto id = co.find_component(n)) ids.push_back(*id);
    }
    return ids;
  };
  if (spec_coordinators.empty()) {
    impl->coordinators.emplace_back(std::string(co.name()), ids_of(all_components));
  } else {
    for (const auto& [name, components] : spec_coordinators) impl->coordinators.emplace_back(name, ids_of(components));
  }

  Impl* self = impl.get();
  impl->subscription = co.subscribe([self](const Record& r) {
    if (self->pending.size() >= kMaxPendingRecords) {
      ++self->dropped;
      return;
    }
    self->pending.push_back(record_to_json(r, self->co()));
  });
  impl->runner->advance_to(Time{0}, impl->result);
  impl->base_wall = std::chrono::steady_clock::now();
  impl->base_sim = Time{0};
  return std::unique_ptr<InProcessSource>(new InProcessSource(std::move(impl)));
}

void InProcessSource::poll() {
  const auto elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - impl_->base_wall).count();
  impl_->advance(impl_->base_sim + seconds_to_time(elapsed * impl_->options.speed));
}

void InProcessSource::advance_to(double t) {
  const Time target = seconds_to_time(t);
  while (impl_->runner->now() + impl_->tick <= target) impl_->advance(target);
  impl_->base_wall = std::chrono::steady_clock::now();
  impl_->base_sim = impl_->now();
}

const Coordinator& InProcessSource::coordinator() const noexcept { return impl_->co(); }

double InProcessSource::now() const { return to_seconds(impl_->now()); }

bool InProcessSource::running() const { return impl_->now() < impl_->duration; }

SystemView InProcessSource::view() const {
  const Coordinator& co = impl_->co();
  SystemView v;
  v.system = impl_->system_name;
  v.description = impl_->description;
  v.t = now();
  v.running = running();
  for (const auto& [name, ids] : impl_->coordinators) {
    CoordinatorView cv;
    cv.name = name;
    for (const ComponentId id : ids) {
      ComponentView c;
      c.name = std::string(co.component_name(id));
      const StateSnapshot ext = co.extended(id);
      c.state = ext.state;
      if (ext.state != State::Normal && ext.outstanding != kNoEvent) c.outstanding = co.event(ext.outstanding).name;
      auto machine = [&](MachineId m, NodeKind kind, std::string name_text) {
        MachineView mv;
        mv.address = co.address_of(m);
        mv.kind = kind;
        mv.name = std::move(name_text);
        const StateSnapshot s = co.snapshot(m);
        mv.state = s.state;
        if (s.state != State::Normal && s.outstanding != kNoEvent) mv.outstanding = co.event(s.outstanding).name;
        c.machines.push_back(std::move(mv));
      };
      machine(co.framework_machine(id), NodeKind::Framework, "s_F");
      machine(co.application_machine(id), NodeKind::Application, "s_A");
      for (const MachineId m : co.provided_machines(id)) machine(m, NodeKind::Provided, std::string(co.interface_name(m)));
      for (const MachineId m : co.required_machines(id)) machine(m, NodeKind::Required, std::string(co.interface_name(m)));
      const auto& provided = co.provided_machines(id);
      for (std::uint32_t i = 0; i < provided.size(); ++i) {
        MachineView mv;
        mv.name = std::string(co.interface_name(provided[i]));
        mv.address = c.name + ".s_S." + mv.name;
        mv.kind = NodeKind::Service;
        mv.state = co.service_state(id, i);
        c.machines.push_back(std::move(mv));
      }
      cv.state = std::max(cv.state, c.state);
      cv.components.push_back(std::move(c));
    }
    v.state = std::max(v.state, cv.state);
    v.coordinators.push_back(std::move(cv));
  }
  return v;
}

std::vector<std::string> InProcessSource::take_records() {
  std::vector<std::string> out;
  out.swap(impl_->pending);
  if (impl_->dropped != 0) {
    out.push_back("{\"kind\":\"overflow\",\"dropped\":" + std::to_string(impl_->dropped) + "}");
    impl_->dropped = 0;
  }
  return out;
}

Expected<std::vector<Explanation>> InProcessSource::explain(std::string_view address) const {
  const Coordinator& co = impl_->co();
  if (address.substr(0, 12) == "coordinator:") {
    const std::string_view name = address.substr(12);
    const auto* ids = impl_->coordinator_components(name);
    if (ids == nullptr) return fail(ErrorCode::NotFound, "no coordinator '" + std::string(name) + "'");
    std::vector<Explanation> all;
    for (const ComponentId id : *ids) {
      const std::vector<Explanation> part = co.explain(Address{Address::Kind::Component, id});
      all.insert(all.end(), part.begin(), part.end());
    }
    return all;
  }
  return co.explain(address);
}

Expected<std::string> InProcessSource::generate(std::string_view event, std::string_view target) {
  if (auto r = impl_->co().generate(event, target); !r) return tl::unexpected(r.error());
  return "generated " + std::string(event) + " on " + std::string(target) + " at t=" + seconds_text(impl_->now());
}

Expected<std::string> InProcessSource::broadcast(std::string_view event) {
  if (auto r = impl_->co().broadcast(event); !r) return tl::unexpected(r.error());
  return "broadcast " + std::string(event) + " at t=" + seconds_text(impl_->now());
}

Expected<std::string> InProcessSource::inject(const InjectRequest& request) {
  Monitor& monitor = impl_->runner->monitor();
  if (request.samples.empty()) return fail(ErrorCode::InvalidArgument, "no samples to inject");
  const std::string n = std::to_string(request.samples.size()) + (request.samples.size() == 1 ? " sample" : " samples");
  if (!request.deep) {
    if (monitor.find_filter(request.target) == nullptr) {
      return fail(ErrorCode::NotFound, "no filter '" + request.target + "'");
    }
    if (auto r = monitor.inject_shallow(request.target, request.samples); !r) return tl::unexpected(r.error());
    return "queued " + n + " into filter " + request.target + " at t=" + seconds_text(impl_->now());
  }
  Signal* s = monitor.signals().find(request.target);
  if (s == nullptr) return fail(ErrorCode::NotFound, "no signal '" + request.target + "' (signals are written Component.signal)");
  if (request.samples.size() > s->buffer().capacity()) {
    return fail(ErrorCode::InvalidArgument, n + " would overflow the history of '" + request.target + "' (" +
                                                std::to_string(s->buffer().capacity()) + " samples): inject fewer at once");
  }
  if (auto r = monitor.inject_deep(request.target, request.samples, impl_->now()); !r) return tl::unexpected(r.error());
  return "wrote " + n + " into signal " + request.target + " at t=" + seconds_text(impl_->now());
}

Expected<std::string> InProcessSource::reset(std::string_view target, std::string_view reason) {
  if (auto r = impl_->co().reset(target, "viewer", reason); !r) return tl::unexpected(r.error());
  return "reset " + std::string(target) + " at t=" + seconds_text(impl_->now()) + " (" + std::string(reason) + ")";
}

}  // namespace safecass::viewer
