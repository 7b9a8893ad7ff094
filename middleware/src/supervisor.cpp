// The supervisor: the system-wide view and lost-coordinator detection (see supervisor.hpp).

#include "safecass/middleware/supervisor.hpp"

#include <atomic>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "ice_util.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::middleware {

using namespace detail;

struct Supervisor::Impl {
  const spec::SystemSpec& system;
  SupervisorOptions options;
  FilterRegistry registry;
  Coordinator model{"supervisor"};
  std::unique_ptr<Monitor> monitor;

  struct Peer {
    std::vector<std::string> components;
    std::int64_t last_heartbeat = 0;
    std::int64_t incarnation = 0;
    std::int64_t last_event_seq = 0;
    bool seen = false;
    bool lost = false;
  };
  mutable std::mutex mutex;
  std::map<std::string, Peer, std::less<>> peers;
  std::map<std::string, ViewRow, std::less<>> view;

  std::shared_ptr<Ice::Communicator> ic;
  std::unique_ptr<Link> link;
  std::shared_ptr<wire::ResyncTopicPrx> resync_pub;
  std::atomic<bool> running{false};
  std::thread link_thread;
  std::thread watch_thread;

  Impl(const spec::SystemSpec& s, SupervisorOptions o) : system(s), options(std::move(o)) {}

  void print(const std::string& line) const {
    if (options.print) {
      options.print(line);
    } else {
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    }
  }

  void on_event(const wire::EventMessage& m) {
    if (m.kind != "transition" && m.kind != "component-transition" && m.kind != "reset") return;
    State from = State::Normal, to = State::Normal;
    if (!from_wire(m.from, from) || !from_wire(m.to, to)) {
      print("supervisor: malformed event message from '" + m.coordinator + "' ignored (invalid level)");
      return;
    }
    {
      std::lock_guard lock(mutex);
      const auto p = peers.find(m.coordinator);
      if (p == peers.end()) {
        print("supervisor: event from unknown coordinator '" + m.coordinator + "' ignored");
        return;
      }
      if (p->second.incarnation == m.incarnation && p->second.last_event_seq != 0 && m.seq != p->second.last_event_seq + 1) {
        print("supervisor: " + std::to_string(m.seq - p->second.last_event_seq - 1) + " event message(s) of '" +
              m.coordinator + "' missed");
      }
      p->second.last_event_seq = m.seq;
      if (m.kind == "reset") {
        print("[" + m.coordinator + "] reset " + m.address + " (" + m.text + ")");
        return;
      }
      ViewRow& row = view[m.address];
      row.coordinator = m.coordinator;
      row.address = m.address;
      row.state = to;
      row.cause = to == State::Normal ? std::string() : m.rootOrigin + ":" + m.rootEvent;
    }
    print("[" + m.coordinator + "] " + m.address + " " + std::string(to_string(from)) + " -> " + std::string(to_string(to)) +
          " " + m.event + (m.rootEvent.empty() ? "" : " (root " + m.rootOrigin + ":" + m.rootEvent + ")"));
  }

  void on_update(const wire::StateUpdate& u) {
    State s = State::Normal;
    if (!from_wire(u.state, s)) {
      print("supervisor: malformed state update from '" + u.coordinator + "' ignored (invalid level)");
      return;
    }
    const auto dot = u.iface.find('.');
    if (dot == std::string::npos) {
      print("supervisor: malformed state update from '" + u.coordinator + "': interface '" + u.iface + "'");
      return;
    }
    const std::string address = u.iface.substr(0, dot) + ".s_S." + u.iface.substr(dot + 1);
    std::string causes;
    for (const wire::Root& r : u.roots) causes += (causes.empty() ? "" : ", ") + r.origin + ":" + r.event;
    {
      std::lock_guard lock(mutex);
      if (peers.find(u.coordinator) == peers.end()) {
        print("supervisor: state update from unknown coordinator '" + u.coordinator + "' ignored");
        return;
      }
      ViewRow& row = view[address];
      if (row.address == address && row.state == s && row.cause == causes) return;
      row = ViewRow{u.coordinator, address, s, causes};
    }
    print("[" + u.coordinator + "] " + address + " " + std::string(to_string(s)) + (causes.empty() ? "" : " (roots " + causes + ")"));
  }

  void on_heartbeat(const wire::Heartbeat& h) {
    std::vector<std::string> recovered;
    {
      std::lock_guard lock(mutex);
      const auto p = peers.find(h.coordinator);
      if (p == peers.end()) {
        print("supervisor: heartbeat from unknown coordinator '" + h.coordinator + "' ignored");
        return;
      }
      Peer& peer = p->second;
      if (!peer.seen) print("supervisor: coordinator '" + h.coordinator + "' is up");
      if (peer.incarnation != h.incarnation) peer.last_event_seq = 0;
      peer.seen = true;
      peer.incarnation = h.incarnation;
      peer.last_heartbeat = steady_ns();
      if (peer.lost) {
        peer.lost = false;
        recovered = peer.components;
      }
    }
    if (recovered.empty()) return;
    print("supervisor: coordinator '" + h.coordinator + "' recovered");
    for (const std::string& c : recovered) (void)model.generate("/EVT_COORDINATOR_LOST", c + ".s_F");
  }

  void watch_loop() {
    while (running.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const std::int64_t now = steady_ns();
      std::vector<std::pair<std::string, std::vector<std::string>>> lost_now;
      {
        std::lock_guard lock(mutex);
        for (auto& [name, peer] : peers) {
          if (!peer.seen || peer.lost) continue;
          if (now - peer.last_heartbeat > std::chrono::nanoseconds(options.lost_after).count()) {
            peer.lost = true;
            lost_now.emplace_back(name, peer.components);
          }
        }
      }
      for (const auto& [name, components] : lost_now) {
        print("supervisor: coordinator '" + name + "' lost: no heartbeat for " +
              std::to_string(options.lost_after.count()) + " ms; EVT_COORDINATOR_LOST on its components");
        for (const std::string& c : components) (void)model.generate("EVT_COORDINATOR_LOST", c + ".s_F");
      }
    }
  }

  void link_loop() {
    bool connected = false;
    bool reported = false;
    while (running.load()) {
      try {
        if (!connected) {
          link->connect({kResyncTopic});
          resync_pub = Ice::uncheckedCast<wire::ResyncTopicPrx>(link->publisher(kResyncTopic));
          resync_pub->resync("supervisor", "");
          connected = true;
          reported = false;
          print("supervisor: connected to IceStorm at " + options.ice.host + ":" + std::to_string(options.ice.port));
        }
        link->ping();
      } catch (const Ice::Exception& e) {
        if (!reported) print("supervisor: IceStorm unreachable (" + std::string(e.ice_id()) + "); retrying");
        reported = true;
        connected = false;
      }
      for (int i = 0; i < 10 && running.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
};

namespace {

class EventServant final : public wire::EventTopic {
public:
  explicit EventServant(Supervisor::Impl& d) : d_(d) {}
  void record(wire::EventMessage e, const Ice::Current&) override { d_.on_event(e); }
  void records(wire::EventMessageSeq batch, const Ice::Current&) override {
    for (const wire::EventMessage& e : batch) d_.on_event(e);
  }

private:
  Supervisor::Impl& d_;
};
class StateServant final : public wire::StateTopic {
public:
  explicit StateServant(Supervisor::Impl& d) : d_(d) {}
  void update(wire::StateUpdate u, const Ice::Current&) override { d_.on_update(u); }
  void updates(wire::StateUpdateSeq batch, const Ice::Current&) override {
    for (const wire::StateUpdate& u : batch) d_.on_update(u);
  }

private:
  Supervisor::Impl& d_;
};
class HeartbeatServant final : public wire::HeartbeatTopic {
public:
  explicit HeartbeatServant(Supervisor::Impl& d) : d_(d) {}
  void beat(wire::Heartbeat h, const Ice::Current&) override { d_.on_heartbeat(h); }

private:
  Supervisor::Impl& d_;
};
}  // namespace

Expected<std::unique_ptr<Supervisor>> Supervisor::create(const spec::SystemSpec& system, SupervisorOptions options) {
  if (options.ice.port <= 0) return fail(ErrorCode::InvalidArgument, "supervisor: no IceStorm port given");
  auto impl = std::make_unique<Impl>(system, std::move(options));
  register_builtin_filters(impl->registry);
  impl->monitor = std::make_unique<Monitor>(impl->model, impl->registry);
  if (auto r = spec::instantiate(system, impl->model, *impl->monitor); !r) return tl::unexpected(r.error());
  for (const auto& [name, components] : system.coordinators) impl->peers[name].components = components;
  Impl* d = impl.get();
  impl->model.subscribe([d](const Record& r) {
    if (r.kind != RecordKind::Transition) return;
    std::string line = "supervisor: " + d->model.address_of(r.machine) + " " + std::string(to_string(r.from)) + " -> " +
                       std::string(to_string(r.to)) + " " + (r.event == kNoEvent ? "" : d->model.event(r.event).name);
    if (r.root.event != kNoEvent) {
      line += " (root " + d->model.address_of(r.root.origin) + ":" + d->model.event(r.root.event).name + ")";
    }
    d->print(line);
  });
  return std::unique_ptr<Supervisor>(new Supervisor(std::move(impl)));
}

Supervisor::Supervisor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Supervisor::~Supervisor() { stop(); }

Expected<void> Supervisor::start() {
  Impl& d = *impl_;
  if (d.running.load()) return {};
  try {
    d.ic = make_communicator();
    auto adapter = d.ic->createObjectAdapterWithEndpoints("SafecassSupervisor", "tcp -h " + d.options.listen_host);
    d.link = std::make_unique<Link>(d.ic, d.options.ice);
    d.link->subscribe_to(kEventTopic, adapter->addWithUUID(std::make_shared<EventServant>(d)), Delivery::Stream);
    auto state = adapter->addWithUUID(std::make_shared<StateServant>(d));
    for (const auto& [name, _] : d.peers) d.link->subscribe_to(state_topic(name), state, Delivery::Stream);
    d.link->subscribe_to(kHeartbeatTopic, adapter->addWithUUID(std::make_shared<HeartbeatServant>(d)));
    adapter->activate();
  } catch (const Ice::Exception& e) {
    if (d.ic) d.ic->destroy();
    d.ic = nullptr;
    return fail(ErrorCode::Io, std::string("supervisor: cannot listen: ") + e.what());
  }
  d.running.store(true);
  d.link_thread = std::thread([&d] { d.link_loop(); });
  d.watch_thread = std::thread([&d] { d.watch_loop(); });
  return {};
}

void Supervisor::stop() noexcept {
  Impl& d = *impl_;
  if (!d.running.exchange(false)) return;
  if (d.link_thread.joinable()) d.link_thread.join();
  if (d.watch_thread.joinable()) d.watch_thread.join();
  try {
    d.ic->shutdown();
    d.ic->waitForShutdown();
    d.ic->destroy();
  } catch (...) {
  }
}

std::vector<ViewRow> Supervisor::view() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<ViewRow> out;
  for (const auto& [_, row] : impl_->view) out.push_back(row);
  return out;
}

std::vector<std::string> Supervisor::lost() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<std::string> out;
  for (const auto& [name, peer] : impl_->peers) {
    if (peer.lost) out.push_back(name);
  }
  return out;
}

const Coordinator& Supervisor::model() const { return impl_->model; }

}  // namespace safecass::middleware
