#include "safecass/viewer/replay_source.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "local_view.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/json/write.hpp"
#include "safecass/replay/replay.hpp"

namespace safecass::viewer {

namespace {

[[nodiscard]] Expected<void> check_speed(double speed) {
  if (!std::isfinite(speed) || speed <= 0.0 || speed > 1000.0) {
    return fail(ErrorCode::InvalidArgument,
                "the speed must be above 0 and at most 1000 (recording seconds per second)");
  }
  return {};
}

}  // namespace

struct ReplaySource::Impl {
  const FilterRegistry* registry = &builtin_filters();  // outlives every session
  replay::ReplayOptions options;
  std::string description;
  // One replay of the log from its start; replaced (with what follows it) when going back.
  std::unique_ptr<replay::ReplaySession> session;
  std::unique_ptr<introspect::LocalQuery> query;
  std::unique_ptr<introspect::Subscription> following;
  Coordinators coordinators;
  std::vector<ConnectionView> connections;
  std::string system_name;
  PendingRecords pending;
  std::uint64_t generation = 0;
  bool transition_seen = false;  // since the last "next" began
  // Controls. Playing: replay time = base_sim + (wall - base_wall) * speed.
  bool playing = false;
  double speed = 1.0;
  std::optional<Time> seek;  // catching up to this time
  bool next = false;         // running on to the next transition
  std::chrono::steady_clock::time_point base_wall;
  Time base_sim{};

  ~Impl() { close(); }

  void close() {
    following.reset();  // before the query and the session's coordinator
    query.reset();
    session.reset();
  }

  /// Opens a new replay of the log from its start, processed up to its first tick; the current
  /// one is kept when that fails.
  [[nodiscard]] Expected<void> restart() {
    auto opened = replay::ReplaySession::open(options, *registry);
    if (!opened) return tl::unexpected(opened.error());
    close();
    session = std::move(*opened);
    runner::ScenarioRunner& r = session->runner();
    coordinators = coordinators_of(r.system().spec(), r.coordinator());
    system_name = r.system().spec().name;
    introspect::LocalOptions local;
    local.name = system_name;
    local.period = to_seconds(session->period());
    local.scenario = options.input;
    local.duration = to_seconds(session->end());
    query = std::make_unique<introspect::LocalQuery>(r.coordinator(), r.monitor(), *registry, local);
    connections = local_connections(*query);
    pending.clear();
    auto follow = query->follow([this](const introspect::HistoryEntry& e) {
      if (e.kind == RecordKind::Transition || e.kind == RecordKind::ComponentTransition) transition_seen = true;
      pending.push(e);
    });
    if (!follow) return tl::unexpected(follow.error());
    following = std::move(*follow);
    ++generation;
    session->advance_to(session->start());
    return {};
  }

  Time now() const { return session->now(); }
  bool at_end() const { return session->now() >= session->end(); }

  void rebase() {
    base_wall = std::chrono::steady_clock::now();
    base_sim = now();
  }

  /// Advances toward `target`, at most kMaxTicksPerPoll ticks.
  void step_toward(Time target) {
    const Time limit = now() + session->period() * kMaxTicksPerPoll;
    session->advance_to(target < limit ? target : limit);
  }

  void poll() {
    if (seek) {
      step_toward(*seek);
      if (now() + session->period() > *seek || at_end()) {  // the last tick at or before the time asked
        seek.reset();
        rebase();
      }
      return;
    }
    if (next) {
      for (std::int64_t i = 0; i < kMaxTicksPerPoll && !transition_seen && !at_end(); ++i) {
        session->advance_to(now() + session->period());
      }
      if (transition_seen || at_end()) {
        next = false;
        rebase();
      }
      return;
    }
    if (!playing) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - base_wall).count();
    step_toward(base_sim + seconds_to_time(elapsed * speed));
    if (at_end()) playing = false;
  }
};

ReplaySource::ReplaySource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ReplaySource::~ReplaySource() = default;

Expected<std::unique_ptr<ReplaySource>> ReplaySource::open(const ReplaySourceOptions& options) {
  if (options.system.empty()) {
    return fail(ErrorCode::InvalidArgument, "a replay needs the system its log is fed through (--system SYSTEM)");
  }
  if (auto s = check_speed(options.speed); !s) {
    return fail(ErrorCode::InvalidArgument, "--speed: " + s.error().message);
  }
  auto impl = std::make_unique<Impl>();
  if (options.registry != nullptr) impl->registry = options.registry;
  impl->options.system = options.system;
  impl->options.input = options.input;
  impl->options.format = options.format;
  impl->options.mapping = options.mapping;
  impl->speed = options.speed;
  if (auto r = impl->restart(); !r) return tl::unexpected(r.error());
  impl->description =
      fmt::format("replay of {} through {}, {} s to {} s", std::filesystem::path(options.input).filename().string(),
                  std::filesystem::path(options.system).filename().string(), seconds_text(impl->session->start()),
                  seconds_text(impl->session->end()));
  impl->rebase();
  return std::unique_ptr<ReplaySource>(new ReplaySource(std::move(impl)));
}

void ReplaySource::poll() { impl_->poll(); }

void ReplaySource::settle() {
  while (impl_->seek || impl_->next) impl_->poll();
}

introspect::CoverageNow ReplaySource::coverage() const {
  return impl_->query->coverage().value_or(introspect::CoverageNow{});  // in-process: never fails
}

SystemView ReplaySource::view() const {
  SystemView v = local_view(*impl_->query, impl_->coordinators, impl_->connections);
  v.system = impl_->system_name;
  v.description = impl_->description;
  v.t = now();
  v.running = running();
  return v;
}

double ReplaySource::now() const { return to_seconds(impl_->now()); }

bool ReplaySource::running() const { return !impl_->at_end(); }

std::vector<std::string> ReplaySource::take_records() { return impl_->pending.take(); }

Expected<std::vector<Explanation>> ReplaySource::explain(std::string_view address) const {
  return local_explain(*impl_->query, impl_->session->runner().coordinator(), impl_->coordinators, address);
}

namespace {
tl::unexpected<Error> read_only() {
  return fail(ErrorCode::InvalidArgument, "refused: a replay is read-only (it shows what the log holds)");
}
}  // namespace

Expected<std::string> ReplaySource::apply(const introspect::Action&) { return read_only(); }

std::optional<ReplayView> ReplaySource::replay() const {
  ReplayView r;
  r.start = to_seconds(impl_->session->start());
  r.end = to_seconds(impl_->session->end());
  r.period = to_seconds(impl_->session->period());
  r.playing = impl_->playing;
  r.speed = impl_->speed;
  r.busy = impl_->seek ? "seek" : impl_->next ? "next" : "";
  return r;
}

std::uint64_t ReplaySource::generation() const { return impl_->generation; }

Expected<std::string> ReplaySource::control(const ReplayControl& c) {
  Impl& m = *impl_;
  const Time start = m.session->start();
  const Time end = m.session->end();
  switch (c.op) {
    case ReplayControl::Op::Play:
      if (m.at_end()) {  // from the start again, as a player does
        if (auto r = m.restart(); !r) return tl::unexpected(r.error());
      }
      m.playing = true;
      m.next = false;
      m.rebase();
      return fmt::format("playing at speed {:g} from t={}", m.speed, seconds_text(m.now()));
    case ReplayControl::Op::Pause:
      m.playing = false;
      m.next = false;
      return "paused at t=" + seconds_text(m.now());
    case ReplayControl::Op::Speed:
      if (auto s = check_speed(c.speed); !s) return tl::unexpected(s.error());
      m.speed = c.speed;
      m.rebase();
      return fmt::format("speed {:g}", m.speed);
    case ReplayControl::Op::Seek: {
      if (!std::isfinite(c.t) || c.t < to_seconds(start) - 1e-9 || c.t > to_seconds(end) + 1e-9) {
        return fail(ErrorCode::InvalidArgument, fmt::format("t={} is outside the replay ({} s to {} s)", c.t,
                                                            seconds_text(start), seconds_text(end)));
      }
      Time target = seconds_to_time(c.t);
      if (target < start) target = start;
      if (target > end) target = end;
      if (target < m.now()) {
        if (auto r = m.restart(); !r) return tl::unexpected(r.error());
      }
      m.next = false;
      m.seek = target;
      m.rebase();
      return "seeking to t=" + seconds_text(target);
    }
    case ReplayControl::Op::Next:
      if (m.at_end()) return fail(ErrorCode::InvalidArgument, "at the end of the replay: no transition after it");
      m.playing = false;
      m.seek.reset();
      m.next = true;
      m.transition_seen = false;
      return "running on to the next transition from t=" + seconds_text(m.now());
  }
  return fail(ErrorCode::InvalidArgument, "unknown replay control");
}

}  // namespace safecass::viewer
