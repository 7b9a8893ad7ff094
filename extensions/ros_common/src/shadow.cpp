#include "safecass/ros_common/shadow.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>

#include "safecass/introspect/format.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::ros_common {

namespace {}  // namespace

struct Shadow::Topic {
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
};

struct Shadow::Loop {
  ComponentId component = kNoComponent;
  Time period{};
  Body body;
  bool threw = false;
  bool overran = false;
};

struct Shadow::Ingest {
  struct Seen {
    DiagnosticLevel level = DiagnosticLevel::Ok;
    Time last{};  ///< when it was last received
  };
  const IngestRule* rule = nullptr;
  MachineId target = kNoMachine;
  std::array<EventId, 3> onset{};                 ///< WARN, ERROR, STALE
  std::map<std::string, Seen, std::less<>> seen;  ///< per status name
  std::array<bool, 3> active{};
  std::string cause;  ///< the status name of the newest non-OK level
};

// ---- construction --------------------------------------------------------------------------------

Expected<std::unique_ptr<Shadow>> Shadow::create(const std::string& mapping_path, const FilterRegistry& registry,
                                                 const Clock* clock, Warn warn, const std::string& system_path) {
  MappingLoad ml = load_mapping(mapping_path);
  if (!ml.mapping) return fail(ErrorCode::Parse, spec::to_text(spec::keep_errors(ml.diagnostics, nullptr)));
  if (!system_path.empty()) ml.mapping->system = system_path;
  auto sys = spec::load_valid_system(ml.mapping->system, registry);
  if (!sys) return fail(ErrorCode::Parse, spec::to_text(sys.error()));

  std::unique_ptr<Shadow> s(new Shadow());
  s->mapping_ = std::move(*ml.mapping);
  s->warn_ = warn ? std::move(warn) : Warn([](const std::string&) {});
  spec::InstanceOptions options;
  options.coordinator = s->mapping_.coordinator;
  options.clock = clock;
  auto built = spec::build_instance(std::move(*sys), registry, options);
  if (!built) return fail(ErrorCode::InvalidArgument, spec::to_text(built.error()));
  s->instance_ = std::move(*built);
  const spec::SystemSpec& system = s->instance_->spec();
  Coordinator& co = s->instance_->coordinator();
  const std::string where = s->mapping_.path + ": ";
  for (const EventDef& e : s->mapping_.events) {
    if (auto r = co.add_event(e); !r)
      return fail(r.error().code, where + "event '" + e.name + "': " + r.error().message);
  }
  for (const EventDef& e : default_ros_events()) {
    if (co.structure().find_event(e.name)) continue;
    if (auto r = co.add_event(e); !r)
      return fail(r.error().code, where + "event '" + e.name + "': " + r.error().message);
  }
  // Which connections the system declares, to check the topics against.
  std::set<std::pair<std::string, std::string>> connections;
  for (const spec::ConnectionSpec& c : system.connections) connections.emplace(c.required, c.provided);
  std::set<std::string> components;
  for (const spec::ComponentSpec& c : system.components) components.insert(c.name);
  for (const auto& n : s->mapping_.nodes) {
    if (components.count(n.first) == 0) {
      return fail(ErrorCode::NotFound,
                  where + "nodes: system '" + system.name + "' has no component '" + n.first + "'");
    }
  }
  for (const TopicMapping& t : s->mapping_.topics) {
    for (const std::string& r : t.required) {
      if (!t.provided.empty() && connections.count({r, t.provided}) == 0) {
        return fail(ErrorCode::NotFound, where + "topic '" + t.topic + "' carries " + t.provided + " to " + r +
                                             ", but the system has no connection between them");
      }
    }
  }
  if (auto r = s->bind(); !r) return tl::unexpected(Error{r.error().code, where + r.error().message});
  return s;
}

Expected<void> Shadow::bind() {
  Coordinator& co = instance_->coordinator();
  // An interface "C.x" whose component is not in this coordinator is somebody else's: kNoMachine.
  auto machine_of = [&](const std::string& iface, const char* kind) -> Expected<MachineId> {
    const std::string component = iface.substr(0, iface.find('.'));
    if (!co.structure().find_component(component)) return kNoMachine;
    return co.structure().find_machine(component + "." + kind + "." + iface.substr(iface.find('.') + 1));
  };
  auto check_target = [&](const std::string& address) -> Expected<FilterTarget> {
    auto m = co.structure().find_machine(address);
    if (!m) return tl::unexpected(m.error());
    FilterTarget t;
    t.kind = co.structure().machine_kind(*m);
    t.component = std::string(co.structure().component_name(co.structure().machine_component(*m)));
    if (t.kind == MachineKind::Provided || t.kind == MachineKind::Required)
      t.interface = std::string(co.structure().interface_name(*m));
    return t;
  };
  auto need_onset = [&](const std::string& event, const std::string& what) -> Expected<EventId> {
    auto e = co.structure().find_event(event);
    if (!e) return fail(ErrorCode::NotFound, what + ": no event '" + event + "'");
    if (!co.structure().event(*e).is_onset)
      return fail(ErrorCode::InvalidArgument, what + ": '" + event + "' is a completion, not an onset");
    if (co.structure().event(*e).counterpart == kNoEvent) {
      return fail(ErrorCode::InvalidArgument, what + ": '" + event + "' has no completion, so it could never clear");
    }
    return *e;
  };

  for (const TopicMapping& tm : mapping_.topics) {
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
      Signal* s = instance_->monitor().signals().find(b.signal);
      std::size_t width = b.path.width();
      if (width == 0) width = b.size != 0 ? b.size : (s != nullptr ? s->size() : 0);
      if (width == 0) {
        return fail(ErrorCode::InvalidArgument,
                    what + ": signal '" + b.signal + "' reads the whole array '" + b.path.text +
                        "': declare the signal in the spec or give {\"field\": ..., \"size\": N}");
      }
      if (s == nullptr) {
        auto created = instance_->monitor().add_signal(b.signal, width);
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
      auto s = instance_->monitor().add_signal(*name, 1);
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
      f.params["event_completion"] = co.structure().event(co.structure().event(*onset).counterpart).name;
      if (watchdog) {
        f.params["timeout"] = (*check)->timeout;
      } else {
        f.params["min_rate"] = (*check)->min_rate;
        f.params["max_rate"] = (*check)->max_rate;
        f.params["window"] = static_cast<double>((*check)->window);
      }
      if (auto r = instance_->monitor().add_filter(std::move(f)); !r)
        return fail(r.error().code, what + ": " + r.error().message);
    }
    topics_.push_back(std::move(t));
  }

  for (const IngestRule& rule : mapping_.ingest) {
    Ingest in;
    in.rule = &rule;
    const std::string what = "ingest rule '" + rule.name + "'";
    auto m = co.structure().find_machine(rule.target);
    if (!m) return fail(m.error().code, what + ": " + m.error().message);
    in.target = *m;
    const std::array<const std::string*, 3> names{&rule.warn, &rule.error, &rule.stale};
    for (std::size_t i = 0; i < 3; ++i) {
      auto e = need_onset(*names[i], what);
      if (!e) return tl::unexpected(e.error());
      in.onset[i] = *e;
    }
    ingests_.push_back(std::move(in));
  }
  auto g = need_onset(mapping_.graph_event, "graph");
  if (!g) return tl::unexpected(g.error());
  graph_event_ = *g;
  graph_name_ = co.intern("ros:graph");
  diagnostics_name_ = co.intern("ros:diagnostics");
  if (mapping_.hardware_id.empty()) mapping_.hardware_id = std::string(co.structure().name());
  return {};
}

Shadow::~Shadow() { stop(); }

const TopicMapping& Shadow::topic(std::size_t i) const noexcept { return *topics_[i]->map; }
const std::vector<Shadow::Bound>& Shadow::bound(std::size_t i) const noexcept { return topics_[i]->bound; }
double* Shadow::scratch(std::size_t i) noexcept { return topics_[i]->scratch.data(); }
Time Shadow::loop_period(std::size_t i) const noexcept { return loops_[i]->period; }

BridgeStats Shadow::stats() const noexcept {
  BridgeStats s;
  s.messages = messages_.load();
  s.bad_messages = bad_messages_.load();
  s.diagnostics_published = published_.load();
  s.statuses_ingested = ingested_.load();
  s.bad_statuses = bad_statuses_.load();
  s.graph_checks = graph_checks_.load();
  s.graph_problems = graph_problem_count_.load();
  return s;
}

// ---- loops and running ---------------------------------------------------------------------------

Expected<void> Shadow::add_loop(std::string_view component, Time period, Body body) {
  if (started_) return fail(ErrorCode::InvalidState, "add_loop() after start()");
  auto c = instance_->coordinator().structure().find_component(component);
  if (!c) return tl::unexpected(c.error());
  if (period <= Time{0})
    return fail(ErrorCode::InvalidArgument, "loop of '" + std::string(component) + "': period must be positive");
  for (const auto& l : loops_) {
    if (l->component == *c)
      return fail(ErrorCode::InvalidArgument, "component '" + std::string(component) + "' already has a loop");
  }
  auto loop = std::make_unique<Loop>();
  loop->component = *c;
  loop->period = period;
  loop->body = std::move(body);
  loops_.push_back(std::move(loop));
  return {};
}

Expected<void> Shadow::start() {
  if (started_) return fail(ErrorCode::InvalidState, "the bridge is already started");
  // A component with a loop of its own runs its ACTIVE filters there; the others on each message.
  for (auto& t : topics_) {
    t->run.clear();
    for (const Bound& b : t->bound) {
      const ComponentId c = b.signal->component();
      const bool looped = std::any_of(loops_.begin(), loops_.end(), [c](const auto& l) { return l->component == c; });
      if (!looped && std::find(t->run.begin(), t->run.end(), c) == t->run.end()) t->run.push_back(c);
    }
  }
  observer_ = instance_->coordinator().subscribe([this](const Record& r) {
    if (r.kind != RecordKind::Event && r.kind != RecordKind::Injection) dirty_.store(true, std::memory_order_release);
  });
  instance_->monitor().start();
  started_ = true;
  return {};
}

void Shadow::stop() noexcept {
  if (!started_) return;
  instance_->monitor().stop();
  instance_->coordinator().unsubscribe(observer_);
  started_ = false;
}

void Shadow::deliver(std::size_t i, Time now) {
  Topic& t = *topics_[i];
  std::size_t offset = 0;
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
  messages_.fetch_add(1, std::memory_order_relaxed);
  for (ComponentId c : t.run) instance_->monitor().run_active(c, now);
}

void Shadow::reject(std::size_t i, const std::string& why) {
  bad_messages_.fetch_add(1, std::memory_order_relaxed);
  warn_throttled("message on " + topics_[i]->map->topic + " rejected (" + why + "); nothing was changed");
}

void Shadow::warn_throttled(const std::string& text) {
  const auto now = std::chrono::steady_clock::now();
  if (last_throttled_warning_.time_since_epoch().count() != 0 &&
      now - last_throttled_warning_ < std::chrono::seconds(5))
    return;
  last_throttled_warning_ = now;
  warn_(text);
}

void Shadow::run_loop(std::size_t i) {
  Loop& loop = *loops_[i];
  const auto begin = std::chrono::steady_clock::now();
  const Time now = instance_->coordinator().clock().now();
  instance_->monitor().run_active(loop.component, now);
  const MachineId framework = instance_->coordinator().structure().framework_machine(loop.component);
  try {
    if (loop.body) loop.body(now);
    if (loop.threw) {
      loop.threw = false;
      instance_->coordinator().generate(framework_event::completion_of(framework_event::kThreadException), framework);
    }
  } catch (const std::exception& e) {
    warn_("the loop of " + std::string(instance_->coordinator().structure().component_name(loop.component)) +
          " threw: " + e.what());
    if (!loop.threw) instance_->coordinator().generate(framework_event::kThreadException, framework);
    loop.threw = true;
  } catch (...) {
    if (!loop.threw) instance_->coordinator().generate(framework_event::kThreadException, framework);
    loop.threw = true;
  }
  const bool overran = std::chrono::steady_clock::now() - begin > loop.period;
  if (overran != loop.overran) {
    loop.overran = overran;
    instance_->coordinator().generate(
        overran ? framework_event::kPeriodOverrun : framework_event::completion_of(framework_event::kPeriodOverrun),
        framework);
  }
}

bool Shadow::tick(Time now) {
  age_ingested(now);
  for (auto& t : topics_) {
    if (t->age == nullptr) continue;
    const Time::rep last = t->last_arrival.load(std::memory_order_acquire);
    t->age->push(now, last < 0 ? to_seconds(now) : to_seconds(now - Time{last}));
  }
  const bool due = now - last_publish_ >= seconds_to_time(mapping_.publish_period);
  if (dirty_.exchange(false, std::memory_order_acq_rel) || due) {
    last_publish_ = now;
    return true;
  }
  return false;
}

// ---- diagnostics out -----------------------------------------------------------------------------

void Shadow::fill_status(Status& s, const std::string& address, StateSnapshot snap,
                         const std::optional<Condition>& outstanding) const {
  const Coordinator& co = instance_->coordinator();
  s.name = status_name(address);
  s.hardware_id = mapping_.hardware_id;
  s.level = to_diagnostic_level(snap.state);
  s.values.emplace_back("state", std::string(to_string(snap.state)));
  if (snap.state == State::Normal || snap.outstanding == kNoEvent) {
    s.message = "Normal";
    return;
  }
  const Event& e = co.structure().event(snap.outstanding);
  s.message = std::string(to_string(snap.state)) + ": " + e.name;
  s.values.emplace_back("outstanding", e.name);
  s.values.emplace_back("severity", std::to_string(e.severity));
  if (!outstanding) return;
  const RootCause& root = outstanding->root;
  if (root.event != kNoEvent && root.origin != kNoMachine) {
    const std::string cause = co.resolve_root(root).name();  // a remote root: its origin in its own process
    s.message += " (cause " + cause;
    if (root.sample.present()) {
      s.message += ", " + std::string(co.structure().name_of(root.sample.filter)) + " judged " +
                   std::string(co.structure().name_of(root.sample.signal));
      if (root.sample.filter != graph_name_) s.message += " = " + number_text(root.sample.value);
    }
    s.message += ")";
    s.values.emplace_back("root_cause", cause);
    if (!co.structure().event(root.event).hazard.empty())
      s.values.emplace_back("hazard", co.structure().event(root.event).hazard);
    if (!co.structure().event(root.event).description.empty())
      s.values.emplace_back("description", co.structure().event(root.event).description);
    if (root.sample.present()) {
      if (root.sample.filter != kNoName)
        s.values.emplace_back("filter", std::string(co.structure().name_of(root.sample.filter)));
      if (root.sample.signal != kNoName)
        s.values.emplace_back("signal", std::string(co.structure().name_of(root.sample.signal)));
      s.values.emplace_back("value", number_text(root.sample.value));
    }
  }
  s.values.emplace_back("since", seconds_text(outstanding->first) + " s");
  s.values.emplace_back("count", std::to_string(outstanding->count));
}

std::vector<Status> Shadow::statuses() {
  const Coordinator& co = instance_->coordinator();
  std::vector<Status> out;
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count())) {
    std::vector<MachineId> machines{co.structure().framework_machine(c), co.structure().application_machine(c)};
    for (MachineId m : co.structure().provided_machines(c)) machines.push_back(m);
    for (MachineId m : co.structure().required_machines(c)) machines.push_back(m);
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
    Status status;
    fill_status(status, std::string(co.structure().component_name(c)), ext, why);
    if (const std::string* node = mapping_.node_of(co.structure().component_name(c)))
      status.values.emplace_back("ros_node", *node);
    out.push_back(std::move(status));
    for (MachineId m : machines) {
      Status ms;
      const StateSnapshot snap = co.snapshot(m);
      fill_status(ms, co.structure().address_of(m), snap,
                  snap.state == State::Normal ? std::nullopt : co.outstanding(m));
      out.push_back(std::move(ms));
    }
  }
  // The bridge's own health: what it read and what it rejected (bad input changes nothing else).
  Status self;
  self.name = status_name("bridge");
  self.hardware_id = mapping_.hardware_id;
  const std::uint64_t bad = bad_messages_.load() + bad_statuses_.load();
  self.level = bad == 0 ? DiagnosticLevel::Ok : DiagnosticLevel::Warn;
  self.message = std::to_string(messages_.load()) + " messages, " + std::to_string(bad) + " rejected";
  self.values = {{"messages", std::to_string(messages_.load())},
                 {"bad_messages", std::to_string(bad_messages_.load())},
                 {"statuses_ingested", std::to_string(ingested_.load())},
                 {"bad_statuses", std::to_string(bad_statuses_.load())},
                 {"graph_checks", std::to_string(graph_checks_.load())},
                 {"graph_problems", std::to_string(graph_problem_count_.load())}};
  out.push_back(std::move(self));
  published_.fetch_add(1, std::memory_order_relaxed);
  return out;
}

// ---- diagnostics in ------------------------------------------------------------------------------

void Shadow::ingest(const std::vector<ReceivedStatus>& statuses, std::string_view sender) {
  const Time now = instance_->coordinator().clock().now();
  for (Ingest& in : ingests_) {
    bool touched = false;
    for (const ReceivedStatus& s : statuses) {
      if (!in.rule->matches(s.name)) continue;
      const auto level = diagnostic_level_from_byte(s.level);
      if (!level) {
        bad_statuses_.fetch_add(1, std::memory_order_relaxed);
        warn_throttled("status '" + std::string(s.name) + "' from " + std::string(sender) + " has level " +
                       std::to_string(s.level) + ", which is not OK/WARN/ERROR/STALE; ignored");
        continue;
      }
      ingested_.fetch_add(1, std::memory_order_relaxed);
      in.seen[std::string(s.name)] = Ingest::Seen{*level, now};
      if (*level != DiagnosticLevel::Ok) in.cause = std::string(s.name);
      touched = true;
    }
    if (touched) apply(in);
  }
}

void Shadow::age_ingested(Time now) {
  for (Ingest& in : ingests_) {
    if (in.rule->stale_after <= 0) continue;
    const Time limit = seconds_to_time(in.rule->stale_after);
    bool aged = false;
    for (auto& [name, seen] : in.seen) {
      if (seen.level == DiagnosticLevel::Stale || now - seen.last < limit) continue;
      seen.level = DiagnosticLevel::Stale;  // silence is not OK
      in.cause = name;
      aged = true;
    }
    if (aged) apply(in);
  }
}

void Shadow::apply(Ingest& in) {
  std::array<bool, 3> want{};
  for (const auto& [name, seen] : in.seen) {
    if (seen.level != DiagnosticLevel::Ok) want[static_cast<std::size_t>(seen.level) - 1] = true;
  }
  SampleCause cause;
  cause.filter = diagnostics_name_;
  cause.signal = instance_->coordinator().intern(in.cause.empty() ? in.rule->name : in.cause);
  // Onsets first, then completions: WARN → ERROR never passes through Normal.
  for (std::size_t i = 0; i < 3; ++i) {
    if (want[i] && !in.active[i]) {
      cause.value = static_cast<double>(i + 1);
      instance_->coordinator().generate(in.onset[i], in.target, cause);
    }
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (!want[i] && in.active[i])
      instance_->coordinator().generate(instance_->coordinator().structure().event(in.onset[i]).counterpart, in.target);
  }
  in.active = want;
}

// ---- graph check ---------------------------------------------------------------------------------

void Shadow::check_graph(const GraphView& live) {
  graph_checks_.fetch_add(1, std::memory_order_relaxed);
  const Coordinator& co = instance_->coordinator();
  std::map<MachineId, std::set<std::string>> now;
  std::size_t problems = 0;
  auto report = [&](MachineId machine, std::string text) {
    ++problems;
    if (machine != kNoMachine)
      now[machine].insert(std::move(text));
    else
      warn_(text);
  };
  auto has = [](const std::map<std::string, std::set<std::string>>& m, const std::string& topic,
                const std::string* node) {
    const auto it = m.find(topic);
    if (it == m.end()) return false;
    return node == nullptr || it->second.count(*node) != 0;
  };
  // Where nodes are unknown: another participant's endpoint, or the bridge's own for a component
  // whose loop runs here.
  auto anybody = [&](const std::map<std::string, std::set<std::string>>& m, const std::string& topic,
                     const std::string& iface) {
    const auto it = m.find(topic);
    if (it == m.end()) return false;
    for (const std::string& node : it->second) {
      if (node != GraphView::kSelf) return true;
    }
    const auto c = co.structure().find_component(iface.substr(0, iface.find('.')));
    return c && std::any_of(loops_.begin(), loops_.end(), [&](const auto& l) { return l->component == *c; });
  };
  auto component_of = [](const std::string& iface) { return iface.substr(0, iface.find('.')); };
  if (live.nodes_known) {
    for (const auto& n : mapping_.nodes) {
      if (live.nodes.count(n.second) != 0) continue;
      auto c = co.structure().find_component(n.first);
      report(c ? co.structure().framework_machine(*c) : kNoMachine,
             "node " + n.second + " of " + n.first + " is not running");
    }
  }
  for (const auto& t : topics_) {
    const TopicMapping& m = *t->map;
    const auto wrong = live.mistyped.find(m.topic);
    if (wrong != live.mistyped.end()) {
      for (const std::string& type : wrong->second) {
        report(t->provided, "topic " + m.topic + " is published as " + type + ", the mapping expects " +
                                std::string(to_string(m.type)));
      }
    }
    // An interface is checked when the mapping names its component's node: that node (or, where
    // the framework cannot name nodes, somebody) must publish or subscribe to the topic.
    auto absent = [&](const std::string* node, const std::map<std::string, std::set<std::string>>& endpoints,
                      const std::string& iface) {
      if (node == nullptr) return false;
      if (!live.nodes_known) return !anybody(endpoints, m.topic, iface);
      return live.nodes.count(*node) != 0 && !has(endpoints, m.topic, node);
    };
    auto who = [&](const std::string* node) { return live.nodes_known ? "node " + *node : std::string("nobody"); };
    if (!m.provided.empty()) {
      const std::string* node = mapping_.node_of(component_of(m.provided));
      if (wrong == live.mistyped.end() && absent(node, live.publishers, m.provided))  // a wrong type says more
        report(t->provided, who(node) + (live.nodes_known ? " does not publish " : " publishes ") + m.topic + " (" +
                                m.provided + ")");
    }
    for (std::size_t i = 0; i < m.required.size(); ++i) {
      const std::string* node = mapping_.node_of(component_of(m.required[i]));
      if (absent(node, live.subscribers, m.required[i]))
        report(t->required[i], who(node) + (live.nodes_known ? " does not subscribe to " : " subscribes to ") +
                                   m.topic + " (" + m.required[i] + ")");
    }
  }
  graph_problem_count_.store(problems, std::memory_order_relaxed);
  SampleCause cause;
  cause.filter = graph_name_;
  for (const auto& p : now) {
    for (const std::string& text : p.second) {
      if (graph_problems_[p.first].count(text) == 0) warn_("ROS graph: " + text);
    }
    if (graph_problems_[p.first].empty()) {
      cause.signal = instance_->coordinator().intern(*p.second.begin());
      instance_->coordinator().generate(graph_event_, p.first, cause);
    }
  }
  for (const auto& p : graph_problems_) {
    if (!p.second.empty() && now.count(p.first) == 0) {
      warn_("ROS graph: " + co.structure().address_of(p.first) + " is complete again");
      instance_->coordinator().generate(co.structure().event(graph_event_).counterpart, p.first);
    }
  }
  graph_problems_ = std::move(now);
}

}  // namespace safecass::ros_common
