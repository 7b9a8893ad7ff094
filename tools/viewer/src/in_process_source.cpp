#include "safecass/viewer/in_process_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "local_view.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/introspect/sample_text.hpp"
#include "safecass/json/write.hpp"
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

struct InProcessSource::Impl {
  const FilterRegistry* registry = nullptr;  // outlives the runner's monitor
  std::unique_ptr<runner::ScenarioRunner> runner;
  runner::RunResult result;
  std::size_t failures_reported = 0;
  InProcessOptions options;
  std::string system_name;
  std::string description;
  Coordinators coordinators;
  std::vector<ConnectionView> connections;
  Time duration{};
  Time tick{};
  // Real-time driving: simulated time = base_sim + (wall - base_wall) * speed.
  std::chrono::steady_clock::time_point base_wall;
  Time base_sim{};
  std::unique_ptr<introspect::LocalQuery> query;        // what the source reads and writes through
  std::unique_ptr<introspect::Subscription> following;  // the records, for take_records()
  PendingRecords pending;

  ~Impl() {
    following.reset();  // before the query and the runner
    query.reset();
  }

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
};

InProcessSource::InProcessSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

InProcessSource::~InProcessSource() = default;

Expected<std::unique_ptr<InProcessSource>> InProcessSource::open(const InProcessOptions& options) {
  if (!std::isfinite(options.speed) || options.speed <= 0.0 || options.speed > 1000.0) {
    return fail(ErrorCode::InvalidArgument, "--speed must be above 0 and at most 1000 (simulated seconds per second)");
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->registry = options.registry != nullptr ? options.registry : &builtin_filters();

  auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{options.scenario, options.system}, *impl->registry);
  if (!opened) return fail(ErrorCode::InvalidArgument, spec::to_text(opened.error()));
  impl->runner = std::move(*opened);
  const spec::SystemSpec& loaded = impl->runner->system().spec();
  const spec::Scenario& scenario = impl->runner->scenario();
  impl->system_name = loaded.name;
  impl->duration = seconds_to_time(scenario.duration);
  impl->tick = seconds_to_time(scenario.period);
  impl->description =
      "in-process: " + std::filesystem::path(scenario.system).filename().string() +
      (options.scenario.empty() ? std::string()
                                : ", scenario " + std::filesystem::path(options.scenario).filename().string());
  char speed[32];
  std::snprintf(speed, sizeof speed, "%g", options.speed);
  impl->description += std::string(", speed ") + speed;

  impl->coordinators = coordinators_of(loaded, impl->co());

  introspect::LocalOptions local;
  local.name = impl->system_name;
  local.period = to_seconds(impl->tick);
  local.scenario = options.scenario;
  local.duration = to_seconds(impl->duration);
  impl->query = std::make_unique<introspect::LocalQuery>(impl->co(), impl->runner->monitor(), *impl->registry, local);
  impl->connections = local_connections(*impl->query);
  Impl* self = impl.get();
  auto following = impl->query->follow([self](const introspect::HistoryEntry& e) { self->pending.push(e); });
  if (!following) return tl::unexpected(following.error());
  impl->following = std::move(*following);
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

introspect::CoverageNow InProcessSource::coverage() const {
  return impl_->query->coverage().value_or(introspect::CoverageNow{});  // in-process: never fails
}

SystemView InProcessSource::view() const {
  SystemView v = local_view(*impl_->query, impl_->coordinators, impl_->connections);
  v.system = impl_->system_name;
  v.description = impl_->description;
  v.t = now();
  v.running = running();
  return v;
}

std::vector<std::string> InProcessSource::take_records() { return impl_->pending.take(); }

Expected<std::vector<Explanation>> InProcessSource::explain(std::string_view address) const {
  return local_explain(*impl_->query, impl_->co(), impl_->coordinators, address);
}

Expected<std::string> InProcessSource::apply(const introspect::Action& action) {
  if (auto r = impl_->query->apply(action); !r) return tl::unexpected(r.error());
  const std::string at = " at t=" + seconds_text(impl_->now());
  return std::visit(
      [&](const auto& a) -> std::string {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, introspect::GenerateEvent>) {
          return "generated " + a.event + " on " + a.target + at;
        } else if constexpr (std::is_same_v<A, introspect::BroadcastEvent>) {
          return "broadcast " + a.event + at;
        } else if constexpr (std::is_same_v<A, introspect::ResetState>) {
          return "reset " + a.target + at + " (" + a.why + ")";
        } else if constexpr (std::is_same_v<A, introspect::InjectShallow>) {
          return "queued " + introspect::count_text(a.samples.size()) + " into filter " + a.filter + at;
        } else if constexpr (std::is_same_v<A, introspect::InjectDeep>) {
          return "wrote " + introspect::count_text(a.samples.size()) + " into signal " + a.signal + at;
        } else {
          return "pushed a sample of " + a.signal + at;
        }
      },
      action);
}

}  // namespace safecass::viewer
