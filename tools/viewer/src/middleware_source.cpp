#include "safecass/viewer/middleware_source.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>

#include <fmt/format.h>

#include "safecass/filters/registry.hpp"
#include "safecass/introspect/coverage.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/introspect/sample_text.hpp"
#include "safecass/json/write.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/spec/instance.hpp"
#include "safecass/viewer/live_diff.hpp"

namespace safecass::viewer {

namespace {

using middleware::RemoteClient;

/// Records waiting for take_records() beyond this are dropped and counted.
constexpr std::size_t kMaxPendingRecords = 100000;

/// The host's monotonic clock in seconds: the clock of every coordinator process of this host
/// (middleware::HostClock), so records, causes and the page's clock agree.
double host_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Seconds to the millisecond, in the confirmations of writes.
/// When a write was done, as a live system's times are shown: wall-clock time, ISO 8601 in the
/// local zone with milliseconds (the read model's formatter).
std::string wall_now() {
  return introspect::iso8601_local(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

std::string component_of(std::string_view address) { return std::string(address.substr(0, address.find('.'))); }

}  // namespace

/// How often a live coordinator's filter list (its filters' run-time facts) is read at most.
constexpr std::chrono::milliseconds kFiltersPeriod{500};

/// One coordinator of the system: its shape (built locally), what its thread last learnt, and
/// the connection the server thread uses for explain and writes.
struct MiddlewareLink {
  std::string name;
  std::string token;       ///< empty without --token-file for it
  std::string read_token;  ///< its read credential, when it has one
  /// The coordinator's model, built from the system file: its rows before it answers, and its
  /// filters and signals (for routing).
  std::unique_ptr<spec::Instance> local;
  std::vector<std::string> components;
  std::thread thread;

  // Shared with the thread; guarded by Impl::mutex.
  std::vector<introspect::StateRow> rows;
  std::vector<introspect::FilterRow> filters;  ///< as last read (the system file's until it answers)
  bool stale = true;                           ///< records arrived since the rows were fetched: fetch them again
  std::string status = "connecting";
  bool tried = false;
  std::shared_ptr<RemoteClient> requests;

  // The server thread's copy, refreshed in poll().
  std::vector<introspect::StateRow> shown_rows;
  std::string shown_status = "connecting";
};

struct MiddlewareSource::Impl {
  MiddlewareOptions options;
  middleware::IceEndpoint ice;
  const FilterRegistry* registry = nullptr;  // outlives the local monitors
  std::string system_name;
  std::string description;
  std::vector<ConnectionView> connections;   ///< from the system file
  std::vector<introspect::EventRow> events;  ///< from the system file: the onsets' hazards
  std::vector<std::unique_ptr<MiddlewareLink>> links;

  mutable std::mutex mutex;
  std::condition_variable wake;  ///< stop requested, or a first answer arrived
  bool stop = false;
  std::vector<std::string> pending;
  std::uint64_t dropped = 0;
  std::uint64_t version = 0;  ///< bumped whenever a link's rows or status change
  std::uint64_t shown_version = 0;
  std::vector<std::string> taken;  ///< server thread: records handed over by poll()

  ~Impl() {
    {
      std::lock_guard lock(mutex);
      stop = true;
    }
    wake.notify_all();
    for (auto& l : links) {
      if (l->thread.joinable()) l->thread.join();
    }
  }

  void push(std::string record) {  // under mutex
    if (pending.size() >= kMaxPendingRecords) {
      ++dropped;
      return;
    }
    pending.push_back(std::move(record));
  }

  void set_status(MiddlewareLink& l, const std::string& status, const std::string& detail) {  // under mutex
    if (l.status == status) return;
    l.status = status;
    ++version;
    push(coordinator_record(l.name,
                            status.empty()   ? "answering"
                            : detail.empty() ? status
                                             : status + ": " + detail,
                            host_seconds()));
  }

  [[nodiscard]] Expected<std::unique_ptr<RemoteClient>> connect(const MiddlewareLink& l) const {
    middleware::ClientOptions o;
    o.ice = ice;
    o.coordinator = l.name;
    o.token = l.token;
    o.keys_dir = options.keys_dir;
    o.tls.dir = options.tls_dir;
    o.read_token = l.read_token;
    o.timeout = options.timeout;
    return RemoteClient::connect(o);
  }

  /// Sleeps `d` unless stopped; returns false when stopped.
  bool pause(std::chrono::milliseconds d) {
    std::unique_lock lock(mutex);
    return !wake.wait_for(lock, d, [&] { return stop; });
  }

  bool stopping() const {
    std::lock_guard lock(mutex);
    return stop;
  }

  /// The thread of one coordinator: connect, follow its pushed records, and fetch its state list
  /// once when it answers and again after each batch of records. Every `retry` without records it
  /// asks for the records after the last one pushed (that checks that the coordinator still
  /// answers and delivers a lost record that no later one revealed) and fetches the list again.
  void follow(MiddlewareLink& l) {
    std::unique_ptr<RemoteClient> reader;
    std::unique_ptr<introspect::Subscription> records;
    bool answered = false;
    std::chrono::steady_clock::time_point filters_read{};
    auto lose = [&](const std::string& why) {
      records.reset();  // before the client it belongs to
      reader.reset();
      std::lock_guard lock(mutex);
      l.requests.reset();
      set_status(l, answered ? "lost" : "unreachable", why);
      l.tried = true;
    };
    while (!stopping()) {
      if (!reader) {
        // Two clients: `c` follows and fetches on this thread, `r` serves explain and writes for
        // the server thread (a RemoteClient is used by one thread at a time).
        auto c = connect(l);
        Expected<std::unique_ptr<RemoteClient>> r =
            c ? connect(l) : Expected<std::unique_ptr<RemoteClient>>(tl::unexpected(c.error()));
        if (!c || !r) {
          lose((!c ? c.error() : r.error()).message);
          wake.notify_all();
          if (!pause(options.retry)) return;
          continue;
        }
        reader = std::move(*c);
        MiddlewareLink* link = &l;
        auto sub = reader->follow([this, link](const introspect::HistoryEntry& e) {
          std::lock_guard lock(mutex);
          push(introspect::history_json(e));
          link->stale = true;
          ++version;
          wake.notify_all();
        });
        if (!sub) {
          lose(sub.error().message);
          wake.notify_all();
          if (!pause(options.retry)) return;
          continue;
        }
        records = std::move(*sub);
        std::lock_guard lock(mutex);
        l.requests = std::shared_ptr<RemoteClient>(std::move(*r));
        l.stale = true;
      }
      {
        std::lock_guard lock(mutex);
        l.stale = false;
      }
      auto answer = reader->state_list();
      // The filters' facts (the hazards' coverage) at most every kFiltersPeriod: a second request
      // per state list would double the coordinator's load of a busy page.
      const auto now = std::chrono::steady_clock::now();
      const bool refilter = !answered || now - filters_read >= kFiltersPeriod;
      auto filters = answer && refilter ? reader->filter_list() : Expected<std::vector<introspect::FilterRow>>();
      if (!answer || !filters) {
        lose((!answer ? answer.error() : filters.error()).message);
        continue;
      }
      if (refilter) filters_read = now;
      answered = true;
      {
        std::lock_guard lock(mutex);
        set_status(l, "", {});
        if (*answer != l.rows) {
          l.rows = std::move(*answer);
          ++version;
        }
        if (refilter) l.filters = std::move(*filters);
        l.tried = true;
      }
      wake.notify_all();
      // Wait for records (which make the rows stale) or for the next liveness check.
      std::unique_lock lock(mutex);
      const bool woken = wake.wait_for(lock, options.retry, [&] { return stop || l.stale; });
      if (stop) return;
      if (!woken) {
        // Quiet for `retry`: the liveness check asks for the records after the last pushed one, so
        // a record lost on the bus with nothing after it still reaches the page (and the rows).
        lock.unlock();
        if (auto caught = records->catch_up(); !caught) lose(caught.error().message);
      }
    }
  }

  MiddlewareLink* owner(std::string_view address) const {
    const std::string component = component_of(address);
    for (const auto& l : links) {
      if (std::find(l->components.begin(), l->components.end(), component) != l->components.end()) return l.get();
    }
    return nullptr;
  }

  MiddlewareLink* link_named(std::string_view name) const {
    for (const auto& l : links) {
      if (l->name == name) return l.get();
    }
    return nullptr;
  }

  /// The request connection of `l`, or an Io error saying that it does not answer.
  [[nodiscard]] Expected<std::shared_ptr<RemoteClient>> requests(const MiddlewareLink& l) const {
    std::lock_guard lock(mutex);
    if (!l.requests) {
      return fail(ErrorCode::Io, "coordinator '" + l.name + "' is " +
                                     (l.status.empty() ? std::string("not connected") : l.status) + " (IceStorm " +
                                     options.ice + ")");
    }
    return l.requests;
  }

  /// The request connection of the coordinator owning `target` for a write.
  [[nodiscard]] Expected<std::pair<MiddlewareLink*, std::shared_ptr<RemoteClient>>> writer(
      std::string_view target, std::string_view what) const {
    if (!options.allow_write)
      return fail(ErrorCode::Denied, "refused: this viewer is read-only (start it with --allow-write)");
    MiddlewareLink* l = owner(target);
    if (l == nullptr) {
      return fail(ErrorCode::NotFound, std::string(what) + ": no component '" + component_of(target) + "' in system '" +
                                           system_name + "' (target '" + std::string(target) + "')");
    }
    return writer_of(*l);
  }

  [[nodiscard]] Expected<std::pair<MiddlewareLink*, std::shared_ptr<RemoteClient>>> writer_of(MiddlewareLink& l) const {
    if (!options.allow_write)
      return fail(ErrorCode::Denied, "refused: this viewer is read-only (start it with --allow-write)");
    if (l.token.empty()) {
      return fail(ErrorCode::Denied, "refused: no token for coordinator '" + l.name +
                                         "' (start the viewer with --token-file " + l.name +
                                         "=FILE, the file its `safecass run --allow-write --token-file` wrote)");
    }
    auto c = requests(l);
    if (!c) return tl::unexpected(c.error());
    return std::pair<MiddlewareLink*, std::shared_ptr<RemoteClient>>{&l, *c};
  }
};

MiddlewareSource::MiddlewareSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MiddlewareSource::~MiddlewareSource() = default;

Expected<std::unique_ptr<MiddlewareSource>> MiddlewareSource::open(const MiddlewareOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  auto ice = middleware::parse_ice_endpoint(options.ice);
  if (!ice) return fail(ErrorCode::Parse, ice.error().message);  // it names --ice and the text
  impl->ice = *ice;
  if (options.system.empty()) return fail(ErrorCode::InvalidArgument, "--ice needs the system file (--system)");
  impl->registry = options.registry != nullptr ? options.registry : &builtin_filters();
  auto loaded = spec::load_valid_system(options.system, *impl->registry);
  if (!loaded) return fail(ErrorCode::Parse, spec::to_text(loaded.error()));
  const spec::SystemSpec& system = *loaded;
  if (system.coordinators.empty()) {
    return fail(ErrorCode::InvalidArgument,
                "system '" + system.name + "' (" + options.system +
                    ") has no \"coordinators\": it runs as one process; view it in-process (--system without --ice)");
  }
  impl->system_name = system.name;
  for (const spec::ConnectionSpec& c : system.connections) impl->connections.push_back({c.required, c.provided});
  std::string names;
  for (const auto& [name, components] : system.coordinators) {
    auto l = std::make_unique<MiddlewareLink>();
    l->name = name;
    l->components = components;
    spec::InstanceOptions only;
    only.coordinator = name;
    auto built = spec::build_instance(system, *impl->registry, only);
    if (!built) return fail(ErrorCode::InvalidArgument, spec::to_text(built.error()));
    l->local = std::move(*built);
    introspect::LocalQuery skeleton(l->local->coordinator(), l->local->monitor(), *impl->registry);
    l->rows = *skeleton.state_list();
    l->shown_rows = l->rows;
    l->filters = *skeleton.filter_list();
    if (impl->events.empty()) impl->events = *skeleton.event_list();
    names += (names.empty() ? "" : ", ") + name;
    impl->links.push_back(std::move(l));
  }
  for (const auto& [name, path] : options.token_files) {
    MiddlewareLink* l = impl->link_named(name);
    if (l == nullptr) {
      return fail(ErrorCode::InvalidArgument, "--token-file " + name + "=" + path + ": system '" + system.name +
                                                  "' has no coordinator '" + name + "' (it has " + names + ")");
    }
    auto token = middleware::read_token_file(path);
    if (!token) return fail(token.error().code, "--token-file " + name + "=" + path + ": " + token.error().message);
    l->token = *token;
  }
  for (const auto& [name, path] : options.read_token_files) {
    MiddlewareLink* l = impl->link_named(name);
    if (l == nullptr) {
      return fail(ErrorCode::InvalidArgument, "--read-token-file " + name + "=" + path + ": system '" + system.name +
                                                  "' has no coordinator '" + name + "' (it has " + names + ")");
    }
    auto token = middleware::read_token_file(path);
    if (!token)
      return fail(token.error().code, "--read-token-file " + name + "=" + path + ": " + token.error().message);
    l->read_token = *token;
  }
  impl->description = "live: " + std::filesystem::path(options.system).filename().string() + " through IceStorm " +
                      middleware::to_string(impl->ice) + ", coordinators " + names;

  Impl* self = impl.get();
  for (auto& l : impl->links) {
    MiddlewareLink* link = l.get();
    l->thread = std::thread([self, link] { self->follow(*link); });
  }
  {
    std::unique_lock lock(impl->mutex);
    impl->wake.wait_for(lock, options.first_wait, [&] {
      return std::all_of(impl->links.begin(), impl->links.end(), [](const auto& l) { return l->tried; });
    });
  }
  auto source = std::unique_ptr<MiddlewareSource>(new MiddlewareSource(std::move(impl)));
  source->poll();
  return source;
}

void MiddlewareSource::poll() {
  Impl& m = *impl_;
  std::lock_guard lock(m.mutex);
  if (m.taken.empty()) {
    m.taken.swap(m.pending);
  } else {
    for (std::string& r : m.pending) m.taken.push_back(std::move(r));
    m.pending.clear();
  }
  if (m.dropped != 0) {
    m.taken.push_back(
        json::JsonObject().str("kind", "overflow").integer("dropped", static_cast<long long>(m.dropped)).text());
    m.dropped = 0;
  }
  if (m.version == m.shown_version) return;
  for (auto& l : m.links) {
    l->shown_rows = l->rows;
    l->shown_status = l->status;
  }
  m.shown_version = m.version;
}

introspect::CoverageNow MiddlewareSource::coverage() const {
  // Each coordinator answers for its own filters; one that is lost, or has not answered yet, can
  // vouch for none of them.
  std::vector<introspect::ProcessFilters> processes;
  {
    std::lock_guard lock(impl_->mutex);
    for (const auto& l : impl_->links) processes.push_back({l->name, !l->status.empty(), l->filters});
  }
  return introspect::coverage_now(
      impl_->events, processes, {},
      std::chrono::duration_cast<Time>(std::chrono::steady_clock::now().time_since_epoch()));
}

SystemView MiddlewareSource::view() const {
  SystemView v;
  v.system = impl_->system_name;
  v.description = impl_->description;
  v.t = now();
  v.running = running();
  v.connections = impl_->connections;
  // The records' times are the host's monotonic clock (host_seconds()): shown as wall-clock time.
  v.host_clock = true;
  v.wall_offset_ns = (std::chrono::duration_cast<Time>(std::chrono::system_clock::now().time_since_epoch()) -
                      std::chrono::duration_cast<Time>(std::chrono::steady_clock::now().time_since_epoch()))
                         .count();
  for (const auto& l : impl_->links) {
    CoordinatorView cv = coordinator_view(l->name, l->shown_rows);
    cv.status = l->shown_status;
    v.state = std::max(v.state, cv.state);
    v.coordinators.push_back(std::move(cv));
  }
  return v;
}

double MiddlewareSource::now() const { return host_seconds(); }

bool MiddlewareSource::running() const { return true; }  // a live system has no scenario that ends

std::vector<std::string> MiddlewareSource::take_records() {
  std::vector<std::string> out;
  out.swap(impl_->taken);
  return out;
}

std::uint64_t MiddlewareSource::view_version() const { return impl_->shown_version; }  // server thread, as poll()

std::string MiddlewareSource::status(std::string_view coordinator) const {
  std::lock_guard lock(impl_->mutex);
  const MiddlewareLink* l = impl_->link_named(coordinator);
  return l == nullptr ? std::string("unknown") : l->status;
}

Expected<std::vector<Explanation>> MiddlewareSource::explain(std::string_view address) const {
  const Impl& m = *impl_;
  std::vector<Explanation> all;
  auto add = [&](const MiddlewareLink& l, const std::string& a) -> Expected<void> {
    auto c = m.requests(l);
    if (!c) return tl::unexpected(c.error());
    auto part = (*c)->explain(a);
    if (!part) return tl::unexpected(part.error());
    all.insert(all.end(), part->conditions.begin(), part->conditions.end());
    return {};
  };
  if (address == "SYSTEM") {  // every coordinator that answers
    bool any = false;
    for (const auto& l : m.links) {
      for (const std::string& c : l->components) {
        if (auto r = add(*l, c); !r) break;
        any = true;
      }
    }
    if (!any) return fail(ErrorCode::Io, "no coordinator of system '" + m.system_name + "' answers");
    return all;
  }
  if (address.substr(0, 12) == "coordinator:") {
    const MiddlewareLink* l = m.link_named(address.substr(12));
    if (l == nullptr) return fail(ErrorCode::NotFound, "no coordinator '" + std::string(address.substr(12)) + "'");
    for (const std::string& c : l->components) {
      if (auto r = add(*l, c); !r) return tl::unexpected(r.error());
    }
    return all;
  }
  const MiddlewareLink* l = m.owner(address);
  if (l == nullptr) {
    return fail(ErrorCode::NotFound, "no component '" + component_of(address) + "' in system '" + m.system_name +
                                         "' (address '" + std::string(address) + "')");
  }
  if (auto r = add(*l, std::string(address)); !r) return tl::unexpected(r.error());
  return all;
}

Expected<std::string> MiddlewareSource::apply(const introspect::Action& action) {
  return std::visit(
      [&](const auto& a) -> Expected<std::string> {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, introspect::GenerateEvent>) {
          return generate(a.event, a.target);
        } else if constexpr (std::is_same_v<A, introspect::BroadcastEvent>) {
          return broadcast(a.event);
        } else if constexpr (std::is_same_v<A, introspect::ResetState>) {
          return reset(a);
        } else if constexpr (std::is_same_v<A, introspect::InjectShallow>) {
          return inject(false, a.filter, a.samples);
        } else if constexpr (std::is_same_v<A, introspect::InjectDeep>) {
          return inject(true, a.signal, a.samples);
        } else {
          return fail(ErrorCode::InvalidArgument, "a sample of " + a.signal +
                                                      " cannot be pushed to a live coordinator: its samples come from "
                                                      "its own framework");
        }
      },
      action);
}

Expected<std::string> MiddlewareSource::generate(const std::string& event, const std::string& target) {
  auto w = impl_->writer(target, "event generate");
  if (!w) return tl::unexpected(w.error());
  if (auto r = w->second->apply(introspect::GenerateEvent{event, target}); !r) return tl::unexpected(r.error());
  return "generated " + event + " on " + target + " (coordinator " + w->first->name + ") at " + wall_now();
}

Expected<std::string> MiddlewareSource::broadcast(const std::string& event) {
  // Every coordinator defines every event of the system, so the first refusal (an unknown event,
  // a wrong token) comes before anything was changed.
  std::string done;
  std::string failed;
  for (auto& l : impl_->links) {
    auto w = impl_->writer_of(*l);
    auto r = w ? w->second->apply(introspect::BroadcastEvent{event}) : Expected<void>(tl::unexpected(w.error()));
    if (!r) {
      if (done.empty()) return fail(r.error().code, "coordinator '" + l->name + "': " + r.error().message);
      failed += "; not on " + l->name + ": " + r.error().message;
      continue;
    }
    done += (done.empty() ? "" : ", ") + l->name;
  }
  return "broadcast " + event + " on coordinators " + done + " at " + wall_now() + failed;
}

Expected<std::string> MiddlewareSource::inject(bool deep, const std::string& target,
                                               const std::vector<std::vector<double>>& samples) {
  if (samples.empty()) return fail(ErrorCode::InvalidArgument, "no samples to inject");
  const std::string n = introspect::count_text(samples.size());
  MiddlewareLink* owner = nullptr;
  if (deep) {
    owner = impl_->owner(target);
    if (owner == nullptr || owner->local->monitor().signals().find(target) == nullptr) {
      return fail(ErrorCode::NotFound, "no signal '" + target + "' (signals are written Component.signal)");
    }
  } else {
    for (auto& l : impl_->links) {
      if (l->local->monitor().find_filter(target) != nullptr) owner = l.get();
    }
    if (owner == nullptr) return fail(ErrorCode::NotFound, "no filter '" + target + "'");
  }
  auto w = impl_->writer_of(*owner);
  if (!w) return tl::unexpected(w.error());
  auto r = deep ? w->second->apply(introspect::InjectDeep{target, samples})
                : w->second->apply(introspect::InjectShallow{target, samples});
  if (!r) return tl::unexpected(r.error());
  return (deep ? "wrote " + n + " into signal " : "queued " + n + " into filter ") + target + " (coordinator " +
         owner->name + ") at " + wall_now();
}

Expected<std::string> MiddlewareSource::reset(const introspect::ResetState& reset) {
  const std::string& target = reset.target;
  const std::string& reason = reset.why;
  if (target == "SYSTEM") {
    std::string done;
    for (auto& l : impl_->links) {
      auto w = impl_->writer_of(*l);
      auto r = w ? w->second->apply(reset) : Expected<void>(tl::unexpected(w.error()));
      if (!r)
        return fail(r.error().code, "coordinator '" + l->name + "': " + r.error().message +
                                        (done.empty() ? "" : " (reset done on " + done + ")"));
      done += (done.empty() ? "" : ", ") + l->name;
    }
    return "reset SYSTEM (coordinators " + done + ") at " + wall_now() + " (" + reason + ")";
  }
  auto w = impl_->writer(target, "reset");
  if (!w) return tl::unexpected(w.error());
  if (auto r = w->second->apply(reset); !r) return tl::unexpected(r.error());
  return "reset " + target + " (coordinator " + w->first->name + ") at " + wall_now() + " (" + reason + ")";
}

}  // namespace safecass::viewer
