#include "safecass/ros1/bridge.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcException.h>

#include "extract.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::ros1 {

namespace {

std::string join_diagnostics(const std::vector<spec::Diagnostic>& diagnostics) {
  std::string out;
  for (const spec::Diagnostic& d : diagnostics) {
    if (d.severity != spec::Diagnostic::Severity::Error) continue;
    out += (out.empty() ? "" : "\n") + spec::format(d);
  }
  return out;
}

std::string fmt_double(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

diagnostic_msgs::KeyValue kv(std::string key, std::string value) {
  diagnostic_msgs::KeyValue k;
  k.key = std::move(key);
  k.value = std::move(value);
  return k;
}

}  // namespace

struct Bridge::Impl {
  struct Bound {
    Signal* signal = nullptr;
    FieldPath path;
    std::size_t width = 1;
  };
  struct Topic {
    const TopicMapping* map = nullptr;
    std::vector<Bound> bound;
    std::vector<double> scratch;   ///< all bound values of one message, so a bad message pushes nothing
    std::vector<ComponentId> run;  ///< components whose ACTIVE filters each message runs
    Signal* rate = nullptr;
    Signal* age = nullptr;
    std::array<Time, 10> arrivals{};
    std::size_t arrival_count = 0;
    std::atomic<Time::rep> last_arrival{-1};
    MachineId provided = kNoMachine;  ///< kNoMachine when the provider is not local
    std::vector<MachineId> required;  ///< per mapping.required; kNoMachine when not local
    ros::Subscriber subscriber;
  };
  struct Loop {
    ComponentId component = kNoComponent;
    Time period{};
    Body body;
    bool threw = false;
    bool overran = false;
    ros::Timer timer;
  };
  struct Ingest {
    const IngestRule* rule = nullptr;
    MachineId target = kNoMachine;
    std::array<EventId, 3> onset{};                              ///< WARN, ERROR, STALE
    std::map<std::string, DiagnosticLevel, std::less<>> levels;  ///< per status name
    std::array<bool, 3> active{};
  };

  Mapping mapping;
  std::unique_ptr<Coordinator> coordinator;
  std::unique_ptr<Monitor> monitor;
  std::vector<std::unique_ptr<Topic>> topics;
  std::vector<std::unique_ptr<Loop>> loops;
  std::vector<Ingest> ingests;
  EventId graph_event = kNoEvent;
  NameId graph_name = kNoName;
  NameId diagnostics_name = kNoName;

  bool started = false;
  std::unique_ptr<ros::NodeHandle> node_handle;
  ros::Publisher publisher;
  ros::Subscriber ingest_subscriber;
  ros::Timer tick_timer;
  Time last_publish{};
  std::atomic<bool> dirty{true};
  Coordinator::SubscriptionId observer = 0;
  bool observing = false;

  std::thread graph_thread;
  std::mutex graph_mutex;
  std::condition_variable graph_wake;
  bool graph_stop = false;
  std::map<MachineId, std::set<std::string>> graph_problems;  ///< graph thread only

  std::atomic<std::uint64_t> messages{0}, bad_messages{0}, published{0}, ingested{0}, bad_statuses{0}, graph_checks{0},
      graph_problem_count{0};

  [[nodiscard]] Expected<void> bind();
  template <class M>
  void on_message(Topic& t, const M& msg);
  void on_diagnostics(const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& event);
  void on_tick();
  void run_loop(Loop& loop);
  void publish_diagnostics();
  void fill_status(diagnostic_msgs::DiagnosticStatus& s, const std::string& address, StateSnapshot snap,
                   const std::optional<Condition>& outstanding) const;
  void graph_loop();
  void check_graph();
  std::string status_name(std::string_view address) const { return mapping.prefix + ": " + std::string(address); }
};

// ---- construction --------------------------------------------------------------------------------

Expected<std::unique_ptr<Bridge>> Bridge::create(const std::string& mapping_path, const FilterRegistry& registry,
                                                 const Clock* clock) {
  MappingLoad ml = load_mapping(mapping_path);
  if (!ml.mapping) return fail(ErrorCode::Parse, join_diagnostics(ml.diagnostics));
  spec::LoadResult sys = spec::load_system(ml.mapping->system, registry);
  if (!sys.ok()) return fail(ErrorCode::Parse, join_diagnostics(sys.diagnostics));

  auto impl = std::make_unique<Impl>();
  impl->mapping = std::move(*ml.mapping);
  const std::string name = impl->mapping.coordinator.empty() ? sys.system->name : impl->mapping.coordinator;
  impl->coordinator = std::make_unique<Coordinator>(name, clock);
  impl->monitor = std::make_unique<Monitor>(*impl->coordinator, registry);
  if (auto r = spec::instantiate(*sys.system, *impl->coordinator, *impl->monitor, impl->mapping.coordinator); !r) {
    return tl::unexpected(r.error());
  }
  Coordinator& co = *impl->coordinator;
  const std::string where = impl->mapping.path + ": ";
  for (const EventDef& e : impl->mapping.events) {
    if (auto r = co.add_event(e); !r)
      return fail(r.error().code, where + "event '" + e.name + "': " + r.error().message);
  }
  for (const EventDef& e : default_ros_events()) {
    if (co.find_event(e.name)) continue;
    if (auto r = co.add_event(e); !r)
      return fail(r.error().code, where + "event '" + e.name + "': " + r.error().message);
  }
  // Which connections the system declares, to check the topics against.
  std::set<std::pair<std::string, std::string>> connections;
  for (const spec::ConnectionSpec& c : sys.system->connections) connections.emplace(c.required, c.provided);
  std::set<std::string> components;
  for (const spec::ComponentSpec& c : sys.system->components) components.insert(c.name);
  for (const auto& n : impl->mapping.nodes) {
    if (components.count(n.first) == 0) {
      return fail(ErrorCode::NotFound,
                  where + "nodes: system '" + sys.system->name + "' has no component '" + n.first + "'");
    }
  }
  for (const TopicMapping& t : impl->mapping.topics) {
    for (const std::string& r : t.required) {
      if (!t.provided.empty() && connections.count({r, t.provided}) == 0) {
        return fail(ErrorCode::NotFound, where + "topic '" + t.topic + "' carries " + t.provided + " to " + r +
                                             ", but the system has no connection between them");
      }
    }
  }
  if (auto r = impl->bind(); !r) return tl::unexpected(Error{r.error().code, where + r.error().message});
  return std::unique_ptr<Bridge>(new Bridge(std::move(impl)));
}

Expected<void> Bridge::Impl::bind() {
  Coordinator& co = *coordinator;
  // An interface "C.x" whose component is not in this coordinator is somebody else's: kNoMachine.
  auto machine_of = [&](const std::string& iface, const char* kind) -> Expected<MachineId> {
    const std::string component = iface.substr(0, iface.find('.'));
    if (!co.find_component(component)) return kNoMachine;
    return co.find_machine(component + "." + kind + "." + iface.substr(iface.find('.') + 1));
  };
  auto check_target = [&](const std::string& address) -> Expected<FilterTarget> {
    auto m = co.find_machine(address);
    if (!m) return tl::unexpected(m.error());
    FilterTarget t;
    t.kind = co.machine_kind(*m);
    t.component = std::string(co.component_name(co.machine_component(*m)));
    if (t.kind == MachineKind::Provided || t.kind == MachineKind::Required)
      t.interface = std::string(co.interface_name(*m));
    return t;
  };
  auto need_onset = [&](const std::string& event, const std::string& what) -> Expected<EventId> {
    auto e = co.find_event(event);
    if (!e) return fail(ErrorCode::NotFound, what + ": no event '" + event + "'");
    if (!co.event(*e).is_onset)
      return fail(ErrorCode::InvalidArgument, what + ": '" + event + "' is a completion, not an onset");
    if (co.event(*e).counterpart == kNoEvent) {
      return fail(ErrorCode::InvalidArgument, what + ": '" + event + "' has no completion, so it could never clear");
    }
    return *e;
  };

  for (const TopicMapping& tm : mapping.topics) {
    auto t = std::make_unique<Topic>();
    t->map = &tm;
    const std::string what = "topic '" + tm.topic + "'";
    if (!tm.provided.empty()) {
      auto m = machine_of(tm.provided, "s_P");
      if (!m) return fail(m.error().code, what + ": " + m.error().message);
      t->provided = *m;
    }
    for (const std::string& r : tm.required) {
      auto m = machine_of(r, "s_R");
      if (!m) return fail(m.error().code, what + ": " + m.error().message);
      t->required.push_back(*m);
    }
    std::size_t total = 0;
    for (const FieldBinding& b : tm.signals) {
      Signal* s = monitor->signals().find(b.signal);
      std::size_t width = b.path.width();
      if (width == 0) width = b.size != 0 ? b.size : (s != nullptr ? s->size() : 0);
      if (width == 0) {
        return fail(ErrorCode::InvalidArgument,
                    what + ": signal '" + b.signal + "' reads the whole array '" + b.path.text +
                        "': declare the signal in the spec or give {\"field\": ..., \"size\": N}");
      }
      if (s == nullptr) {
        auto created = monitor->add_signal(b.signal, width);
        if (!created) return fail(created.error().code, what + ": " + created.error().message);
        s = *created;
      } else if (s->size() != width) {
        return fail(ErrorCode::InvalidArgument, what + ": field '" + b.path.text + "' gives " + std::to_string(width) +
                                                    " doubles but signal '" + b.signal + "' has " +
                                                    std::to_string(s->size()));
      }
      t->bound.push_back(Bound{s, b.path, width});
      total += width;
    }
    t->scratch.resize(total);
    for (auto [name, out] :
         {std::pair<const std::string*, Signal**>{&tm.rate_signal, &t->rate}, {&tm.age_signal, &t->age}}) {
      if (name->empty()) continue;
      auto s = monitor->add_signal(*name, 1);
      if (!s) return fail(s.error().code, what + ": " + s.error().message);
      *out = *s;
    }
    for (const auto* check : {&tm.watchdog, &tm.frequency}) {
      if (!*check) continue;
      const bool watchdog = check == &tm.watchdog;
      auto target = check_target((*check)->target);
      if (!target) return fail(target.error().code, what + ": " + target.error().message);
      auto onset = need_onset((*check)->event, what);
      if (!onset) return tl::unexpected(onset.error());
      FilterConfig f;
      f.name = "ros" + tm.topic + (watchdog ? ":watchdog" : ":frequency");
      f.type = watchdog ? "Watchdog" : "Frequency";
      f.target = *target;
      f.execution = ExecutionMode::Passive;
      f.params["input_signal"] = tm.rate_signal;
      f.params["event_onset"] = (*check)->event;
      f.params["event_completion"] = co.event(co.event(*onset).counterpart).name;
      if (watchdog) {
        f.params["timeout"] = (*check)->timeout;
      } else {
        f.params["min_rate"] = (*check)->min_rate;
        f.params["max_rate"] = (*check)->max_rate;
        f.params["window"] = static_cast<double>((*check)->window);
      }
      if (auto r = monitor->add_filter(std::move(f)); !r) return fail(r.error().code, what + ": " + r.error().message);
    }
    topics.push_back(std::move(t));
  }

  for (const IngestRule& rule : mapping.ingest) {
    Ingest in;
    in.rule = &rule;
    const std::string what = "ingest rule '" + rule.name + "'";
    auto m = co.find_machine(rule.target);
    if (!m) return fail(m.error().code, what + ": " + m.error().message);
    in.target = *m;
    const std::array<const std::string*, 3> names{&rule.warn, &rule.error, &rule.stale};
    for (std::size_t i = 0; i < 3; ++i) {
      auto e = need_onset(*names[i], what);
      if (!e) return tl::unexpected(e.error());
      in.onset[i] = *e;
    }
    ingests.push_back(std::move(in));
  }
  auto g = need_onset(mapping.graph_event, "graph");
  if (!g) return tl::unexpected(g.error());
  graph_event = *g;
  graph_name = co.intern("ros:graph");
  diagnostics_name = co.intern("ros:diagnostics");
  if (mapping.hardware_id.empty()) mapping.hardware_id = std::string(co.name());
  return {};
}

Bridge::Bridge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Bridge::~Bridge() { stop(); }

Coordinator& Bridge::coordinator() noexcept { return *impl_->coordinator; }
Monitor& Bridge::monitor() noexcept { return *impl_->monitor; }
const Mapping& Bridge::mapping() const noexcept { return impl_->mapping; }
std::string Bridge::status_name(std::string_view address) const { return impl_->status_name(address); }

BridgeStats Bridge::stats() const noexcept {
  BridgeStats s;
  s.messages = impl_->messages.load();
  s.bad_messages = impl_->bad_messages.load();
  s.diagnostics_published = impl_->published.load();
  s.statuses_ingested = impl_->ingested.load();
  s.bad_statuses = impl_->bad_statuses.load();
  s.graph_checks = impl_->graph_checks.load();
  s.graph_problems = impl_->graph_problem_count.load();
  return s;
}

Expected<void> Bridge::add_loop(std::string_view component, Time period, Body body) {
  if (impl_->started) return fail(ErrorCode::InvalidState, "add_loop() after start()");
  auto c = impl_->coordinator->find_component(component);
  if (!c) return tl::unexpected(c.error());
  if (period <= Time{0})
    return fail(ErrorCode::InvalidArgument, "loop of '" + std::string(component) + "': period must be positive");
  for (const auto& l : impl_->loops) {
    if (l->component == *c)
      return fail(ErrorCode::InvalidArgument, "component '" + std::string(component) + "' already has a loop");
  }
  auto loop = std::make_unique<Impl::Loop>();
  loop->component = *c;
  loop->period = period;
  loop->body = std::move(body);
  impl_->loops.push_back(std::move(loop));
  return {};
}

// ---- running -------------------------------------------------------------------------------------

Expected<void> Bridge::start() {
  Impl& d = *impl_;
  if (d.started) return fail(ErrorCode::InvalidState, "the bridge is already started");
  if (!ros::isInitialized()) return fail(ErrorCode::InvalidState, "call ros::init() before Bridge::start()");
  if (!ros::master::check()) return fail(ErrorCode::InvalidState, "no ROS master at " + ros::master::getURI());
  d.node_handle = std::make_unique<ros::NodeHandle>();
  ros::NodeHandle& nh = *d.node_handle;

  // A component with a loop of its own runs its ACTIVE filters there; the others on each message.
  for (auto& t : d.topics) {
    for (const Impl::Bound& b : t->bound) {
      const ComponentId c = b.signal->component();
      const bool looped = std::any_of(d.loops.begin(), d.loops.end(), [c](const auto& l) { return l->component == c; });
      if (!looped && std::find(t->run.begin(), t->run.end(), c) == t->run.end()) t->run.push_back(c);
    }
    Impl::Topic* topic = t.get();
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    switch (t->map->type) {
      case MessageType::Float64:
        t->subscriber = nh.subscribe<std_msgs::Float64>(
            t->map->topic, 100, [&d, topic](const std_msgs::Float64::ConstPtr& m) { d.on_message(*topic, *m); },
            ros::VoidConstPtr(), hints);
        break;
      case MessageType::WrenchStamped:
        t->subscriber = nh.subscribe<geometry_msgs::WrenchStamped>(
            t->map->topic, 100,
            [&d, topic](const geometry_msgs::WrenchStamped::ConstPtr& m) { d.on_message(*topic, *m); },
            ros::VoidConstPtr(), hints);
        break;
      case MessageType::JointState:
        t->subscriber = nh.subscribe<sensor_msgs::JointState>(
            t->map->topic, 100, [&d, topic](const sensor_msgs::JointState::ConstPtr& m) { d.on_message(*topic, *m); },
            ros::VoidConstPtr(), hints);
        break;
    }
  }
  d.publisher = nh.advertise<diagnostic_msgs::DiagnosticArray>(d.mapping.publish_topic, 10);
  if (!d.ingests.empty()) {
    d.ingest_subscriber = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        d.mapping.ingest_topic, 50,
        [&d](const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& e) { d.on_diagnostics(e); });
  }
  for (auto& l : d.loops) {
    Impl::Loop* loop = l.get();
    l->timer =
        nh.createTimer(ros::Duration(to_seconds(l->period)), [&d, loop](const ros::TimerEvent&) { d.run_loop(*loop); });
  }
  d.observer = d.coordinator->subscribe([&d](const Record& r) {
    if (r.kind != RecordKind::Event && r.kind != RecordKind::Injection) d.dirty.store(true, std::memory_order_release);
  });
  d.observing = true;
  d.tick_timer = nh.createTimer(ros::Duration(0.02), [&d](const ros::TimerEvent&) { d.on_tick(); });
  d.monitor->start();
  if (d.mapping.graph_period > 0) {
    d.graph_stop = false;
    d.graph_thread = std::thread([&d] { d.graph_loop(); });
  }
  d.started = true;
  return {};
}

void Bridge::stop() noexcept {
  Impl& d = *impl_;
  if (!d.started) return;
  {
    std::lock_guard<std::mutex> lock(d.graph_mutex);
    d.graph_stop = true;
  }
  d.graph_wake.notify_all();
  if (d.graph_thread.joinable()) d.graph_thread.join();
  d.monitor->stop();
  d.tick_timer.stop();
  for (auto& l : d.loops) l->timer.stop();
  for (auto& t : d.topics) t->subscriber.shutdown();
  d.ingest_subscriber.shutdown();
  d.publisher.shutdown();
  if (d.observing) d.coordinator->unsubscribe(d.observer);
  d.observing = false;
  d.node_handle.reset();
  d.started = false;
}

template <class M>
void Bridge::Impl::on_message(Topic& t, const M& msg) {
  const Time now = coordinator->clock().now();
  std::string error;
  std::size_t offset = 0;
  for (const Bound& b : t.bound) {
    if (!detail::extract(b.path, msg, t.scratch.data() + offset, b.width, error)) {
      bad_messages.fetch_add(1, std::memory_order_relaxed);
      ROS_WARN_THROTTLE(5.0, "safecass: message on %s rejected (%s); nothing was changed", t.map->topic.c_str(),
                        error.c_str());
      return;
    }
    offset += b.width;
  }
  offset = 0;
  for (const Bound& b : t.bound) {
    b.signal->push(now, t.scratch.data() + offset);
    offset += b.width;
  }
  // Rate over the last arrivals (0 until two messages have arrived).
  t.arrivals[t.arrival_count % t.arrivals.size()] = now;
  ++t.arrival_count;
  if (t.rate != nullptr) {
    double rate = 0.0;
    const std::size_t n = std::min(t.arrival_count, t.arrivals.size());
    if (n >= 2) {
      const Time oldest = t.arrivals[(t.arrival_count - n) % t.arrivals.size()];
      const double span = to_seconds(now - oldest);
      if (span > 0) rate = static_cast<double>(n - 1) / span;
    }
    t.rate->push(now, rate);
  }
  t.last_arrival.store(now.count(), std::memory_order_release);
  messages.fetch_add(1, std::memory_order_relaxed);
  for (ComponentId c : t.run) monitor->run_active(c, now);
}

void Bridge::Impl::run_loop(Loop& loop) {
  const auto begin = std::chrono::steady_clock::now();
  const Time now = coordinator->clock().now();
  monitor->run_active(loop.component, now);
  const MachineId framework = coordinator->framework_machine(loop.component);
  try {
    if (loop.body) loop.body(now);
    if (loop.threw) {
      loop.threw = false;
      coordinator->generate(framework_event::completion_of(framework_event::kThreadException), framework);
    }
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5.0, "safecass: the loop of %s threw: %s",
                       std::string(coordinator->component_name(loop.component)).c_str(), e.what());
    if (!loop.threw) coordinator->generate(framework_event::kThreadException, framework);
    loop.threw = true;
  } catch (...) {
    if (!loop.threw) coordinator->generate(framework_event::kThreadException, framework);
    loop.threw = true;
  }
  const bool overran = std::chrono::steady_clock::now() - begin > loop.period;
  if (overran != loop.overran) {
    loop.overran = overran;
    coordinator->generate(
        overran ? framework_event::kPeriodOverrun : framework_event::completion_of(framework_event::kPeriodOverrun),
        framework);
  }
}

void Bridge::Impl::on_tick() {
  const Time now = coordinator->clock().now();
  for (auto& t : topics) {
    if (t->age == nullptr) continue;
    const Time::rep last = t->last_arrival.load(std::memory_order_acquire);
    t->age->push(now, last < 0 ? to_seconds(now) : to_seconds(now - Time{last}));
  }
  const bool due = now - last_publish >= seconds_to_time(mapping.publish_period);
  if (dirty.exchange(false, std::memory_order_acq_rel) || due) {
    last_publish = now;
    publish_diagnostics();
  }
}

void Bridge::Impl::fill_status(diagnostic_msgs::DiagnosticStatus& s, const std::string& address, StateSnapshot snap,
                               const std::optional<Condition>& outstanding) const {
  const Coordinator& co = *coordinator;
  s.name = status_name(address);
  s.hardware_id = mapping.hardware_id;
  s.level = static_cast<std::uint8_t>(to_diagnostic_level(snap.state));
  s.values.push_back(kv("state", std::string(to_string(snap.state))));
  if (snap.state == State::Normal || snap.outstanding == kNoEvent) {
    s.message = "Normal";
    return;
  }
  const Event& e = co.event(snap.outstanding);
  s.message = std::string(to_string(snap.state)) + ": " + e.name;
  s.values.push_back(kv("outstanding", e.name));
  s.values.push_back(kv("severity", std::to_string(e.severity)));
  if (!outstanding) return;
  const RootCause& root = outstanding->root;
  if (root.event != kNoEvent && root.origin != kNoMachine) {
    const std::string cause = co.address_of(root.origin) + ":" + co.event(root.event).name;
    s.message += " (cause " + cause;
    if (root.sample.present()) {
      s.message +=
          ", " + std::string(co.name_of(root.sample.filter)) + " judged " + std::string(co.name_of(root.sample.signal));
      if (root.sample.filter != graph_name) s.message += " = " + fmt_double(root.sample.value);
    }
    s.message += ")";
    s.values.push_back(kv("root_cause", cause));
    if (!co.event(root.event).hazard.empty()) s.values.push_back(kv("hazard", co.event(root.event).hazard));
    if (!co.event(root.event).description.empty())
      s.values.push_back(kv("description", co.event(root.event).description));
    if (root.sample.present()) {
      if (root.sample.filter != kNoName) s.values.push_back(kv("filter", std::string(co.name_of(root.sample.filter))));
      if (root.sample.signal != kNoName) s.values.push_back(kv("signal", std::string(co.name_of(root.sample.signal))));
      s.values.push_back(kv("value", fmt_double(root.sample.value)));
    }
  }
  s.values.push_back(kv("since", fmt_double(to_seconds(outstanding->first)) + " s"));
  s.values.push_back(kv("count", std::to_string(outstanding->count)));
}

void Bridge::Impl::publish_diagnostics() {
  const Coordinator& co = *coordinator;
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = ros::Time::now();
  for (ComponentId c : id_range<ComponentId>(co.component_count())) {
    std::vector<MachineId> machines{co.framework_machine(c), co.application_machine(c)};
    for (MachineId m : co.provided_machines(c)) machines.push_back(m);
    for (MachineId m : co.required_machines(c)) machines.push_back(m);
    // The component: its extended state, explained by the machine that holds its outstanding event.
    const StateSnapshot ext = co.extended(c);
    std::optional<Condition> why;
    for (MachineId m : machines) {
      const StateSnapshot ms = co.snapshot(m);
      if (ext.state != State::Normal && ms.state == ext.state && ms.outstanding == ext.outstanding) {
        why = co.outstanding(m);
        break;
      }
    }
    diagnostic_msgs::DiagnosticStatus status;
    fill_status(status, std::string(co.component_name(c)), ext, why);
    if (const std::string* node = mapping.node_of(co.component_name(c))) status.values.push_back(kv("ros_node", *node));
    array.status.push_back(std::move(status));
    for (MachineId m : machines) {
      diagnostic_msgs::DiagnosticStatus ms;
      const StateSnapshot snap = co.snapshot(m);
      fill_status(ms, co.address_of(m), snap, snap.state == State::Normal ? std::nullopt : co.outstanding(m));
      array.status.push_back(std::move(ms));
    }
  }
  // The bridge's own health: what it read and what it rejected (bad input changes nothing else).
  diagnostic_msgs::DiagnosticStatus self;
  self.name = status_name("bridge");
  self.hardware_id = mapping.hardware_id;
  const std::uint64_t bad = bad_messages.load() + bad_statuses.load();
  self.level = bad == 0 ? diagnostic_msgs::DiagnosticStatus::OK : diagnostic_msgs::DiagnosticStatus::WARN;
  self.message = std::to_string(messages.load()) + " messages, " + std::to_string(bad) + " rejected";
  self.values = {kv("messages", std::to_string(messages.load())),
                 kv("bad_messages", std::to_string(bad_messages.load())),
                 kv("statuses_ingested", std::to_string(ingested.load())),
                 kv("bad_statuses", std::to_string(bad_statuses.load())),
                 kv("graph_checks", std::to_string(graph_checks.load())),
                 kv("graph_problems", std::to_string(graph_problem_count.load()))};
  array.status.push_back(std::move(self));
  publisher.publish(array);
  published.fetch_add(1, std::memory_order_relaxed);
}

void Bridge::Impl::on_diagnostics(const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& event) {
  if (event.getPublisherName() == ros::this_node::getName()) return;  // our own statuses
  const diagnostic_msgs::DiagnosticArray& array = *event.getConstMessage();
  for (Ingest& in : ingests) {
    bool touched = false;
    std::string cause_name = in.rule->name;
    for (const diagnostic_msgs::DiagnosticStatus& s : array.status) {
      if (!in.rule->matches(s.name)) continue;
      const auto level = diagnostic_level_from_byte(s.level);
      if (!level) {
        bad_statuses.fetch_add(1, std::memory_order_relaxed);
        ROS_WARN_THROTTLE(5.0, "safecass: status '%s' from %s has level %d, which is not OK/WARN/ERROR/STALE; ignored",
                          s.name.c_str(), event.getPublisherName().c_str(), static_cast<int>(s.level));
        continue;
      }
      ingested.fetch_add(1, std::memory_order_relaxed);
      in.levels[s.name] = *level;
      if (*level != DiagnosticLevel::Ok) cause_name = s.name;
      touched = true;
    }
    if (!touched) continue;
    std::array<bool, 3> want{};
    for (const auto& l : in.levels) {
      if (l.second != DiagnosticLevel::Ok) want[static_cast<std::size_t>(l.second) - 1] = true;
    }
    SampleCause cause;
    cause.filter = diagnostics_name;
    cause.signal = coordinator->intern(cause_name);
    // Onsets first, then completions: WARN → ERROR never passes through Normal.
    for (std::size_t i = 0; i < 3; ++i) {
      if (want[i] && !in.active[i]) {
        cause.value = static_cast<double>(i + 1);
        coordinator->generate(in.onset[i], in.target, cause);
      }
    }
    for (std::size_t i = 0; i < 3; ++i) {
      if (!want[i] && in.active[i]) coordinator->generate(coordinator->event(in.onset[i]).counterpart, in.target);
    }
    in.active = want;
  }
}

// ---- graph check ---------------------------------------------------------------------------------

void Bridge::Impl::graph_loop() {
  std::unique_lock<std::mutex> lock(graph_mutex);
  if (graph_wake.wait_for(lock, std::chrono::duration<double>(mapping.graph_grace), [this] { return graph_stop; }))
    return;
  while (!graph_stop) {
    lock.unlock();
    check_graph();
    lock.lock();
    if (graph_wake.wait_for(lock, std::chrono::duration<double>(mapping.graph_period), [this] { return graph_stop; }))
      return;
  }
}

void Bridge::Impl::check_graph() {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) {
    ROS_WARN_THROTTLE(10.0, "safecass: the ROS master did not answer getSystemState; graph not checked");
    return;
  }
  std::map<std::string, std::set<std::string>> publishers, subscribers;
  std::set<std::string> present;
  try {
    for (int kind = 0; kind < payload.size() && kind < 3; ++kind) {
      for (int i = 0; i < payload[kind].size(); ++i) {
        const std::string topic = payload[kind][i][0];
        for (int j = 0; j < payload[kind][i][1].size(); ++j) {
          const std::string node = payload[kind][i][1][j];
          present.insert(node);
          if (kind == 0) publishers[topic].insert(node);
          if (kind == 1) subscribers[topic].insert(node);
        }
      }
    }
  } catch (const XmlRpc::XmlRpcException& e) {
    ROS_WARN_THROTTLE(10.0, "safecass: malformed getSystemState answer (%s); graph not checked",
                      e.getMessage().c_str());
    return;
  }
  graph_checks.fetch_add(1, std::memory_order_relaxed);
  const Coordinator& co = *coordinator;
  std::map<MachineId, std::set<std::string>> now;
  std::size_t problems = 0;
  auto report = [&](MachineId machine, std::string text) {
    ++problems;
    if (machine != kNoMachine)
      now[machine].insert(std::move(text));
    else
      ROS_WARN_THROTTLE(10.0, "safecass: %s", text.c_str());
  };
  auto component_of = [](const std::string& iface) { return iface.substr(0, iface.find('.')); };
  for (const auto& n : mapping.nodes) {
    if (present.count(n.second) != 0) continue;
    auto c = co.find_component(n.first);
    report(c ? co.framework_machine(*c) : kNoMachine, "node " + n.second + " of " + n.first + " is not running");
  }
  for (const auto& t : topics) {
    const TopicMapping& m = *t->map;
    if (!m.provided.empty()) {
      const std::string* node = mapping.node_of(component_of(m.provided));
      if (node != nullptr && present.count(*node) != 0 && publishers[m.topic].count(*node) == 0) {
        report(t->provided, "node " + *node + " does not publish " + m.topic + " (" + m.provided + ")");
      }
    }
    for (std::size_t i = 0; i < m.required.size(); ++i) {
      const std::string* node = mapping.node_of(component_of(m.required[i]));
      if (node != nullptr && present.count(*node) != 0 && subscribers[m.topic].count(*node) == 0) {
        report(t->required[i], "node " + *node + " does not subscribe to " + m.topic + " (" + m.required[i] + ")");
      }
    }
  }
  graph_problem_count.store(problems, std::memory_order_relaxed);
  SampleCause cause;
  cause.filter = graph_name;
  for (const auto& p : now) {
    for (const std::string& text : p.second) {
      if (graph_problems[p.first].count(text) == 0) ROS_WARN("safecass: ROS graph: %s", text.c_str());
    }
    if (graph_problems[p.first].empty()) {
      cause.signal = coordinator->intern(*p.second.begin());
      coordinator->generate(graph_event, p.first, cause);
    }
  }
  for (const auto& p : graph_problems) {
    if (!p.second.empty() && now.count(p.first) == 0) {
      ROS_INFO("safecass: ROS graph: %s is complete again", co.address_of(p.first).c_str());
      coordinator->generate(co.event(graph_event).counterpart, p.first);
    }
  }
  graph_problems = std::move(now);
}

}  // namespace safecass::ros1
