// Crafted wire messages against a real coordinator node (DESIGN §7 "bad input", "nothing let in",
// §4 "fail toward safe on loss"), published straight to IceStorm. The test plays the provider
// coordinator "wire-p" (with its real key), an attacker (with a key of its own, or another
// coordinator's), and the supervisor:
// - each update of a signed batch is checked on its own: a bad one is refused alone;
// - forged, re-signed, replayed, mis-attributed and far-future messages are refused, counted and
//   change nothing;
// - a provider whose heartbeat stops is lost: its client's required interfaces go to Error
//   (EVT_COORDINATOR_LOST), and clear once it is back and resynchronised;
// - a supervisor that stops is reported as a framework warning (EVT_SUPERVISOR_LOST);
// - a client sends its token only to a coordinator found through an authenticated heartbeat.
//
// Environment (set by tests/integration/middleware/CMakeLists.txt):
//   SAFECASS_ICESTORM_ENV    file written by the fixture's scripts/start-icestorm --env
//   SAFECASS_SCRATCH         a directory for key files

#include <gtest/gtest.h>

#include <Ice/Ice.h>
#include <IceStorm/IceStorm.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "auth.hpp"
#include "fixture.hpp"
#include "receiver.hpp"
#include "safecass.h"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/supervisor.hpp"
#include "safecass/spec/load.hpp"

namespace safecass {
namespace {

using namespace std::chrono_literals;

std::string fixture_port() {
  const char* file = std::getenv("SAFECASS_ICESTORM_ENV");
  std::ifstream in(file != nullptr ? file : "");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ICESTORM_PORT=", 0) == 0) return line.substr(14);
  }
  return "";
}

bool eventually(const std::function<bool()>& ok, std::chrono::milliseconds timeout = 5000ms) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (ok()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return ok();
}

// P (coordinator "wire-p", played by the test) provides D0..D3; C ("wire-c") requires them.
constexpr const char* kSystem = R"({ "safecass": 1, "system": "wire",
  "components": [
    { "component": "P", "interfaces": { "provided": ["D0", "D1", "D2", "D3"], "required": [] },
      "event": [ { "name": "EVT_E", "severity": 50, "state_transition": ["N2E", "W2E"] },
                 { "name": "/EVT_E", "severity": 50, "state_transition": ["E2N", "E2W"] } ] },
    { "component": "C", "interfaces": { "provided": [], "required": ["D0", "D1", "D2", "D3"] } } ],
  "connections": [ { "required": "C.D0", "provided": "P.D0" }, { "required": "C.D1", "provided": "P.D1" },
                   { "required": "C.D2", "provided": "P.D2" }, { "required": "C.D3", "provided": "P.D3" } ],
  "coordinators": { "wire-p": ["P"], "wire-c": ["C"] } })";

using middleware::encode;
using middleware::Keyring;
using middleware::Signer;

constexpr std::int64_t kIncarnation = 42;

/// One state update as a test writes it: of wire-p's interface `iface`, by a process of
/// `incarnation`. Bus::batch() turns a list of them into the wire's StateBatch.
struct Update {
  std::string iface;
  wire::StateUpdate wire;
  std::int64_t incarnation = kIncarnation;
};

Update update(const std::string& iface, std::int64_t seq, const std::string& event, wire::Level level,
              std::int64_t incarnation = kIncarnation) {
  Update u{iface, {}, incarnation};
  u.wire.seq = seq;
  u.wire.state = level;
  if (!event.empty()) {
    u.wire.roots.push_back(
        wire::Root{event, "P.s_A", 1000, level, "", "", 0.0, 0, false, {"P.s_A", "P.s_S." + iface.substr(2)}});
  }
  return u;
}

Signer load_signer(const std::string& dir, const std::string& name) {
  auto keyring = Keyring::load(dir);
  EXPECT_TRUE(keyring) << (keyring ? "" : keyring.error().message);
  auto s = Signer::load(dir, name, *keyring);
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
  return *s;
}

struct Bus;

/// The proof of life (wire::Alive) of a process the test plays (wire-p, or the supervisor), as a
/// real process serves it: its current heartbeat, signed with its key, for the asker's nonce.
class FakeAlive final : public wire::Alive {
public:
  FakeAlive(Bus& bus, std::string name) : bus_(bus), name_(std::move(name)) {}
  wire::Signed prove(wire::Bytes nonce, const Ice::Current&) override;

private:
  Bus& bus_;
  std::string name_;
};

/// The coordinator node "wire-c" on the fixture's IceStorm, and the test as everybody else: the
/// real "wire-p" and supervisor (the system's keys), and an attacker (keys of its own).
struct Bus {
  std::string port = fixture_port();
  std::string scratch = std::getenv("SAFECASS_SCRATCH") != nullptr ? std::getenv("SAFECASS_SCRATCH") : "/tmp";
  std::string keys = scratch + "/wire-keys";
  std::string attacker_keys = scratch + "/wire-attacker-keys";
  FilterRegistry registry;
  spec::LoadResult load;
  middleware::HostClock clock;
  Coordinator co{"wire-c", &clock};
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<middleware::CoordinatorNode> node;
  mutable std::mutex mutex;
  std::vector<std::string> log;
  Ice::CommunicatorHolder ice;  ///< presents wire-p's certificate (made with the keys, below)
  /// Presents the supervisor's certificate: the supervisor's Alive object, which a receiver
  /// believes only from a process whose certificate names it.
  Ice::CommunicatorHolder supervisor_ice;
  std::shared_ptr<Ice::ObjectAdapter> supervisor_adapter;
  std::shared_ptr<wire::StateTopicPrx> state_pub;
  /// The publisher of `name`'s heartbeat topic ("safecass.heartbeat.<name>").
  std::shared_ptr<wire::HeartbeatTopicPrx> heartbeat_pub(const std::string& name) {
    return Ice::uncheckedCast<wire::HeartbeatTopicPrx>(topic("safecass.heartbeat." + name)->getPublisher());
  }
  std::optional<Signer> provider, other, supervisor, attacker;
  // The provider's heartbeat, sent by a thread while `beating`: the last seq of each stream.
  std::map<std::string, std::int64_t> last_sent;
  std::vector<std::string> settling;  ///< what wire-p's heartbeats list as losses of its own it clears
  /// The state streams wire-p's heartbeats and proofs list when not the system file's (another
  /// system file at wire-p).
  std::optional<middleware::StateStreams> provider_streams;
  std::optional<std::int64_t> events_sent;  ///< the last event record listed, when the heartbeat lists one
  std::atomic<bool> beating{true};
  std::atomic<std::uint64_t> beat_rounds{0};  ///< rounds of the beat thread, each a heartbeat when `beating`
  std::atomic<bool> running{true};
  std::int64_t beat_seq = 0;
  std::int64_t newest = kIncarnation;  ///< the newest incarnation wire-p's key beat with: the one it proves
  std::shared_ptr<Ice::ObjectAdapter> adapter;
  std::string alive_proxy;             ///< named by wire-p's genuine heartbeats
  std::atomic<bool> proving{true};     ///< wire-p answers nonces (else with nothing signed)
  std::string supervisor_alive_proxy;  ///< named by the supervisor's genuine heartbeats
  std::thread beat_thread;

  /// `lost_after`: the node's loss bound (0: its default, three heartbeat periods).
  explicit Bus(std::chrono::milliseconds lost_after = std::chrono::milliseconds(0)) {
    register_builtin_filters(registry);
    load = spec::load_system_from_text(kSystem, "wire.json", registry);
    EXPECT_TRUE(load.ok());
    // The attacker's keys are not the system's, but its certificate is of the system's CA: an
    // insider at the broker (a reader), whose messages every receiver must still refuse.
    EXPECT_TRUE(fixture::make_keys(*load.system, keys));
    EXPECT_TRUE(fixture::make_keys(*load.system, attacker_keys));
    ice = Ice::CommunicatorHolder(fixture::communicator(keys, "wire-p"));
    supervisor_ice = Ice::CommunicatorHolder(fixture::communicator(keys, "supervisor"));
    provider = load_signer(keys, "wire-p");
    other = load_signer(keys, "wire-c");
    supervisor = load_signer(keys, "supervisor");
    attacker = load_signer(attacker_keys, "wire-p");
    monitor = std::make_unique<Monitor>(co, registry);
    EXPECT_TRUE(spec::instantiate(*load.system, co, *monitor, "wire-c"));
    EXPECT_TRUE(middleware::connect_remote_providers(*load.system, "wire-c", co));
    for (const char* d : {"P.D0", "P.D1", "P.D2", "P.D3"}) last_sent[d] = 0;

    adapter = ice->createObjectAdapterWithEndpoints("ProviderAlive", fixture::kAdapterEndpoint);
    alive_proxy = adapter->addWithUUID(std::make_shared<FakeAlive>(*this, "wire-p"))->ice_toString();
    supervisor_adapter = supervisor_ice->createObjectAdapterWithEndpoints("SupervisorAlive", fixture::kAdapterEndpoint);
    supervisor_alive_proxy =
        supervisor_adapter->addWithUUID(std::make_shared<FakeAlive>(*this, "supervisor"))->ice_toString();
    adapter->activate();
    supervisor_adapter->activate();
    state_pub = Ice::uncheckedCast<wire::StateTopicPrx>(topic("safecass.state.wire-p")->getPublisher()->ice_oneway());
    beat_thread = std::thread([this] {
      while (running.load()) {
        try {
          if (beating.load()) beat(*provider, "wire-p", kIncarnation);
        } catch (const Ice::Exception& e) {  // a beat lost on the way, as on a network; said in the log
          std::lock_guard lock(mutex);
          log.push_back(std::string("test: wire-p's heartbeat not sent (") + e.ice_id() + ")");
        }
        beat_rounds.fetch_add(1);
        std::this_thread::sleep_for(100ms);
      }
    });

    node = start_node(lost_after);
    if (!node) return;
    EXPECT_TRUE(eventually([&] { return node->stats().connected; }, 10000ms));
    // The node's subscriptions are in place: IceStorm lists a subscriber on each of its topics.
    EXPECT_TRUE(eventually(
        [&] {
          for (const char* t : {"safecass.state.wire-p", "safecass.heartbeat.wire-p", "safecass.resync"}) {
            if (subscribers(t).empty()) return false;
          }
          return true;
        },
        10000ms));
    // The node believes wire-p once its process has answered the node's nonce.
    EXPECT_TRUE(
        eventually([&] { return all_log().find("coordinator 'wire-p' proved alive") != std::string::npos; }, 10000ms))
        << all_log();
  }
  /// wire-p falls silent: once this returns no heartbeat of it is on its way (one the beat thread
  /// was sending when told may otherwise reach a receiver that subscribes after).
  void silence() {
    beating.store(false);
    const std::uint64_t round = beat_rounds.load();
    EXPECT_TRUE(eventually([&] { return beat_rounds.load() >= round + 2; }));
  }
  /// wire-c's node on this bus, its lines in `log`; started (null, said, when it cannot be).
  std::unique_ptr<middleware::CoordinatorNode> start_node(std::chrono::milliseconds lost_after = 0ms) {
    middleware::NodeOptions options;
    options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + port);
    options.keys_dir = keys;
    options.lost_after = lost_after;
    options.log = [this](const std::string& line) {
      std::lock_guard lock(mutex);
      log.push_back(line);
    };
    auto n = middleware::CoordinatorNode::create(co, *monitor, registry, *load.system, "wire-c", options);
    EXPECT_TRUE(n) << (n ? "" : n.error().message);
    if (!n) return nullptr;
    EXPECT_TRUE((*n)->start());
    return std::move(*n);
  }
  ~Bus() {
    running.store(false);
    if (beat_thread.joinable()) beat_thread.join();
    if (node) node->stop();
    adapter->destroy();
    supervisor_adapter->destroy();
  }

  /// The topic `name` of the fixture's members' broker (created when it does not exist yet),
  /// linked to the tools' broker when tools hear it, as a member that publishes on it links it.
  std::shared_ptr<IceStorm::TopicPrx> topic(const std::string& name) {
    auto manager = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(ice->stringToProxy(fixture::topic_manager(port)));
    std::shared_ptr<IceStorm::TopicPrx> t;
    try {
      t = manager->retrieve(name);
    } catch (const IceStorm::NoSuchTopic&) {
      t = manager->create(name);
    }
    if (middleware::tools_hear(name) && linked.insert(name).second) {
      middleware::link_topic(t,
                             Ice::uncheckedCast<IceStorm::TopicManagerPrx>(
                                 ice->stringToProxy(fixture::topic_manager(port, fixture::Broker::Tools))),
                             name);
    }
    return t;
  }
  std::set<std::string> linked;  ///< the topics topic() linked to the tools' broker
  /// Who subscribes to `name` at `broker`: the processes, not the links to the tools' broker.
  std::vector<Ice::Identity> subscribers(const std::string& name, fixture::Broker broker = fixture::Broker::Members) {
    std::shared_ptr<IceStorm::TopicPrx> t;
    if (broker == fixture::Broker::Members) {
      t = topic(name);
    } else {
      t = middleware::topic(Ice::uncheckedCast<IceStorm::TopicManagerPrx>(
                                ice->stringToProxy(fixture::topic_manager(port, fixture::Broker::Tools))),
                            name);
    }
    auto all = t->getSubscribers();
    std::erase_if(all, [](const Ice::Identity& id) { return id.category == middleware::kToolStormInstance; });
    return all;
  }

  /// Lists in `h` the state streams the system file gives `h.coordinator` (under mutex): wire-p's
  /// at the numbers last sent, any other's at 0.
  void list_states(wire::Heartbeat& h) const {
    const middleware::StateStreams streams = h.coordinator == "wire-p" && provider_streams
                                                 ? *provider_streams
                                                 : middleware::Members(*load.system).state_streams(h.coordinator);
    h.statesId = streams.id;
    h.states.clear();
    for (const std::string& iface : streams.ifaces) {
      const auto it = h.coordinator == "wire-p" ? last_sent.find(iface) : last_sent.end();
      h.states.push_back(it == last_sent.end() ? 0 : it->second);
    }
  }
  /// wire-p's heartbeat as it stands (under mutex): the streams' last numbers.
  wire::Heartbeat provider_heartbeat(std::int64_t incarnation, std::int64_t seq) {
    wire::Heartbeat h;
    h.coordinator = "wire-p";
    h.incarnation = incarnation;
    h.seq = seq;
    h.time = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
                 .count();
    h.control = alive_proxy;
    list_states(h);
    if (events_sent) h.events = *events_sent;
    h.settling = settling;
    return h;
  }
  /// A heartbeat of `name` signed by `key`, listing the streams' last numbers. wire-p's genuine
  /// heartbeats name its Alive object unless `control` is given.
  void beat(const Signer& key, const std::string& name, std::int64_t incarnation, std::string control = {}) {
    if (control.empty() && name == "wire-p" && &key == &*provider) control = alive_proxy;
    if (control.empty() && name == "supervisor" && &key == &*supervisor) control = supervisor_alive_proxy;
    wire::Heartbeat h;
    h.coordinator = name;
    h.incarnation = incarnation;
    h.time = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
                 .count();
    h.control = std::move(control);
    {
      std::lock_guard lock(mutex);
      h.seq = ++beat_seq;
      if (&key == &*provider) newest = std::max(newest, incarnation);
      list_states(h);
      if (name == "wire-p") {
        if (events_sent) h.events = *events_sent;
        h.settling = settling;
      }
    }
    heartbeat_pub(name)->beat(key.sign(middleware::kKindHeartbeat, encode(ice.communicator(), h)));
  }
  /// The state message body of `updates` (of one incarnation) as coordinator `coordinator` sends
  /// it: each interface by its position among wire-p's streams (one past them when wire-p has no
  /// such interface), the list's id the one `coordinator`'s heartbeats list.
  wire::StateBatch batch(const std::vector<Update>& updates, const std::string& coordinator = "wire-p") const {
    wire::Heartbeat listed;
    listed.coordinator = coordinator;
    std::lock_guard lock(mutex);
    list_states(listed);
    const middleware::StateStreams streams =
        provider_streams ? *provider_streams : middleware::Members(*load.system).state_streams("wire-p");
    wire::StateBatch b{coordinator, updates.empty() ? kIncarnation : updates.front().incarnation, listed.statesId, {}};
    for (const Update& u : updates) {
      EXPECT_EQ(u.incarnation, b.incarnation) << "a batch is of one process";
      wire::StateUpdate w = u.wire;
      w.stream = static_cast<std::int32_t>(std::find(streams.ifaces.begin(), streams.ifaces.end(), u.iface) -
                                           streams.ifaces.begin());
      b.updates.push_back(std::move(w));
    }
    return b;
  }
  /// `updates` sealed by `key` as a state message of `coordinator`.
  wire::Signed sealed(const Signer& key, const std::vector<Update>& updates,
                      const std::string& coordinator = "wire-p") const {
    return key.seal(middleware::kKindState, encode(ice.communicator(), batch(updates, coordinator)));
  }
  /// Publishes `updates` sealed by `key`; a genuine batch also advances what the heartbeat lists.
  void send(const Signer& key, const std::vector<Update>& updates) {
    state_pub->updates(sealed(key, updates));
    if (&key != &*provider) return;
    std::lock_guard lock(mutex);
    for (const Update& u : updates) last_sent[u.iface] = std::max<std::int64_t>(last_sent[u.iface], u.wire.seq);
  }
  /// Publishes `updates` sealed by `key` without advancing what wire-p's heartbeats list: what its
  /// process never sent (its key misused, an older incarnation's), so its heartbeats never list it.
  void send_unlisted(const Signer& key, const std::vector<Update>& updates) {
    state_pub->updates(sealed(key, updates));
  }
  State state(const std::string& machine) { return co.state(*co.structure().find_machine(machine)); }
  std::string all_log() {
    std::lock_guard lock(mutex);
    std::string all;
    for (const std::string& line : log) all += line + "\n";
    return all;
  }
  bool explains(const std::string& machine, const std::string& event) {
    auto why = explain(co, machine);
    if (!why) return false;
    for (const Explanation& e : *why) {
      if (e.event == event || e.root.event == event) return true;
    }
    return false;
  }
};

wire::Signed FakeAlive::prove(wire::Bytes nonce, const Ice::Current&) {
  std::lock_guard lock(bus_.mutex);
  if (name_ == "wire-p" && !bus_.proving.load()) return {};
  if (name_ == "wire-p") {
    return middleware::make_proof(*bus_.provider, bus_.ice.communicator(), nonce,
                                  bus_.provider_heartbeat(bus_.newest, bus_.beat_seq));
  }
  wire::Heartbeat h;
  h.coordinator = name_;
  h.incarnation = kIncarnation;
  h.seq = bus_.beat_seq;
  h.control = bus_.supervisor_alive_proxy;
  bus_.list_states(h);
  return middleware::make_proof(*bus_.supervisor, bus_.ice.communicator(), nonce, h);
}

TEST(Wire, ABadUpdateInABatchIsRefusedAloneAndTheOthersApply) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error),
                           update("P.D1", 1, "EVT_UNKNOWN", wire::Level::Error),  // unknown event
                           update("P.D2", 1, "EVT_E", wire::Level::Normal),       // a Normal root
                           update("P.D3", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return bus.node->stats().updates_applied + bus.node->stats().updates_rejected >= 4; }));
  EXPECT_EQ(bus.state("C.s_R.D0"), State::Error);
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Normal) << "refused: nothing changed";
  EXPECT_EQ(bus.state("C.s_R.D2"), State::Normal) << "refused: nothing changed";
  EXPECT_EQ(bus.state("C.s_R.D3"), State::Error);
  EXPECT_EQ(bus.node->stats().updates_applied, 2u);
  EXPECT_EQ(bus.node->stats().updates_rejected, 2u);
  // Refusals are logged at most once per second per source (and always counted).
  EXPECT_NE(bus.all_log().find("refused state update P.D1 seq 1 from coordinator 'wire-p': nothing changed"),
            std::string::npos)
      << bus.all_log();
  EXPECT_NE(bus.all_log().find("no event 'EVT_UNKNOWN'"), std::string::npos) << bus.all_log();

  // The refused streams are not stuck: their next update applies; a repeated number is ignored.
  bus.send(*bus.provider,
           {update("P.D1", 2, "EVT_E", wire::Level::Error), update("P.D0", 1, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; }));
  EXPECT_TRUE(eventually([&] { return bus.node->stats().updates_rejected == 3u; })) << "P.D0 seq 1 again: stale";
}

TEST(Wire, ForgedReplayedMisattributedAndFarFutureUpdatesAreRefusedAndChangeNothing) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  const std::vector<Update> raise{update("P.D0", 1, "EVT_E", wire::Level::Error)};
  bus.send(*bus.provider, raise);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; }));
  bus.send(*bus.provider, {update("P.D0", 2, "", wire::Level::Normal)});
  // The node counts an update after applying it, so the state can be seen before the count.
  ASSERT_TRUE(
      eventually([&] { return bus.state("C.s_R.D0") == State::Normal && bus.node->stats().updates_applied == 2u; }));
  const auto before = bus.node->stats();

  auto ic = bus.ice.communicator();
  // 1. Signed with a key that is not wire-p's (an attacker who read the heartbeat topic).
  bus.send(*bus.attacker, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  // 2. The one-message freeze: a sequence number near 2^63, forged.
  bus.send(*bus.attacker, {update("P.D0", std::numeric_limits<std::int64_t>::max() - 1, "", wire::Level::Normal)});
  // 3. Signed by another coordinator of the system (a real key) but naming wire-p.
  bus.send(*bus.other, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  // 4. Claiming wire-p as signer with another key's signature, and with no signature at all.
  wire::Signed relabelled = bus.sealed(*bus.other, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  relabelled.signer = "wire-p";
  bus.state_pub->updates(relabelled);
  wire::Signed unsigned_message = relabelled;
  unsigned_message.tags.clear();
  bus.state_pub->updates(unsigned_message);
  // 5. A replay of wire-p's genuine first message.
  bus.send(*bus.provider, raise);
  // 6. A genuine key, an older incarnation. wire-p's heartbeats do not list 6 and 7: if they did,
  // the node would rightly count the numbers they list as lost once the loss bound passed.
  bus.send_unlisted(*bus.provider, {update("P.D0", 100, "EVT_E", wire::Level::Error, kIncarnation - 1)});
  // 7. A genuine key, a jump far into the future (a stream must not be frozen even by its owner).
  bus.send_unlisted(*bus.provider, {update("P.D0", 2 + (std::int64_t{1} << 21), "EVT_E", wire::Level::Error)});
  // 8. A heartbeat kind sent on the state topic.
  wire::Heartbeat hb;
  hb.coordinator = "wire-p";
  bus.state_pub->updates(bus.provider->sign(middleware::kKindHeartbeat, encode(ic, hb)));

  EXPECT_TRUE(eventually([&] { return bus.node->stats().messages_refused - before.messages_refused >= 9; }))
      << bus.all_log();
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(bus.state("C.s_R.D0"), State::Normal) << "nothing forged or replayed changed the state\n" << bus.all_log();
  EXPECT_EQ(bus.node->stats().updates_applied, before.updates_applied);
  EXPECT_EQ(bus.node->stats().messages_refused - before.messages_refused, 9u);
  EXPECT_NE(bus.all_log().find("bad seal"), std::string::npos) << bus.all_log();

  // The stream is not frozen: wire-p's next genuine update applies at once.
  bus.send(*bus.provider, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; })) << bus.all_log();
}

TEST(Wire, AClientRaisesCoordinatorLostWhenItsProviderFallsSilentAndClearsOnceItIsBackAndResynchronised) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; }));
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Normal);

  bus.beating.store(false);  // wire-p dies (kill -9: no goodbye)
  // Forged heartbeats naming wire-p must not keep it alive.
  const auto until = std::chrono::steady_clock::now() + 1000ms;
  while (std::chrono::steady_clock::now() < until && bus.state("C.s_R.D1") != State::Error) {
    bus.beat(*bus.attacker, "wire-p", kIncarnation);
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Error) << "lost within the bound (3 heartbeats) + one check\n"
                                                 << bus.all_log();
  for (const char* r : {"C.s_R.D0", "C.s_R.D1", "C.s_R.D2", "C.s_R.D3"}) {
    EXPECT_TRUE(bus.explains(r, "EVT_COORDINATOR_LOST")) << r;
  }
  EXPECT_EQ(bus.co.extended(*bus.co.structure().find_component("C")).state, State::Error)
      << "dispatch() in the client sees Error";
  EXPECT_EQ(bus.node->stats().providers_lost, 1u);

  // Back, but with a state the client has not received yet (seq 2): still lost.
  {
    std::lock_guard lock(bus.mutex);
    bus.last_sent["P.D0"] = 2;
  }
  bus.beating.store(true);
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Error) << "not resynchronised yet";
  // Back only on a new proof of life (verify --bus, P2), which lists seq 2 as sent: the client asks
  // for a republish, and what wire-p republishes (seq 3) resynchronises it. The loss clears and
  // the client holds exactly the provider's state.
  bus.send(*bus.provider, {update("P.D0", 3, "", wire::Level::Normal)});
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  EXPECT_EQ(bus.state("C.s_R.D0"), State::Normal);
  EXPECT_FALSE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
}

/// A heartbeat of wire-p numbered `seq`, stamped `sent` (wire-p's steady clock), signed with its
/// key: what a member that took a subscription kept of wire-p's traffic, published again later.
void relay_heartbeat(Bus& bus, std::int64_t seq, std::int64_t sent) {
  wire::Heartbeat h;
  {
    std::lock_guard lock(bus.mutex);
    h = bus.provider_heartbeat(kIncarnation, seq);
  }
  h.time = sent;
  bus.heartbeat_pub("wire-p")->beat(bus.provider->sign(middleware::kKindHeartbeat, encode(bus.ice.communicator(), h)));
}

std::int64_t steady_now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// verify --bus, mutant no-reproof (P2), at wire level: a member that took the client's heartbeat
// subscription keeps wire-p's genuine heartbeats; wire-p dies; the member publishes them to the
// client, each newer than the last it took and each sent within the bound. Without a new proof of
// life they end no loss: the client stays at Error.
TEST(Wire, HeartbeatsAMemberKeptAndRelaysAfterTheProviderDiedEndNoLoss) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  bus.beating.store(false);  // wire-p dies
  bus.proving.store(false);  // and answers no nonce
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; })) << bus.all_log();
  std::int64_t seq = 0;
  {
    std::lock_guard lock(bus.mutex);
    seq = bus.beat_seq;
  }
  // The member publishes what it kept, one a period, each stamped as sent just now (the freshest
  // a recording could claim): numbers the client never took.
  const auto until = std::chrono::steady_clock::now() + 1500ms;
  while (std::chrono::steady_clock::now() < until) {
    relay_heartbeat(bus, ++seq, steady_now());
    std::this_thread::sleep_for(100ms);
    ASSERT_EQ(bus.state("C.s_R.D1"), State::Error) << "a relayed heartbeat ended the loss\n" << bus.all_log();
  }
  EXPECT_TRUE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
}

// A heartbeat lists numbers in the order both sides derive from the system file
// (Heartbeat::states). A provider run with another system file (here one that gives P a fifth
// interface) would have its numbers read as other interfaces' numbers: the client believes none
// of its heartbeats nor proofs instead, says why, and holds it lost until the lists agree again.
TEST(Wire, AProviderWhoseHeartbeatsAndUpdatesNumberOtherStateStreamsThanTheSystemFileGivesItIsLostAndSaysWhy) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  {
    std::lock_guard lock(bus.mutex);
    bus.provider_streams = middleware::StateStreams::of({"P.D0", "P.D1", "P.D2", "P.D3", "P.D4"});
  }
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; })) << bus.all_log();
  EXPECT_TRUE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
  const std::string log = bus.all_log();
  EXPECT_NE(log.find("it lists 5 state stream(s)"), std::string::npos) << log;
  EXPECT_NE(log.find("another system file?"), std::string::npos) << log;
  // Its state updates number the streams of its list too: refused whole, never read by position.
  // Sent until the refusal is logged (its heartbeats' refusals share the source's one line a second).
  const std::uint64_t rejected = bus.node->stats().updates_rejected;
  EXPECT_TRUE(eventually(
      [&] {
        bus.state_pub->updates(bus.sealed(*bus.provider, {update("P.D1", 1, "", wire::Level::Normal)}));
        return bus.all_log().find("its updates number the state streams of a list of id") != std::string::npos;
      },
      10000ms))
      << bus.all_log();
  EXPECT_GT(bus.node->stats().updates_rejected, rejected);
  std::this_thread::sleep_for(500ms);  // proofs asked meanwhile carry the same list
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Error) << bus.all_log();
  {
    std::lock_guard lock(bus.mutex);
    bus.provider_streams.reset();
  }
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << "the lists agree again\n"
                                                                                  << bus.all_log();
}

// verify --bus, mutant no-settle-hold (P5), at wire level: wire-p comes back from a partition still
// clearing a loss of its own (it lists the supervisor in Heartbeat::settling), its state about to
// change. Proven, caught up and fresh, it would end the client's loss; the client keeps the loss
// until wire-p has settled, and then clears it in one step to the state wire-p settled in.
TEST(Wire, AClientKeepsALossUntilItsProviderHasSettledItsOwnSoItsViewChangesOnce) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  bus.beating.store(false);  // cut off
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; })) << bus.all_log();
  {
    std::lock_guard lock(bus.mutex);
    bus.settling = {"supervisor"};  // it lost the supervisor too, and has not heard it again yet
  }
  bus.beating.store(true);  // the network heals
  // Proven again, and caught up with its Warning (republished each period, as a resync would):
  // the loss would end within a few periods, and shows D0 at Warning; it is kept while wire-p
  // settles, and D0 stays at Error.
  std::int64_t seq = 0;
  const auto until = std::chrono::steady_clock::now() + 1500ms;
  while (std::chrono::steady_clock::now() < until) {
    bus.send(*bus.provider, {update("P.D0", ++seq, "EVT_SUPERVISOR_LOST", wire::Level::Warning)});
    std::this_thread::sleep_for(100ms);
    ASSERT_EQ(bus.state("C.s_R.D0"), State::Error) << "a loss ended while wire-p settles\n" << bus.all_log();
  }
  EXPECT_TRUE(bus.explains("C.s_R.D0", "EVT_COORDINATOR_LOST"));
  // wire-p hears the supervisor again: its Warning clears, and its heartbeats list nothing.
  bus.send(*bus.provider, {update("P.D0", ++seq, "", wire::Level::Normal)});
  {
    std::lock_guard lock(bus.mutex);
    bus.settling.clear();
  }
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Normal; })) << bus.all_log();
  EXPECT_FALSE(bus.explains("C.s_R.D0", "EVT_COORDINATOR_LOST"));
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Normal);
}

// verify --bus, mutant arrival-time (P1), at wire level: wire-p is cut off from the client, and a
// member holds its heartbeats back and relays them late, one a period, so that one arrives
// whenever the bound would pass. Each counts from when it was sent: the client is lost within the
// bound after the last one sent in time, although heartbeats keep arriving. (Were wire-p still
// reachable, it would answer the client's new question and be believed again: alive, rightly.)
TEST(Wire, HeartbeatsHeldBackAndRelayedLateBuyNoTime) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  bus.beating.store(false);  // from now on the member holds everything back
  bus.proving.store(false);  // and wire-p is cut off from the client: only the member's relays reach it
  const std::int64_t held_from = steady_now();
  std::int64_t seq = 0;
  {
    std::lock_guard lock(bus.mutex);
    seq = bus.beat_seq;
  }
  // It relays, every 100 ms, a heartbeat sent 100 ms after the one before, starting from when it
  // began to hold them back: each arrives later than the one before (250 ms, then more).
  std::int64_t sent = held_from;
  const auto start = std::chrono::steady_clock::now();
  bool lost = false;
  while (std::chrono::steady_clock::now() - start < 2000ms && !lost) {
    std::this_thread::sleep_for(150ms);
    sent += 100'000'000;
    relay_heartbeat(bus, ++seq, sent);
    lost = bus.state("C.s_R.D1") == State::Error;
  }
  EXPECT_TRUE(lost) << "heartbeats relayed ever later kept the client Normal\n" << bus.all_log();
}

TEST(Wire, ACoordinatorRaisesAFrameworkWarningWhenTheSupervisorFallsSilent) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  for (int i = 0; i < 3; ++i) {
    bus.beat(*bus.supervisor, "supervisor", kIncarnation);
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(bus.state("C.s_F"), State::Normal);
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_F") == State::Warning; }, 2000ms)) << bus.all_log();
  EXPECT_TRUE(bus.explains("C.s_F", "EVT_SUPERVISOR_LOST"));
  bus.beat(*bus.supervisor, "supervisor", kIncarnation);
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_F") == State::Normal; }, 2000ms)) << bus.all_log();
}

TEST(Wire, AClientSendsItsTokenOnlyToACoordinatorFoundThroughAnAuthenticatedHeartbeatOnThisHost) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beating.store(false);
  std::atomic<bool> spoofing{true};
  std::atomic<bool> remote_control{false};
  std::thread spoofer([&] {
    while (spoofing.load()) {
      // Forged: "wire-p" with an attacker's Control proxy on this host.
      bus.beat(*bus.attacker, "wire-p", kIncarnation, "control-wire-p -t:tcp -h 127.0.0.1 -p 1");
      // Genuine, but its Control endpoint is on another host.
      if (remote_control.load())
        bus.beat(*bus.provider, "wire-p", kIncarnation, "control-wire-p -t:tcp -h 10.1.2.3 -p 9");
      std::this_thread::sleep_for(50ms);
    }
  });
  middleware::ClientOptions o;
  o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  o.coordinator = "wire-p";
  o.token = std::string(64, 'a');
  o.keys_dir = bus.keys;
  o.timeout = 800ms;
  auto lured = middleware::RemoteClient::connect(o);
  ASSERT_FALSE(lured);
  EXPECT_EQ(lured.error().code, ErrorCode::Io);
  EXPECT_NE(lured.error().message.find("forged heartbeat(s) naming it refused"), std::string::npos)
      << lured.error().message;

  remote_control.store(true);
  auto far = middleware::RemoteClient::connect(o);
  ASSERT_FALSE(far);
  EXPECT_EQ(far.error().code, ErrorCode::Denied) << far.error().message;
  EXPECT_NE(far.error().message.find("not on this host"), std::string::npos) << far.error().message;
  spoofing.store(false);
  spoofer.join();

  // The real coordinator, found through its own signed heartbeat, answers.
  o.coordinator = "wire-c";
  o.timeout = 2000ms;
  auto real = middleware::RemoteClient::connect(o);
  ASSERT_TRUE(real) << real.error().message;
  EXPECT_EQ(*(*real)->coordinator(), "wire-c");
}

TEST(Wire, TheSupervisorBelievesOnlyAuthenticatedFreshMessagesAndPrintsEachOnOneLine) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  std::mutex mutex;
  std::string printed;
  middleware::SupervisorOptions options;
  options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  options.keys_dir = bus.keys;
  options.lost_after = 300ms;
  options.print = [&](const std::string& line) {
    std::lock_guard lock(mutex);
    printed += line + "\n";
  };
  auto supervisor = middleware::Supervisor::create(*bus.load.system, options);
  ASSERT_TRUE(supervisor) << supervisor.error().message;
  ASSERT_TRUE((*supervisor)->start());
  auto output = [&] {
    std::lock_guard lock(mutex);
    return printed;
  };
  ASSERT_TRUE(eventually([&] { return output().find("coordinator 'wire-p' is up") != std::string::npos; }, 5000ms))
      << output();

  // Spoofed heartbeats do not keep a dead coordinator alive.
  bus.beating.store(false);
  const auto until = std::chrono::steady_clock::now() + 1500ms;
  while (std::chrono::steady_clock::now() < until && output().find("coordinator 'wire-p' lost") == std::string::npos) {
    bus.beat(*bus.attacker, "wire-p", kIncarnation);
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_NE(output().find("coordinator 'wire-p' lost"), std::string::npos) << output();
  EXPECT_EQ((*supervisor)->lost(), std::vector<std::string>{"wire-p"});

  // A forged event record cannot add a line; a genuine one with a newline in it stays on one line.
  const auto topic = bus.topic("safecass.events");
  auto events = Ice::uncheckedCast<wire::EventTopicPrx>(topic->getPublisher()->ice_oneway());
  // A machine's transition (machine: the address) or a component's reset (component: the address).
  auto record = [](std::int64_t seq, wire::RecordKind kind, const std::string& address, const std::string& text) {
    wire::EventMessage m{};  // every field set: an indeterminate bool is undefined behaviour (UBSan)
    m.coordinator = "wire-p";
    m.incarnation = kIncarnation;
    m.seq = seq;
    m.record.kind = kind;
    (kind == wire::RecordKind::Transition ? m.record.machine : m.record.component) = address;
    m.record.event = "EVT_E";
    m.record.from = wire::Level::Error;
    m.record.to = wire::Level::Normal;
    m.record.level = wire::Level::Error;
    m.record.text = text;
    return m;
  };
  auto ic = bus.ice.communicator();
  events->records(bus.attacker->seal(
      middleware::kKindEvents,
      encode(ic, wire::EventMessageSeq{record(1, wire::RecordKind::Transition, "P.s_A\n[wire-p] FORGED", "")})));
  events->records(bus.provider->seal(
      middleware::kKindEvents,
      encode(ic, wire::EventMessageSeq{record(1, wire::RecordKind::Reset, "P", "operator\n[wire-p] FAKE LINE")})));
  ASSERT_TRUE(eventually([&] { return output().find("[wire-p] reset P (") != std::string::npos; })) << output();
  EXPECT_NE(output().find("[wire-p] reset P (operator\\x0a[wire-p] FAKE LINE)"), std::string::npos) << output();
  EXPECT_EQ(output().find("\n[wire-p] FAKE LINE"), std::string::npos) << output();
  EXPECT_EQ(output().find("FORGED"), std::string::npos) << output();
  // The same genuine record again is a replay.
  events->records(bus.provider->seal(
      middleware::kKindEvents, encode(ic, wire::EventMessageSeq{record(1, wire::RecordKind::Reset, "P", "again")})));

  // Back with a newer incarnation (a restart): its view is refreshed. The old incarnation still
  // beating beside it is a second process with the same name, and is reported.
  for (int i = 0; i < 3; ++i) {
    bus.beat(*bus.provider, "wire-p", kIncarnation + 1);
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(eventually([&] {
    return output().find("coordinator 'wire-p' restarted; its view is refreshed") != std::string::npos;
  })) << output();
  EXPECT_TRUE(eventually([&] { return output().find("coordinator 'wire-p' recovered") != std::string::npos; }))
      << output();
  bus.beat(*bus.provider, "wire-p", kIncarnation);
  EXPECT_TRUE(eventually([&] { return output().find("two processes run coordinator 'wire-p'") != std::string::npos; }))
      << output();
  EXPECT_EQ(output().find("reset P (again)"), std::string::npos) << "a replayed record is not printed\n" << output();
  EXPECT_GE((*supervisor)->messages_refused(), 3u);
  (*supervisor)->stop();
}

/// What a supervisor printed, kept by the test (the lines' text is made only here, on demand).
struct SupervisorOutput {
  std::mutex mutex;
  std::string text;
  /// Record lines of a coordinator (not of the supervisor's own model). Read by the test's thread
  /// while the supervisor's adds: atomic.
  std::atomic<std::size_t> records = 0;
  void operator()(const middleware::SupervisorLine& line) {
    std::lock_guard lock(mutex);
    if (line.kind() == middleware::SupervisorLine::Kind::Record && !line.coordinator().empty()) ++records;
    text += line.text() + "\n";
  }
  std::string all() {
    std::lock_guard lock(mutex);
    return text;
  }
};

std::optional<State> view_state(const middleware::Supervisor& s, const std::string& address) {
  for (const middleware::ViewRow& row : s.view()) {
    if (row.address == address) return row.state;
  }
  return std::nullopt;
}

/// A supervisor of the bus's system (records on) printing into `out`, started and waited for until
/// it printed `ready` (by default: wire-p's first heartbeat seen); null when it did not start.
std::unique_ptr<middleware::Supervisor> start_supervisor(Bus& bus, SupervisorOutput& out,
                                                         const std::string& ready = "coordinator 'wire-p' is up") {
  middleware::SupervisorOptions options;
  options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  options.keys_dir = bus.keys;
  options.output = [&out](const middleware::SupervisorLine& line) { out(line); };
  auto supervisor = middleware::Supervisor::create(*bus.load.system, options);
  EXPECT_TRUE(supervisor) << supervisor.error().message;
  if (!supervisor || !(*supervisor)->start()) return nullptr;
  EXPECT_TRUE(eventually([&] { return out.all().find(ready) != std::string::npos; })) << out.all();
  return std::move(*supervisor);
}

// Heartbeats go to one topic per signer: a coordinator hears itself (its heartbeat coming back
// proves its subscriptions work), the providers it holds and the supervisor; the supervisor hears
// every coordinator of the system file (and itself, to notice a second supervisor). Nobody hears
// the heartbeats of members it does not watch, so deliveries grow with the connections, not with
// the square of the members (docs/scaling.md).
TEST(Wire, ACoordinatorHearsTheHeartbeatsOfItselfItsProvidersAndTheSupervisorAndTheSupervisorThoseOfEveryCoordinator) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const auto node_hears = [&](const std::string& topic) {
    for (const Ice::Identity& id : bus.topic(topic)->getSubscribers()) {
      if (id.category.starts_with("safecass-wire-c-") && id.category.ends_with("-heartbeat")) return true;
    }
    return false;
  };
  for (const char* signer : {"wire-c", "wire-p", "supervisor"}) {
    const std::string topic = std::string("safecass.heartbeat.") + signer;
    EXPECT_TRUE(eventually([&] { return node_hears(topic); })) << topic;
    // The node and the supervisor: nobody else.
    EXPECT_TRUE(eventually([&] { return bus.subscribers(topic).size() == 2; })) << topic;
  }
}

// A process knows its link to IceStorm works when its own heartbeat comes back round: only a
// heartbeat not back a period after it was sent costs a ping. Counted from the arrival instead,
// the period plus the link thread's own work made nearly every heartbeat late: a round trip to
// IceStorm each period, from every process.
TEST(Wire, AHealthyLinkCostsNoPingOfIceStormPerPeriod) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  const std::uint64_t before = bus.node->stats().broker_pings;
  std::this_thread::sleep_for(2000ms);  // 20 heartbeat periods of a healthy link
  const std::uint64_t pings = bus.node->stats().broker_pings - before;
  EXPECT_LE(pings, 2u) << "pinged in " << pings << " of 20 periods\n" << bus.all_log();
  EXPECT_EQ(bus.node->stats().connects, 1u) << bus.all_log();
}

// IceStorm drops a twoway subscriber whose delivery fails or times out (a process starved, or a
// message it cannot decode), and anyone who reaches IceStorm can unsubscribe anybody: a process
// that did not notice would go on with nothing reaching it. Here every subscription of the
// provider's state topic and of the heartbeat topic is removed from outside.
TEST(Wire, ACoordinatorAndTheSupervisorMakeAgainASubscriptionThatIceStormNoLongerHolds) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;

  std::size_t removed = 0;
  for (const char* name : {"safecass.state.wire-p", "safecass.heartbeat.wire-p"}) {
    auto t = bus.topic(name);
    for (const Ice::Identity& subscriber : bus.subscribers(name)) {
      t->unsubscribe(bus.ice->stringToProxy(Ice::identityToString(subscriber)));
      ++removed;
    }
  }
  ASSERT_GE(removed, 4u) << "the node and the supervisor each subscribe to both topics";
  EXPECT_TRUE(eventually([&] { return bus.node->stats().resubscriptions >= 2; }, 3000ms)) << bus.all_log();
  EXPECT_TRUE(
      eventually([&] { return out.all().find("no longer held the subscription") != std::string::npos; }, 3000ms))
      << out.all();
  EXPECT_NE(bus.all_log().find("subscribed again under a new identity, resynchronising"), std::string::npos)
      << bus.all_log();

  // What the provider sends now reaches both views: republished once a period, as a coordinator
  // answers the requests of a receiver that lost it meanwhile (under load the removal can outlast
  // the loss bound, and a receiver that lost wire-p holds its state only from a republish).
  std::int64_t seq = 0;
  EXPECT_TRUE(eventually(
      [&] {
        bus.send(*bus.provider, {update("P.D0", ++seq, "EVT_E", wire::Level::Error)});
        return eventually(
            [&] { return bus.state("C.s_R.D0") == State::Error && view_state(sup, "P.s_S.D0") == State::Error; },
            100ms);
      },
      5000ms))
      << bus.all_log() << out.all();
  supervisor->stop();
}

// Members only at the broker (docs/security.md): IceStorm serves mutual TLS only, and admits a
// process only with a certificate of the system's CA; the members' broker refuses the tools'
// certificate too (tools hear the topics linked to the tools' broker). Without a member's
// certificate (plain TCP, a certificate of another CA, the tools' reader) nobody lists,
// unsubscribes, takes an identity, creates or publishes; the victim keeps its subscriptions and
// sees the provider's next fault at once, without having to make one again.
TEST(Wire, NeitherANonMemberNorAToolCanListUnsubscribeOrCreateATopicAtTheMembersBrokerAndTheVictimsViewStaysTrue) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  const std::size_t held = bus.topic("safecass.state.wire-p")->getSubscribers().size();
  ASSERT_GE(held, 1u) << "the node subscribes to the provider's state topic";
  const std::uint64_t resubscribed = bus.node->stats().resubscriptions;

  const std::string outsider_keys = bus.scratch + "/wire-outsider-keys";
  std::filesystem::remove_all(outsider_keys);
  ASSERT_TRUE(middleware::create_bus_keys(*bus.load.system, outsider_keys, middleware::KeyOptions::replacing()))
      << "a CA of its own";
  struct Outsider {
    const char* who;
    Ice::CommunicatorHolder ice;
    std::string manager;
  };
  // Each call bounded: a broker that never answers an outsider (the stress runs saw a plain-TCP
  // request to the TLS port wait for ever) is a refusal too, not a hung test.
  const std::pair<std::string, std::string> bounded{"Ice.Default.InvocationTimeout", "3000"};
  Ice::InitializationData plain;
  plain.properties = Ice::createProperties();
  plain.properties->setProperty(bounded.first, bounded.second);
  std::vector<Outsider> outsiders;
  outsiders.push_back({"plain TCP", Ice::CommunicatorHolder(Ice::initialize(plain)),
                       "SafecassIceStorm/TopicManager:tcp -h 127.0.0.1 -p " + bus.port + " -t 1000"});
  outsiders.push_back({"a certificate of another CA",
                       Ice::CommunicatorHolder(fixture::communicator(outsider_keys, "reader", {bounded})),
                       fixture::topic_manager(bus.port) + " -t 1000"});
  outsiders.push_back({"the tools' certificate",
                       Ice::CommunicatorHolder(fixture::communicator(bus.keys, "reader", {bounded})),
                       fixture::topic_manager(bus.port) + " -t 1000"});
  for (Outsider& o : outsiders) {
    auto manager = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(o.ice->stringToProxy(o.manager));
    EXPECT_THROW(manager->retrieveAll(), Ice::LocalException) << o.who << ": lists no topic";
    EXPECT_THROW(manager->create("safecass.outsider"), Ice::LocalException) << o.who << ": creates no topic";
    EXPECT_THROW(
        {
          auto t = manager->retrieve("safecass.state.wire-p");
          for (const Ice::Identity& victim : t->getSubscribers()) {
            t->unsubscribe(o.ice->stringToProxy(Ice::identityToString(victim)));
          }
        },
        Ice::LocalException)
        << o.who << ": unsubscribes nobody";
  }
  EXPECT_EQ(bus.topic("safecass.state.wire-p")->getSubscribers().size(), held);

  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; })) << bus.all_log();
  EXPECT_EQ(bus.node->stats().resubscriptions, resubscribed) << "no subscription was lost to make again";
}

// A coordinator of the system file that never sends a heartbeat the supervisor can believe (not
// started, or signing with a key the keyring does not hold) is lost once the bound has passed
// since the supervisor connected, and recovers with its first authentic heartbeat.
TEST(Wire, TheSupervisorReportsLostACoordinatorOfTheSystemItNeverHeardFrom) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beating.store(false);  // wire-p is silent from the start
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out, "supervisor: connected to IceStorm");
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;

  // Heartbeats naming wire-p under a key the keyring does not hold are not believed either.
  for (int i = 0; i < 10 && sup.lost().empty(); ++i) {
    bus.beat(*bus.attacker, "wire-p", kIncarnation);
    std::this_thread::sleep_for(100ms);
  }
  // Up to 15 s: wire-c, which beats, starts lost too, and is up once the supervisor has proved it
  // alive (over 5 s once, in make test beside the bus model's searches on both cores).
  EXPECT_TRUE(eventually([&] { return sup.lost() == std::vector<std::string>{"wire-p"}; }, 15000ms)) << out.all();
  EXPECT_EQ(sup.model().state(*sup.model().structure().find_machine("P.s_F")), State::Error) << out.all();
  EXPECT_NE(out.all().find("coordinator 'wire-p' not proven alive yet (the supervisor just started); "
                           "EVT_COORDINATOR_LOST on its components until it is"),
            std::string::npos)
      << out.all();
  EXPECT_EQ(out.all().find("coordinator 'wire-c' lost"), std::string::npos) << "wire-c beats: " << out.all();

  bus.beating.store(true);  // its first authentic heartbeat: up, and recovered
  EXPECT_TRUE(eventually([&] { return sup.lost().empty(); })) << out.all();
  EXPECT_TRUE(eventually([&] {
    return sup.model().state(*sup.model().structure().find_machine("P.s_F")) == State::Normal;
  })) << out.all();
  supervisor->stop();
}

TEST(Wire, TheSupervisorRefusesAReplayedStateUpdateSoAnOlderStateNeverComesBack) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;

  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Error; })) << out.all();
  bus.send(*bus.provider, {update("P.D0", 2, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Normal; })) << out.all();
  bus.send(*bus.provider, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Error; })) << out.all();
  const auto refused = sup.messages_refused();
  // The genuine, signed update 2 again: authentic, but older than what the view holds.
  bus.send(*bus.provider, {update("P.D0", 2, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() > refused; })) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_S.D0"), State::Error) << out.all();
  EXPECT_NE(out.all().find("for P.D0: seq 2 not above 3 (stale or replayed)"), std::string::npos) << out.all();
  EXPECT_NE(out.all().find("[wire-p] P.s_S.D0 Error (roots P.s_A:EVT_E)"), std::string::npos) << out.all();
  supervisor->stop();
}

// The view's rows of a restarted coordinator go (its new process starts from nothing) and come
// back from its new process's updates alone, one row per service, whatever the supervisor kept to
// reach a row without looking it up.
TEST(Wire, AfterACoordinatorRestartsTheSupervisorsServiceRowsComeOnlyFromItsNewProcess) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;
  const auto rows_of = [&](const std::string& address) {
    const auto view = sup.view();
    return std::count_if(view.begin(), view.end(), [&](const middleware::ViewRow& r) { return r.address == address; });
  };

  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Error; })) << out.all();
  for (int i = 0; i < 3; ++i) {
    bus.beat(*bus.provider, "wire-p", kIncarnation + 1);
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(eventually([&] {
    return out.all().find("coordinator 'wire-p' restarted; its view is refreshed") != std::string::npos;
  })) << out.all();
  EXPECT_EQ(rows_of("P.s_S.D0"), 0) << "the earlier process's row went with it\n" << out.all();

  // The new process's first update above what its proof listed makes the row again.
  bus.send(*bus.provider, {update("P.D0", 2, "EVT_W", wire::Level::Warning, kIncarnation + 1)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Warning; })) << out.all();
  EXPECT_EQ(rows_of("P.s_S.D0"), 1) << out.all();
  // The earlier process is older: its update changes nothing.
  const auto refused = sup.messages_refused();
  bus.send(*bus.provider, {update("P.D0", 3, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() > refused; })) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_S.D0"), State::Warning) << out.all();
  EXPECT_EQ(rows_of("P.s_S.D0"), 1) << out.all();
  supervisor->stop();
}

TEST(Wire, ASupervisorWatchingStatesOnlyGetsNoRecordsRefusesForgedUpdatesReportsMissedOnesAndLosesASilentCoordinator) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  middleware::SupervisorOptions options;
  options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  options.keys_dir = bus.keys;
  options.lost_after = 300ms;
  options.records = false;
  options.output = [&out](const middleware::SupervisorLine& line) { out(line); };
  auto supervisor = middleware::Supervisor::create(*bus.load.system, options);
  ASSERT_TRUE(supervisor) << supervisor.error().message;
  ASSERT_TRUE((*supervisor)->start());
  ASSERT_TRUE(eventually([&] { return out.all().find("coordinator 'wire-p' is up") != std::string::npos; }))
      << out.all();
  const middleware::Supervisor& sup = **supervisor;

  bus.send(*bus.provider, {update("P.D1", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D1") == State::Error; })) << out.all();
  EXPECT_NE(out.all().find("[wire-p] P.s_S.D1 Error (roots P.s_A:EVT_E)\n"), std::string::npos) << out.all();

  // A forged update (the attacker's key under the provider's name) changes nothing.
  bus.send(*bus.attacker, {update("P.D1", 2, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() >= 1; })) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_S.D1"), State::Error);

  // Event records are not followed: a genuine reset record prints nothing.
  const auto topic = bus.topic("safecass.events");
  auto events = Ice::uncheckedCast<wire::EventTopicPrx>(topic->getPublisher()->ice_oneway());
  wire::EventMessage m{};
  m.coordinator = "wire-p";
  m.incarnation = kIncarnation;
  m.seq = 1;
  m.record.kind = wire::RecordKind::Reset;
  m.record.component = "P";
  m.record.text = "operator: not followed";
  events->records(
      bus.provider->seal(middleware::kKindEvents, encode(bus.ice.communicator(), wire::EventMessageSeq{m})));

  // An update the heartbeat lists but that never came: reported after two heartbeats.
  {
    std::lock_guard lock(bus.mutex);
    bus.last_sent["P.D2"] = 4;
  }
  EXPECT_TRUE(eventually([&] {
    return out.all().find("supervisor: 4 state update(s) of 'wire-p' missed; asking for its full state") !=
           std::string::npos;
  })) << out.all();
  EXPECT_EQ(out.all().find("not followed"), std::string::npos) << out.all();
  EXPECT_EQ(out.records, 0u) << out.all();

  // A coordinator that falls silent is lost: the view gets worse, never stale-green.
  bus.beating.store(false);
  EXPECT_TRUE(eventually([&] { return sup.lost() == std::vector<std::string>{"wire-p"}; })) << out.all();
  EXPECT_TRUE(eventually([&] {
    return sup.model().state(*sup.model().structure().find_machine("P.s_F")) == State::Error;
  })) << out.all();
  (*supervisor)->stop();
}

/// Publishes hand-made event records of 'wire-p' (signed with its key) in the order given:
/// record `seq` takes P.s_A to Error (odd seq) or back to Normal (even seq).
struct RecordSender {
  explicit RecordSender(Bus& bus) : bus_(bus) {
    const auto topic = bus.topic("safecass.events");
    // Twoway: each batch is in IceStorm before the next is sent, so the order is the order sent.
    events_ = Ice::uncheckedCast<wire::EventTopicPrx>(topic->getPublisher()->ice_twoway());
  }

  void send(const std::vector<std::int64_t>& seqs) {
    wire::EventMessageSeq batch;
    for (std::int64_t seq : seqs) batch.push_back(record(seq));
    send_batch(batch);
  }

  void send_batch(const wire::EventMessageSeq& batch) {
    events_->records(bus_.provider->seal(middleware::kKindEvents, encode(bus_.ice.communicator(), batch)));
  }

  static wire::EventMessage record(std::int64_t seq) {
    wire::EventMessage m{};
    m.coordinator = "wire-p";
    m.incarnation = kIncarnation;
    m.seq = seq;
    m.record.kind = wire::RecordKind::Transition;
    m.record.machine = "P.s_A";
    m.record.component = "P";
    m.record.event = seq % 2 == 1 ? "EVT_E" : "/EVT_E";
    m.record.from = seq % 2 == 1 ? wire::Level::Normal : wire::Level::Error;
    m.record.to = seq % 2 == 1 ? wire::Level::Error : wire::Level::Normal;
    m.record.level = m.record.to;
    return m;
  }

private:
  Bus& bus_;
  std::shared_ptr<wire::EventTopicPrx> events_;
};

/// A supervisor with records on, started once 'wire-p' is up (its first heartbeat seen). With
/// `events_sent`, wire-p's heartbeats list that many event records sent.
std::unique_ptr<middleware::Supervisor> start_record_supervisor(Bus& bus, SupervisorOutput& out,
                                                                std::optional<std::int64_t> events_sent = {}) {
  {
    std::lock_guard lock(bus.mutex);
    bus.events_sent = events_sent;
  }
  return start_supervisor(bus, out);
}

/// wire-p's bus with a supervisor following its records (started once wire-p is up) and a sender
/// of hand-made records. With `events_sent`, wire-p's heartbeats list that many records sent.
struct RecordedBus {
  Bus bus;
  SupervisorOutput out;
  std::unique_ptr<middleware::Supervisor> supervisor;
  RecordSender records{bus};
  explicit RecordedBus(std::optional<std::int64_t> events_sent = {})
      : supervisor(start_record_supervisor(bus, out, events_sent)) {}
  RecordedBus(const RecordedBus&) = delete;
  RecordedBus& operator=(const RecordedBus&) = delete;
  ~RecordedBus() {
    if (supervisor) supervisor->stop();
  }
};

TEST(Wire, ASupervisorAcceptsEventRecordsThatArriveLateAndReportsMissedThoseThatDoNotComeInTime) {
  // IceStorm forwards a topic's messages without ordering them: a batch can overtake the one
  // before it. A late record is authentic and new: it belongs in the history, it is not "missed"
  // and not a replay, and it never takes a row of the view back to an older state.
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  RecordedBus r;
  ASSERT_TRUE(r.bus.node);
  ASSERT_TRUE(r.supervisor);
  const middleware::Supervisor& sup = *r.supervisor;

  r.records.send({1});
  r.records.send({4, 5});  // 2 and 3 overtaken
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_A") == State::Error; })) << r.out.all();
  r.records.send({2, 3});  // late: 2 would take P.s_A to Normal, but 5 (Error) is newer
  ASSERT_TRUE(eventually([&] { return r.out.records >= 5; })) << r.out.all();
  std::this_thread::sleep_for(400ms);  // longer than the supervisor's wait for late records
  EXPECT_EQ(r.out.records, 5u) << r.out.all();
  EXPECT_EQ(sup.messages_refused(), 0u) << r.out.all();
  EXPECT_EQ(r.out.all().find("of 'wire-p' missed"), std::string::npos) << r.out.all();
  EXPECT_EQ(view_state(sup, "P.s_A"), State::Error) << r.out.all();
  // Printed after newer ones, each late record says so; the others do not.
  EXPECT_NE(r.out.all().find("/EVT_E (late: seq 2 arrived after newer records)"), std::string::npos) << r.out.all();
  EXPECT_NE(r.out.all().find("EVT_E (late: seq 3 arrived after newer records)"), std::string::npos) << r.out.all();
  EXPECT_EQ(r.out.all().find("seq 4 arrived"), std::string::npos) << r.out.all();

  // Received once already: a replay, refused.
  r.records.send({2});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() == 1; })) << r.out.all();
  EXPECT_NE(r.out.all().find("seq 2 not above 5 and received already (replayed)"), std::string::npos) << r.out.all();

  // 6 and 7 never come: reported missed, once, with their numbers.
  r.records.send({8});
  ASSERT_TRUE(eventually([&] { return r.out.all().find("of 'wire-p' missed") != std::string::npos; })) << r.out.all();
  EXPECT_NE(r.out.all().find("supervisor: 2 event record(s) of 'wire-p' missed (seq 6..7)"), std::string::npos)
      << r.out.all();
  EXPECT_EQ(view_state(sup, "P.s_A"), State::Normal) << r.out.all();
  // Reported missed, then it comes after all: authentic and never received, so accepted, and said
  // to be late; the view keeps the newer state of 8. Once received, it is a replay like any other.
  r.records.send({7});
  ASSERT_TRUE(eventually([&] { return r.out.records == 7u; })) << r.out.all();
  EXPECT_NE(
      r.out.all().find("supervisor: event record(s) of 'wire-p' reported missed (seq 6..7) arrive late; accepted"),
      std::string::npos)
      << r.out.all();
  EXPECT_NE(r.out.all().find("(late: seq 7 arrived after newer records)"), std::string::npos) << r.out.all();
  EXPECT_EQ(sup.messages_refused(), 1u) << r.out.all();
  EXPECT_EQ(view_state(sup, "P.s_A"), State::Normal) << r.out.all();
  r.records.send({7});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() == 2; })) << r.out.all();
  EXPECT_EQ(r.out.records, 7u) << r.out.all();
}

/// The records `out` says were missed of `who`, summed over its lines.
std::int64_t said_missed(const std::string& out, const std::string& who) {
  const std::string mark = " event record(s) of '" + who + "' missed (seq ";
  std::int64_t n = 0;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    constexpr std::string_view kPrefix = "supervisor: ";
    if (line.rfind(kPrefix, 0) == 0 && line.find(mark) != std::string::npos)
      n += std::strtoll(line.c_str() + kPrefix.size(), nullptr, 10);
  }
  return n;
}

TEST(Wire, ASupervisorSaysEveryRecordMissedEvenWhenGapsComeFasterThanItsLinesMay) {
  // After a broker failover gaps come in bursts. A line a second per coordinator, but none left
  // out: the gaps found within a second of a line are said in the next one, summed (a rate limit
  // that dropped them lost 18 transitions unreported in a chaos run).
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  RecordedBus r;
  ASSERT_TRUE(r.bus.node);
  ASSERT_TRUE(r.supervisor);

  r.records.send({1, 4});  // 2..3 never come
  ASSERT_TRUE(eventually([&] { return said_missed(r.out.all(), "wire-p") == 2; })) << r.out.all();
  EXPECT_NE(r.out.all().find("supervisor: 2 event record(s) of 'wire-p' missed (seq 2..3)"), std::string::npos)
      << r.out.all();
  r.records.send({7});   // 5..6 never come
  r.records.send({10});  // nor 8..9
  ASSERT_TRUE(eventually([&] { return said_missed(r.out.all(), "wire-p") >= 6; }, 5000ms)) << r.out.all();
  EXPECT_EQ(said_missed(r.out.all(), "wire-p"), 6) << r.out.all();
  // Said in one line when both gaps fall within the second after the first line (the usual case),
  // in two otherwise; either way with their numbers.
  const std::string out = r.out.all();
  EXPECT_TRUE(
      out.find("missed (seq 5..6, 8..9)") != std::string::npos ||
      (out.find("missed (seq 5..6)") != std::string::npos && out.find("missed (seq 8..9)") != std::string::npos))
      << out;
  std::size_t shown = 0;  // wire-p's records printed: 1, 4, 7 and 10
  for (auto at = out.find("[wire-p] P.s_A "); at != std::string::npos; at = out.find("[wire-p] P.s_A ", at + 1))
    ++shown;
  EXPECT_EQ(shown, 4u) << out;
}

TEST(Wire, ASupervisorReportsTheFirstRecordsOfACoordinatorMissedWhenItsHeartbeatListedNoneSent) {
  // The heartbeat the supervisor saw said no record was sent yet: record 3 arriving first means 1
  // and 2 were lost (an IceStorm restart just after the coordinator's first records), not that
  // the supervisor joined the stream at 3.
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  RecordedBus r(0);
  ASSERT_TRUE(r.bus.node);
  ASSERT_TRUE(r.supervisor);
  const middleware::Supervisor& sup = *r.supervisor;

  r.records.send({3});
  // Waits for wire-p's report: wire-c's own records may be reported missed first (sent before it
  // proved itself alive to the supervisor). The record is printed as it is taken, the gap by the
  // supervisor's watch loop: in either order.
  ASSERT_TRUE(eventually([&] {
    return r.out.all().find("of 'wire-p' missed") != std::string::npos && r.out.records >= 1;
  })) << r.out.all();
  EXPECT_NE(r.out.all().find("supervisor: 2 event record(s) of 'wire-p' missed (seq 1..2)"), std::string::npos)
      << r.out.all();
  EXPECT_EQ(r.out.records, 1u) << r.out.all();
  EXPECT_EQ(sup.messages_refused(), 0u) << r.out.all();
}

TEST(Wire, ASupervisorRefusesATransitionRecordThatNamesNoMachineAndItChangesNothing) {
  // A record's address is its machine (or, for a component's records, its component). A signed
  // transition record without one has no row to be shown under: refused, and its number is not
  // taken, so the record that follows with that number is accepted.
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  RecordedBus r;
  ASSERT_TRUE(r.bus.node);
  ASSERT_TRUE(r.supervisor);
  const middleware::Supervisor& sup = *r.supervisor;

  wire::EventMessage nameless = RecordSender::record(1);
  nameless.record.machine.clear();
  wire::EventMessage no_component = RecordSender::record(1);
  no_component.record.kind = wire::RecordKind::ComponentTransition;
  no_component.record.machine.clear();
  no_component.record.component.clear();
  r.records.send_batch(wire::EventMessageSeq{nameless, no_component});
  ASSERT_TRUE(eventually([&] { return sup.messages_refused() == 2; })) << r.out.all();
  EXPECT_EQ(r.out.records, 0u) << r.out.all();
  EXPECT_FALSE(view_state(sup, "").has_value()) << r.out.all();

  r.records.send({1});
  // The supervisor shows a record in its view, then prints it: wait for both.
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_A") == State::Error && r.out.records >= 1; }))
      << r.out.all();
  EXPECT_EQ(r.out.records, 1u) << r.out.all();
  EXPECT_EQ(sup.messages_refused(), 2u) << r.out.all();
  // Nothing of wire-p's is missed (wire-c's start-up records may be, under load: not this test's).
  EXPECT_EQ(r.out.all().find("of 'wire-p' missed"), std::string::npos) << r.out.all();
  EXPECT_FALSE(view_state(sup, "").has_value()) << r.out.all();
}

TEST(Wire, ASupervisorReportsMissedAndDoesNotTakeRecordsSentBeforeTheirCoordinatorProvedItselfAlive) {
  // 1. Its first heartbeat and its proof of life listed 5 records sent: 4 and 5 may still be on
  // the events topic, or be replays of records of long ago. A newcomer cannot tell them apart:
  // neither is taken as current (they were sent before it heard of wire-p: not missed either).
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  RecordedBus r(5);
  ASSERT_TRUE(r.bus.node);
  ASSERT_TRUE(r.supervisor);
  const middleware::Supervisor& sup = *r.supervisor;
  r.records.send({4, 5});
  r.records.send({6});
  // IceStorm delivers one topic's messages to a subscriber in order: once 6 is printed, 4 and 5
  // have been dealt with.
  ASSERT_TRUE(eventually([&] { return r.out.records == 1u; })) << r.out.all();
  EXPECT_EQ(r.out.records, 1u) << "4 and 5 are not printed as current\n" << r.out.all();
  EXPECT_EQ(view_state(sup, "P.s_A"), State::Normal) << r.out.all();  // 6: back to Normal
  EXPECT_EQ(r.out.all().find("of 'wire-p' missed"), std::string::npos) << r.out.all();

  // 2. A supervisor that hears of wire-p (a heartbeat listing 6 records sent) but cannot prove it
  // alive yet does not take records 7 and 8, whether they arrive before the proof (unproven) or
  // after it (at or below the count it lists); once proven, the proof lists 8 sent: both are
  // reported missed, and the view is read again.
  r.bus.proving.store(false);
  {
    // Before the late supervisor starts: every heartbeat it can hear lists the 6 records sent (set
    // after its start, a heartbeat still listing 5 could reach it first under load).
    std::lock_guard lock(r.bus.mutex);
    r.bus.events_sent = 6;
  }
  SupervisorOutput out;
  auto late = start_supervisor(r.bus, out, "supervisor: connected to IceStorm");
  ASSERT_TRUE(late);
  EXPECT_TRUE(eventually([&] { return out.all().find("not proven alive") != std::string::npos; })) << out.all();
  r.records.send({7, 8});
  {
    std::lock_guard lock(r.bus.mutex);
    r.bus.events_sent = 8;
  }
  r.bus.proving.store(true);
  EXPECT_TRUE(eventually([&] {
    return out.all().find("2 event record(s) of 'wire-p' missed (seq 7..8, sent before it proved itself alive") !=
           std::string::npos;
  })) << out.all();
  EXPECT_EQ(out.records, 0u) << out.all();
  late->stop();
}

TEST(Wire, SupervisorLinesAreTheReadModelsLiveLinesTaggedWithTheCoordinatorAndOnOneLine) {
  introspect::HistoryEntry e;
  e.kind = RecordKind::Transition;
  e.machine = "JR3.s_A";
  e.component = "JR3";
  e.from = State::Normal;
  e.to = State::Error;
  e.event = "EVT_FORCE_ERROR";
  e.root.emplace();
  e.root->event = "EVT_FORCE_ERROR";
  e.root->origin = "JR3.s_A";
  EXPECT_EQ(introspect::live_line(e), "JR3.s_A Normal -> Error EVT_FORCE_ERROR (root JR3.s_A:EVT_FORCE_ERROR)");
  EXPECT_EQ(middleware::SupervisorLine::of_record("robot", e).text(), "[robot] " + introspect::live_line(e));
  EXPECT_EQ(middleware::SupervisorLine::of_record("", e).text(), "supervisor: " + introspect::live_line(e));
  EXPECT_EQ(middleware::SupervisorLine::of_record("robot", e).record(), &e);
  introspect::HistoryEntry reset;
  reset.kind = RecordKind::Reset;
  reset.component = "BMM";
  reset.text = "operator\n[robot] FAKE";
  EXPECT_EQ(middleware::SupervisorLine::of_record("robot", reset).text(),
            "[robot] reset BMM (operator\\x0a[robot] FAKE)");
  EXPECT_EQ(middleware::SupervisorLine::of_state("ui", "C.s_S.Out", State::Warning, "roots JR3.s_A:EVT_W").text(),
            "[ui] C.s_S.Out Warning (roots JR3.s_A:EVT_W)");
  EXPECT_EQ(middleware::SupervisorLine::of_state("ui", "C.s_S.Out", State::Normal, "").text(), "[ui] C.s_S.Out Normal");
  EXPECT_EQ(middleware::SupervisorLine::notice("supervisor: coordinator 'ui' is up").kind(),
            middleware::SupervisorLine::Kind::Notice);
}

TEST(Wire, ACoordinatorReportsAnotherProcessRunningUnderItsName) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beat(*bus.other, "wire-c", kIncarnation);  // wire-c's key, another incarnation: a second process
  EXPECT_TRUE(eventually([&] { return bus.node->stats().duplicates_seen >= 1; })) << bus.all_log();
  EXPECT_TRUE(eventually([&] {
    return bus.all_log().find("another process runs coordinator 'wire-c'") != std::string::npos;
  })) << bus.all_log();
}

TEST(Wire, AFloodOfResyncRequestsCostsAtMostOneRepublishPerHeartbeatPeriod) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beating.store(false);  // a real wire-p runs below, with its own heartbeat
  middleware::HostClock clock;
  Coordinator provider("wire-p", &clock);
  Monitor monitor(provider, bus.registry);
  ASSERT_TRUE(spec::instantiate(*bus.load.system, provider, monitor, "wire-p"));
  middleware::NodeOptions options;
  options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  options.keys_dir = bus.keys;
  options.log = [](const std::string&) {};
  auto node = middleware::CoordinatorNode::create(provider, monitor, bus.registry, *bus.load.system, "wire-p", options);
  ASSERT_TRUE(node) << node.error().message;
  ASSERT_TRUE((*node)->start());
  ASSERT_TRUE(eventually([&] { return (*node)->stats().connected; }, 10000ms));
  std::this_thread::sleep_for(500ms);  // start-up republishes done

  const auto topic = bus.topic("safecass.resync");
  auto resync = Ice::uncheckedCast<wire::ResyncTopicPrx>(topic->getPublisher());
  const auto before = (*node)->stats().updates_published;
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t i = 1; i <= 300; ++i) {
    resync->resync(bus.supervisor->seal(
        middleware::kKindResync,
        encode(bus.ice.communicator(), wire::ResyncRequest{"supervisor", kIncarnation, i, "wire-p"})));
  }
  const auto elapsed = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
  std::this_thread::sleep_for(400ms);  // the last request kept inside a period is honoured
  const auto republished = (*node)->stats().updates_published - before;
  const auto periods = static_cast<std::uint64_t>(elapsed.count() / 100 + 6);
  EXPECT_GE(republished, 4u) << "the requests are honoured, not lost";
  EXPECT_LE(republished, 4 * periods) << "at most one republish (4 interfaces) per heartbeat period per requester, "
                                      << "over " << elapsed.count() << " ms";
  (*node)->stop();
}

TEST(Wire, StringsFromMessagesArePrintedOnOneLine) {
  EXPECT_EQ(middleware::printable("robot"), "robot");
  EXPECT_EQ(middleware::printable("a\nb\rc\x1b[2J\\"), "a\\x0ab\\x0dc\\x1b[2J\\\\");
  // Capped: a 128 KB name is not a 128 KB line.
  const std::string huge(std::size_t{128} * 1024, 'n');
  const std::string shown = middleware::printable(huge);
  EXPECT_EQ(shown, std::string(middleware::kMaxPrintable, 'n') + "...(+" +
                       std::to_string(huge.size() - middleware::kMaxPrintable) + " bytes)");
}

/// An Alive endpoint that answers every nonce with a proof it recorded earlier (a genuine proof of
/// the real process, signed for another nonce), and counts what it was asked.
class ReplayingAlive final : public wire::Alive {
public:
  explicit ReplayingAlive(wire::Signed recorded) : recorded_(std::move(recorded)) {}
  wire::Signed prove(wire::Bytes, const Ice::Current&) override {
    ++asked;
    return recorded_;
  }
  std::atomic<int> asked{0};

private:
  wire::Signed recorded_;
};

/// A dead process's heartbeats, recorded and replayed, name an endpoint an impostor now serves.
struct Impostor {
  std::shared_ptr<Ice::ObjectAdapter> adapter;
  std::shared_ptr<ReplayingAlive> alive;
  std::string proxy;
  explicit Impostor(Bus& bus) {
    std::lock_guard lock(bus.mutex);
    const Ice::ByteSeq old_nonce(middleware::kNonceBytes, 7);
    alive = std::make_shared<ReplayingAlive>(middleware::make_proof(
        *bus.provider, bus.ice.communicator(), old_nonce, bus.provider_heartbeat(kIncarnation, bus.beat_seq)));
    adapter = bus.ice->createObjectAdapterWithEndpoints("", fixture::kAdapterEndpoint);
    proxy = adapter->add(alive, Ice::stringToIdentity("safecass/control-wire-p"))->ice_toString();
    adapter->activate();
  }
  ~Impostor() { adapter->destroy(); }
};

// Attack: a process that starts after wire-p died is fed wire-p's recorded heartbeats (genuine
// signatures, rising numbers) naming an endpoint an impostor serves with a recorded proof. A
// heartbeat is believed only on a signed answer to the newcomer's own nonce: the newcomer's view
// stays Error (wire-p lost), the supervisor never says it is up, and the console sends no token.
TEST(Wire, ANewcomerBelievesNoReplayedHeartbeatOfAProcessThatCannotProveItselfAlive) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;  // the node wire-c starts while wire-p lives, and proves it
  ASSERT_TRUE(bus.node);
  bus.beating.store(false);  // wire-p dies
  Impostor impostor(bus);
  std::atomic<bool> replaying{true};
  std::thread replayer([&] {
    while (replaying.load()) {
      bus.beat(*bus.provider, "wire-p", kIncarnation + 1, impostor.proxy);  // as recorded, of a later run
      std::this_thread::sleep_for(50ms);
    }
  });
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out, "supervisor: connected to IceStorm");
  ASSERT_TRUE(supervisor);
  // wire-c is believed too, but once wire-c has lost wire-p (a loss bound after wire-p died) its
  // heartbeats list that loss as one it is clearing, and the supervisor then keeps wire-c lost for
  // up to Liveness::kSettleLimit (under load the supervisor proves wire-c only after that).
  EXPECT_TRUE(eventually([&] { return supervisor->lost() == std::vector<std::string>{"wire-p"}; },
                         middleware::Liveness::kSettleLimit + 3000ms))
      << out.all();
  EXPECT_EQ(out.all().find("coordinator 'wire-p' is up"), std::string::npos) << out.all();
  // Refusals are logged at most once a second per source (and 8 a second in all): under load the
  // first one said may be another (a question that timed out); this one comes.
  EXPECT_TRUE(eventually(
      [&] { return out.all().find("an answer to another nonce (a recorded proof)") != std::string::npos; }, 3000ms))
      << out.all();
  // The node had proven wire-p's earlier process; the replayed later one is not believed either.
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; }, 3000ms)) << bus.all_log();
  EXPECT_TRUE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));

  middleware::ClientOptions o;
  o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  o.coordinator = "wire-p";
  o.token = std::string(64, 'a');
  o.keys_dir = bus.keys;
  o.timeout = 800ms;
  auto lured = middleware::RemoteClient::connect(o);
  ASSERT_FALSE(lured);
  EXPECT_NE(lured.error().message.find("an answer to another nonce"), std::string::npos) << lured.error().message;
  EXPECT_GE(impostor.alive->asked.load(), 1) << "asked only for a proof: the impostor is no Control, so any "
                                                "other request (and the token) would have failed the connect";
  replaying.store(false);
  replayer.join();
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Error) << bus.all_log();
  supervisor->stop();
}

// Attack: every subscription of the provider's state topic is removed from outside, so its
// updates no longer reach the client, while its heartbeats (on another topic) still do. A stream
// that heartbeats show ahead of what the receiver holds, not caught up within the loss bound,
// counts as lost, as a silent provider does; it clears once the state is held again.
TEST(Wire, AStateStreamItsHeartbeatsShowAheadAndNotCaughtUpWithinTheBoundCountsAsLost) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  {
    std::lock_guard lock(bus.mutex);
    bus.last_sent["P.D0"] = 1;  // sent (the heartbeats say so) but never received
  }
  // The node starts with wire-p's interfaces at Error until it is proven alive and its state is
  // received (a newcomer starts toward safe): what to wait for is the loss the stream causes once
  // wire-p is proven, not the Error it already shows.
  EXPECT_TRUE(eventually(
      [&] {
        return bus.all_log().find("coordinator 'wire-p' lost (its heartbeats list state of P.D0 not received") !=
               std::string::npos;
      },
      3000ms))
      << bus.all_log();
  // The loss is said under the node's peer lock and written to the coordinator just after it.
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Error; }, 1000ms)) << bus.all_log();
  EXPECT_TRUE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
  // Back on a new proof of life (verify --bus, P2), which lists seq 1 as sent: the client asks for
  // a republish, and wire-p republishes (seq 2, 3, ... once a period, as a coordinator answers the
  // requests) until its state reaches the client through the subscription made again.
  std::int64_t republished = 1;
  EXPECT_TRUE(eventually(
      [&] {
        bus.send(*bus.provider, {update("P.D0", ++republished, "", wire::Level::Normal)});
        return eventually([&] { return bus.state("C.s_R.D1") == State::Normal; }, 100ms);
      },
      3000ms))
      << bus.all_log();
  EXPECT_FALSE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
}

// Attack: one message that does not decode, published on each topic. IceStorm drops a twoway
// subscriber whose dispatch fails; every subscription is oneway, so nobody is dropped, the
// message is counted once, and a flood of them is one log line a second, not a line each.
TEST(Wire, UndecodableMessagesDropNoSubscriptionAndAreLoggedAtMostOnceASecond) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  // A loss bound of 2 s: the 1,500 messages queue ahead of wire-p's heartbeats on the node's
  // connection, and on a loaded machine once held them back past the default 300 ms. A loss is
  // answered by subscribing again (a silent stream may be a dropped subscription), which this
  // test would read as a drop. A subscription IceStorm did drop is still seen: the node's check
  // of its subscriptions (every second) subscribes again, or IceStorm lists no subscriber.
  Bus bus(std::chrono::milliseconds(2000));
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const auto refused_before = bus.node->stats().messages_refused;
  // A well-formed request whose parameter is 3 bytes that are no wire::Signed.
  Ice::ByteSeq garbage;
  {
    Ice::OutputStream encoded(bus.ice.communicator());
    encoded.startEncapsulation();
    for (Ice::Byte b : {Ice::Byte{1}, Ice::Byte{2}, Ice::Byte{3}}) encoded.write(b);
    encoded.endEncapsulation();
    encoded.finished(garbage);
  }
  for (const char* name : {"safecass.state.wire-p", "safecass.heartbeat.wire-p", "safecass.resync"}) {
    auto pub = bus.topic(name)->getPublisher()->ice_oneway();
    const char* op = std::string(name) == "safecass.heartbeat.wire-p" ? "beat"
                     : std::string(name) == "safecass.resync"         ? "resync"
                                                                      : "updates";
    Ice::ByteSeq ignored;
    for (int i = 0; i < 500; ++i) pub->ice_invoke(op, Ice::OperationMode::Normal, garbage, ignored);
  }
  ASSERT_TRUE(eventually([&] { return bus.node->stats().messages_refused - refused_before >= 1000; })) << bus.all_log();
  std::this_thread::sleep_for(300ms);
  for (const char* name : {"safecass.state.wire-p", "safecass.heartbeat.wire-p", "safecass.resync"}) {
    EXPECT_FALSE(bus.subscribers(name).empty()) << name;
  }
  EXPECT_EQ(bus.node->stats().resubscriptions, 0u) << "nobody was dropped\n" << bus.all_log();
  std::size_t lines = 0;
  for (std::size_t at = bus.all_log().find("does not decode"); at != std::string::npos;
       at = bus.all_log().find("does not decode", at + 1))
    ++lines;
  EXPECT_GE(lines, 1u) << bus.all_log();
  EXPECT_LE(lines, 3u) << "1,000 undecodable messages in well under a second\n" << bus.all_log();
  // Everything still flows: an update reaches the node and the supervisor.
  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; })) << bus.all_log();
  EXPECT_TRUE(eventually([&] { return view_state(*supervisor, "P.s_S.D0") == State::Error; })) << out.all();
  supervisor->stop();
}

// Attack: members that sign as themselves but speak for others, or push a stream far ahead.
// wire-c (a member, its own key) reports wire-p's component P Normal; wire-p's own update jumps
// 2^21 ahead; a heartbeat carries an incarnation near 2^63; wire-p reports an interface P does
// not provide. None changes the supervisor's view, and none freezes a stream: wire-p's next
// genuine update applies.
TEST(Wire, TheSupervisorBelievesAMemberOnlyAboutItsOwnComponentsAndWithinTheJumpAndClockBounds) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;
  bus.send(*bus.provider, {update("P.D0", 1, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Error; })) << out.all();
  const auto refused = sup.messages_refused();

  // Each attack is sent until the supervisor says it refused it: on a machine too busy to deliver
  // heartbeats within the loss bound, the supervisor subscribes again, and a message published
  // while it does is never delivered. (Its refusals of one source are said at most once a second.)
  const auto refused_until_said = [&](const std::string& said, const std::function<void()>& send) {
    return eventually([&] {
      send();
      return out.all().find(said) != std::string::npos;
    });
  };
  // wire-c, on its own topic and signing as itself, about wire-p's component. wire-c provides no
  // interface: an update of its own can name none of P's.
  auto own = Ice::uncheckedCast<wire::StateTopicPrx>(bus.topic("safecass.state.wire-c")->getPublisher()->ice_oneway());
  EXPECT_TRUE(refused_until_said("of 'wire-c' for stream 0, not one of its 0 state streams", [&] {
    own->updates(bus.sealed(*bus.other, {update("P.D0", 2, "", wire::Level::Normal)}, "wire-c"));
  })) << out.all();
  // wire-p itself, 2^21 ahead (sent raw: its heartbeats do not list it).
  EXPECT_TRUE(refused_until_said("jumps more than 1048576 ahead", [&] {
    bus.state_pub->updates(
        bus.sealed(*bus.provider, {update("P.D0", 2 + (std::int64_t{1} << 21), "", wire::Level::Normal)}));
  })) << out.all();
  // wire-p's key, an incarnation near 2^63: refused, it does not lock wire-p out.
  EXPECT_TRUE(refused_until_said("more than 60 s ahead of this host's clock", [&] {
    bus.beat(*bus.provider, "wire-p", std::numeric_limits<std::int64_t>::max() - 1);
    std::lock_guard lock(bus.mutex);
    bus.newest = kIncarnation;  // that beat was a key holder's, not a restart: wire-p still proves its own
  })) << out.all();
  EXPECT_GE(sup.messages_refused(), refused + 3);
  EXPECT_TRUE(eventually([&] {
    return bus.all_log().find("more than 60 s ahead of this host's clock") != std::string::npos;
  })) << bus.all_log();
  EXPECT_EQ(view_state(sup, "P.s_S.D0"), State::Error) << out.all();
  // wire-p itself, about an interface its component does not provide: refused, no row is made
  // for it. Sent until the refusal is logged (a source's refusals are logged at most once a second).
  std::int64_t d9 = 0;
  EXPECT_TRUE(eventually([&] {
    bus.state_pub->updates(bus.sealed(*bus.provider, {update("P.D9", ++d9, "EVT_E", wire::Level::Error)}));
    return out.all().find("for stream 4, not one of its 4 state streams") != std::string::npos;
  })) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_S.D9"), std::nullopt) << out.all();
  // wire-p is not locked out: heard (a machine busy enough to starve its heartbeats past the loss
  // bound makes it lost for a while, and its proof of life ends that loss).
  EXPECT_TRUE(eventually([&] { return sup.lost().empty(); })) << out.all();
  bus.send(*bus.provider, {update("P.D0", 2, "", wire::Level::Normal)});
  EXPECT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Normal; })) << out.all();
  supervisor->stop();
}

}  // namespace
}  // namespace safecass

namespace safecass {
namespace {

/// Resident set size of this process, in KiB.
long rss_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  }
  return 0;
}

// Attack: a flood of 20,000 bad messages on each topic (undecodable bytes, forged seals and
// signatures, signer names of 1 KiB holding newlines and escape codes) while the provider raises a
// genuine fault. Both the coordinator and the supervisor see the fault (its latency is printed),
// their logs stay a few lines a second, and memory does not grow with the flood. A second burst of 300 messages with
// 128 KiB signer names grows neither.
TEST(Wire, AFloodOfBadMessagesOnEveryTopicHidesNoGenuineFaultAndGrowsNeitherLogsNorMemory) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  auto ic = bus.ice.communicator();
  Ice::ByteSeq garbage;
  {
    Ice::OutputStream encoded(ic);
    encoded.startEncapsulation();
    for (Ice::Byte b : {Ice::Byte{1}, Ice::Byte{2}, Ice::Byte{3}}) encoded.write(b);
    encoded.endEncapsulation();
    encoded.finished(garbage);
  }
  const std::string evil_name = std::string(1024, 'x') + "\n[wire-p] P.s_A Error -> Normal\x1b[2J";
  struct Topic {
    const char* name;
    const char* operation;
  };
  const std::vector<Topic> topics{{"safecass.state.wire-p", "updates"},
                                  {"safecass.events", "records"},
                                  {"safecass.heartbeat.wire-p", "beat"},
                                  {"safecass.resync", "resync"}};
  const std::size_t log_before = bus.all_log().size();
  const std::size_t out_before = out.all().size();
  const long rss_before = rss_kib();
  constexpr int kPerTopic = 20000;
  // The flood of the issue: 20,000 per topic in a few seconds (2 s: 40,000 messages a second in
  // all). SAFECASS_FLOOD_UNPACED=1 sends as fast as this process can instead, to see the queues.
  constexpr auto kFloodTime = std::chrono::milliseconds(2000);
  const bool paced = std::getenv("SAFECASS_FLOOD_UNPACED") == nullptr;
  std::chrono::steady_clock::duration flood_took{};
  std::atomic<bool> flooding{true};
  std::thread flood([&] {
    std::vector<std::shared_ptr<Ice::ObjectPrx>> pubs;
    pubs.reserve(topics.size());
    for (const Topic& t : topics) pubs.push_back(bus.topic(t.name)->getPublisher()->ice_batchOneway());
    // Forged: an attacker's seal and signature under a hostile signer name.
    wire::Signed forged = bus.sealed(*bus.attacker, {update("P.D0", 99, "", wire::Level::Normal)});
    forged.signer = evil_name;
    Ice::ByteSeq forged_bytes;
    {
      Ice::OutputStream encoded(ic);
      encoded.startEncapsulation();
      encoded.write(forged);
      encoded.endEncapsulation();
      encoded.finished(forged_bytes);
    }
    Ice::ByteSeq ignored;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < kPerTopic; ++i) {
      for (std::size_t t = 0; t < topics.size(); ++t) {
        pubs[t]->ice_invoke(topics[t].operation, Ice::OperationMode::Normal, i % 2 == 0 ? garbage : forged_bytes,
                            ignored);
      }
      if (i % 200 == 199) {
        for (auto& p : pubs) p->ice_flushBatchRequests();
        if (paced) std::this_thread::sleep_until(start + kFloodTime * (i + 1) / kPerTopic);
      }
    }
    for (auto& p : pubs) p->ice_flushBatchRequests();
    flood_took = std::chrono::steady_clock::now() - start;
    flooding.store(false);
  });
  // In the middle of the flood, wire-p raises a genuine fault.
  ASSERT_TRUE(eventually([&] { return bus.node->stats().messages_refused > 2000; }, 20000ms)) << bus.all_log();
  const auto sent = std::chrono::steady_clock::now();
  const std::vector<Update> fault{update("P.D0", 1, "EVT_E", wire::Level::Error)};
  bus.send(*bus.provider, fault);
  const auto supervisor_lost_p = [&] {
    const std::vector<std::string> lost = supervisor->lost();
    return std::find(lost.begin(), lost.end(), "wire-p") != lost.end();
  };
  // During the flood each receiver shows the fault, or worse: wire-p lost, when the flood (on a
  // loaded machine) starves its heartbeats past the loss bound. Never Normal.
  bool node_saw = false, supervisor_saw = false;
  std::string node_how, supervisor_how;
  std::chrono::steady_clock::duration node_after{}, supervisor_after{};
  while (std::chrono::steady_clock::now() - sent < 10s && !(node_saw && supervisor_saw)) {
    if (!node_saw && bus.state("C.s_R.D0") == State::Error) {
      node_saw = true;
      node_after = std::chrono::steady_clock::now() - sent;
      node_how = bus.explains("C.s_R.D0", "EVT_E") ? "the fault" : "wire-p lost";
    }
    if (!supervisor_saw && (view_state(*supervisor, "P.s_S.D0") == State::Error || supervisor_lost_p())) {
      supervisor_saw = true;
      supervisor_after = std::chrono::steady_clock::now() - sent;
      supervisor_how = view_state(*supervisor, "P.s_S.D0") == State::Error ? "the fault" : "wire-p lost";
    }
    std::this_thread::sleep_for(200us);
  }
  const bool mid_flood = flooding.load();
  flood.join();
  auto ms = [](std::chrono::steady_clock::duration d) {
    return static_cast<double>(std::chrono::duration_cast<std::chrono::microseconds>(d).count()) / 1000.0;
  };
  std::printf(
      "[flood] %d messages on each of %zu topics in %.0f ms (%s); the coordinator showed %s after %.1f ms, the "
      "supervisor %s after %.1f ms%s\n",
      kPerTopic, topics.size(), ms(flood_took), paced ? "paced" : "unpaced", node_how.c_str(), ms(node_after),
      supervisor_how.c_str(), ms(supervisor_after), mid_flood ? " (during the flood)" : "");
  EXPECT_TRUE(node_saw) << bus.all_log();
  EXPECT_TRUE(supervisor_saw) << out.all();
  // Paced, the receivers keep up and the fault is seen within a few milliseconds; unpaced it waits
  // in IceStorm's and the receivers' queues behind the flood on its own topic (docs/security.md).
  // The bound is loose so that a loaded machine passes: the figure is what the line above prints.
  EXPECT_LT(ms(node_after), 2000.0);
  EXPECT_LT(ms(supervisor_after), 2000.0);
  // Once the flood ends, both show the fault itself, and wire-p alive. A receiver that lost wire-p
  // asks it to republish: wire-p republishes once a period, under fresh numbers, as a coordinator
  // answers the requests (a number sent before the loss proves nothing after it).
  std::int64_t republished = 1;
  const auto both_show_the_fault = [&] {
    return bus.explains("C.s_R.D0", "EVT_E") && !bus.explains("C.s_R.D0", "EVT_COORDINATOR_LOST") &&
           view_state(*supervisor, "P.s_S.D0") == State::Error && !supervisor_lost_p();
  };
  EXPECT_TRUE(eventually(
      [&] {
        bus.send(*bus.provider, {update("P.D0", ++republished, "EVT_E", wire::Level::Error)});
        return eventually(both_show_the_fault, 100ms);
      },
      5000ms))
      << bus.all_log() << out.all();

  // Then 300 forged messages with 128 KiB signer names (64 MB of log before names were capped).
  {
    wire::Signed huge = bus.sealed(*bus.attacker, {});
    huge.signer = std::string(std::size_t{128} * 1024, 'n');
    for (int i = 0; i < 300; ++i) bus.state_pub->updates(huge);
  }
  ASSERT_TRUE(eventually([&] { return bus.node->stats().messages_refused >= 4u * kPerTopic / 4; }, 20000ms));
  std::this_thread::sleep_for(500ms);
  const std::size_t logged = bus.all_log().size() - log_before;
  const std::size_t printed = out.all().size() - out_before;
  const long grown = rss_kib() - rss_before;
  std::printf(
      "[flood] %llu messages refused by the coordinator; its log grew %zu bytes, the supervisor's %zu; RSS %+ld KiB\n",
      static_cast<unsigned long long>(bus.node->stats().messages_refused), logged, printed, grown);
  EXPECT_LT(logged, 64u * 1024u) << "a few capped lines a second, not one per message";
  EXPECT_LT(printed, 64u * 1024u) << out.all().substr(out_before, 4096);
  EXPECT_EQ(out.all().find("\n[wire-p] P.s_A Error -> Normal"), std::string::npos) << "no injected line";
  EXPECT_EQ(bus.all_log().find('\x1b'), std::string::npos) << "no terminal escape reaches a log";
  EXPECT_LT(grown, 32L * 1024L) << "memory does not grow with the flood";
  supervisor->stop();
}

}  // namespace
}  // namespace safecass

namespace safecass {
namespace {

// Attack: `console --ice watch` is fed event records of wire-c as sealed by wire-c's own key, of
// an earlier run (an older incarnation) and of a run that never proved itself alive (a later
// one). A follower believes nothing it cannot check: it follows the incarnation proven at
// connect and reads the records from that process's history, so it shows only what wire-c
// really recorded.
TEST(Wire, AFollowerShowsNoRecordOfAnotherIncarnationThanTheProcessProvenAlive) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  middleware::ClientOptions o;
  o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  o.coordinator = "wire-c";
  o.keys_dir = bus.keys;
  o.timeout = 3000ms;
  auto client = middleware::RemoteClient::connect(o);
  ASSERT_TRUE(client) << client.error().message;
  std::mutex mutex;
  std::vector<std::string> shown;
  auto follow = (*client)->follow([&](const introspect::HistoryEntry& e) {
    std::lock_guard lock(mutex);
    shown.push_back(e.event + " " + e.text);
  });
  ASSERT_TRUE(follow) << follow.error().message;
  ASSERT_TRUE(eventually([&] { return !bus.subscribers("safecass.events", fixture::Broker::Tools).empty(); }));

  // Records "of wire-c", sealed with its key, naming incarnations it does not run.
  auto events = Ice::uncheckedCast<wire::EventTopicPrx>(bus.topic("safecass.events")->getPublisher()->ice_twoway());
  auto record = [](std::int64_t incarnation, std::int64_t seq, const std::string& text) {
    wire::EventMessage m{};
    m.coordinator = "wire-c";
    m.incarnation = incarnation;
    m.seq = seq;
    m.record.seq = seq;
    m.record.kind = wire::RecordKind::Reset;
    m.record.component = "C";
    m.record.event = "FAKE";
    m.record.text = text;
    return m;
  };
  const std::int64_t refused = static_cast<std::int64_t>((*client)->records_refused());
  auto ic = bus.ice.communicator();
  for (std::int64_t incarnation : {std::int64_t{1}, std::numeric_limits<std::int64_t>::max() / 2}) {
    events->records(bus.other->seal(middleware::kKindEvents,
                                    encode(ic, wire::EventMessageSeq{record(incarnation, 1, "not this run")})));
  }
  ASSERT_TRUE(eventually([&] { return static_cast<std::int64_t>((*client)->records_refused()) >= refused + 2; }));
  // What wire-c really records is shown.
  ASSERT_TRUE(reset(bus.co, "C", "operator", "real").has_value());
  ASSERT_TRUE(eventually([&] {
    std::lock_guard lock(mutex);
    return std::any_of(shown.begin(), shown.end(),
                       [](const std::string& s) { return s.find("real") != std::string::npos; });
  })) << "the real record";
  std::lock_guard lock(mutex);
  for (const std::string& s : shown) EXPECT_EQ(s.find("not this run"), std::string::npos) << s;
}

}  // namespace
}  // namespace safecass

// ---- Bus v2.1: the attacks of the second independent review (docs/security.md) -------------------

namespace safecass {
namespace {

/// An object an attacker serves: every request is handed to `answer` (operation, its in-parameters
/// encapsulation) which returns the out-parameters encapsulation, or nothing for "not served";
/// every operation and the request's context are kept, to say what reached it.
class Relay final : public Ice::BlobjectArray {
public:
  using Answer = std::function<std::optional<std::vector<Ice::Byte>>(const std::string& operation,
                                                                     std::pair<const Ice::Byte*, const Ice::Byte*> in)>;
  explicit Relay(Answer answer) : answer_(std::move(answer)) {}
  bool ice_invoke(std::pair<const Ice::Byte*, const Ice::Byte*> in, std::vector<Ice::Byte>& out,
                  const Ice::Current& current) override {
    {
      std::lock_guard lock(mutex_);
      seen_.push_back(current.operation);
      for (const auto& [key, value] : current.ctx) seen_.push_back("context " + key);
    }
    auto answer = answer_(current.operation, in);
    if (!answer) throw Ice::OperationNotExistException(__FILE__, __LINE__);
    out = std::move(*answer);
    return true;
  }
  std::vector<std::string> seen() {
    std::lock_guard lock(mutex_);
    return seen_;
  }

private:
  Answer answer_;
  std::mutex mutex_;
  std::vector<std::string> seen_;
};

/// Encodes `value` as an operation's out-parameters.
template <class T>
std::vector<Ice::Byte> out_params(const std::shared_ptr<Ice::Communicator>& ic, const T& value) {
  Ice::OutputStream out(ic);
  out.startEncapsulation();
  out.write(value);
  out.endEncapsulation();
  std::vector<Ice::Byte> bytes;
  out.finished(bytes);
  return bytes;
}

/// Decodes an operation's single in-parameter.
template <class T>
T in_param(const std::shared_ptr<Ice::Communicator>& ic, std::pair<const Ice::Byte*, const Ice::Byte*> in) {
  Ice::InputStream stream(ic, in);
  stream.startEncapsulation();
  T value;
  stream.read(value);
  stream.endEncapsulation();
  return value;
}

/// An impostor's process: a communicator presenting `certificate` of the system's CA and an
/// object served on loopback.
struct ImpostorProcess {
  std::string certificate;
  Ice::CommunicatorHolder ice;
  std::shared_ptr<Ice::ObjectAdapter> adapter;
  std::shared_ptr<Relay> servant;
  std::string proxy;
  ImpostorProcess(const std::string& keys, const std::string& name, Relay::Answer answer)
      : certificate(name), ice(fixture::communicator(keys, name)) {
    adapter = ice->createObjectAdapterWithEndpoints("Relay", fixture::kAdapterEndpoint);
    servant = std::make_shared<Relay>(std::move(answer));
    proxy = adapter->add(servant, Ice::Identity{"control-wire-p", "safecass"})->ice_toString();
    adapter->activate();
  }
  ~ImpostorProcess() { adapter->destroy(); }
};

/// wire-c restarted: a new incarnation that proves itself with wire-c's key and serves its own
/// Control, answering `answer` for every operation but the proof. Its heartbeats list records
/// always ahead of what the supervisor holds, so the supervisor reads its view again (its state
/// list, then an explanation of each row not Normal).
struct RestartedMember {
  RestartedMember(Bus& bus_of, Relay::Answer answer)
      : bus(bus_of),
        process(bus.keys, "wire-c",
                [this, answer = std::move(answer)](const std::string& operation,
                                                   std::pair<const Ice::Byte*, const Ice::Byte*> in) {
                  auto ic = bus.ice.communicator();
                  if (operation == "prove") {
                    return std::optional<std::vector<Ice::Byte>>(out_params(
                        ic, middleware::make_proof(*bus.other, ic, in_param<Ice::ByteSeq>(ic, in), heartbeat())));
                  }
                  if (operation == "stateList") ++lists;
                  return answer(operation, in);
                }) {}
  wire::Heartbeat heartbeat() {
    wire::Heartbeat h;
    h.coordinator = "wire-c";
    h.incarnation = incarnation;
    h.seq = seq.load();
    h.control = process.proxy;
    bus.list_states(h);
    h.events = 1000 + seq.load();
    return h;
  }
  /// Beats every 50 ms until the supervisor has read its state list twice, 3 s at most.
  void beat_until_read() {
    auto ic = bus.ice.communicator();
    auto pub = Ice::uncheckedCast<wire::HeartbeatTopicPrx>(bus.topic("safecass.heartbeat.wire-c")->getPublisher());
    const auto until = std::chrono::steady_clock::now() + 3000ms;
    while (std::chrono::steady_clock::now() < until && lists.load() < 2) {
      ++seq;
      pub->beat(bus.other->sign(middleware::kKindHeartbeat, encode(ic, heartbeat())));
      std::this_thread::sleep_for(50ms);
    }
  }
  Bus& bus;
  const std::int64_t incarnation = middleware::new_incarnation();
  std::atomic<std::int64_t> seq{0};
  std::atomic<int> lists{0};  ///< state lists read
  ImpostorProcess process;
};

// Attack 1 of the review: a fake Control on a dead robot's old port, announced by the robot's
// replayed heartbeats, forwards the console's nonce to the live robot and returns its genuine
// signed answer. Whatever certificate of the system's CA the impostor holds (the tools' reader,
// another member's, even the robot's own), the console sends it nothing: the connection must be
// the coordinator's own (its certificate names it), and the proof must be of the process that
// serves the endpoint asked (a relayed proof names the live robot's endpoint).
TEST(Wire, ARelayedProofGetsNoTokenWhateverCertificateTheRelayHolds) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beating.store(false);  // the robot's last heartbeats are what the attacker replays
  for (const char* certificate : {"reader", "wire-c", "wire-p"}) {
    SCOPED_TRACE(certificate);
    std::shared_ptr<Ice::Communicator> relay_ic;
    ImpostorProcess fake(
        bus.keys, certificate,
        [&](const std::string& operation,
            std::pair<const Ice::Byte*, const Ice::Byte*> in) -> std::optional<std::vector<Ice::Byte>> {
          if (operation != "prove") return std::nullopt;
          // The relay: the console's own nonce, answered by the live robot.
          auto live = Ice::uncheckedCast<wire::AlivePrx>(relay_ic->stringToProxy(bus.alive_proxy));
          return out_params(relay_ic, live->prove(in_param<Ice::ByteSeq>(relay_ic, in)));
        });
    relay_ic = fake.ice.communicator();
    std::atomic<bool> replaying{true};
    std::thread replayer([&] {
      while (replaying.load()) {
        bus.beat(*bus.provider, "wire-p", kIncarnation, fake.proxy);  // genuine, naming the old endpoint
        std::this_thread::sleep_for(50ms);
      }
    });
    middleware::ClientOptions o;
    o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
    o.coordinator = "wire-p";
    o.token = std::string(64, 'a');
    o.read_token = std::string(64, 'b');
    o.keys_dir = bus.keys;
    o.timeout = 1000ms;
    auto lured = middleware::RemoteClient::connect(o);
    replaying.store(false);
    replayer.join();
    ASSERT_FALSE(lured) << "the console believed a relayed proof";
    const std::string why = lured.error().message;
    if (std::string(certificate) == "wire-p") {
      EXPECT_NE(why.find("(relayed)"), std::string::npos) << why;
    } else {
      EXPECT_NE(why.find("not of 'wire-p'"), std::string::npos) << why;
    }
    // Nothing but the proof question ever reached it: no read, no context, no token.
    for (const std::string& op : fake.servant->seen()) EXPECT_EQ(op, "prove") << why;
  }
}

// Attack 2 of the review: a member (here wire-c, with its own key and certificate) announces a
// Control of its own that lists wire-p's components as Normal, and heartbeats listing records
// ahead, so that the supervisor reads that list to refresh its view. The supervisor applies the
// rule every live update gets: a member speaks only for its own components.
TEST(Wire, AMemberCannotSpeakForAnotherMembersComponentsThroughTheSupervisorsRefresh) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;
  auto ic = bus.ice.communicator();
  // The truth: wire-p's P.s_A goes to Error (a genuine transition record).
  wire::EventMessage m{};
  m.coordinator = "wire-p";
  m.incarnation = kIncarnation;
  m.seq = 1;
  m.record.kind = wire::RecordKind::Transition;
  m.record.machine = "P.s_A";
  m.record.component = "P";
  m.record.event = "EVT_E";
  m.record.from = wire::Level::Normal;
  m.record.to = wire::Level::Error;
  m.record.level = wire::Level::Error;
  auto events = Ice::uncheckedCast<wire::EventTopicPrx>(bus.topic("safecass.events")->getPublisher()->ice_oneway());
  events->records(bus.provider->seal(middleware::kKindEvents, encode(ic, wire::EventMessageSeq{m})));
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_A") == State::Error; })) << out.all();

  // wire-c restarted (a new incarnation it proves with its own key), serving its own Control.
  RestartedMember member(bus,
                         [&](const std::string& operation,
                             std::pair<const Ice::Byte*, const Ice::Byte*>) -> std::optional<std::vector<Ice::Byte>> {
                           if (operation == "stateList") {
                             return out_params(
                                 ic, wire::StateEntrySeq{{"P", "component", wire::Level::Normal, ""},
                                                         {"P.s_A", "application", wire::Level::Normal, ""},
                                                         {"C.s_A", "application", wire::Level::Warning, "EVT_W"}});
                           }
                           if (operation == "explain") return out_params(ic, wire::ExplainReply{});
                           return std::nullopt;
                         });
  member.beat_until_read();
  ASSERT_GE(member.lists.load(), 1) << "the supervisor read the member's list\n" << out.all();
  // What wire-c says of its own component is taken; of wire-p's, nothing.
  EXPECT_TRUE(eventually([&] { return view_state(sup, "C.s_A") == State::Warning; })) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_A"), State::Error) << out.all();
  EXPECT_EQ(out.all().find("[wire-c] P.s_A"), std::string::npos) << out.all();
  EXPECT_EQ(out.all().find("[wire-c] P Normal"), std::string::npos) << out.all();
  supervisor->stop();
}

// The supervisor reads a member's view again after missed records: its state list, then an
// explanation of each row not Normal. A row can change between the two requests (the member's
// losses clear as it proves its peers alive): the row takes the state the explanation gives with
// the causes it gives, never a state from one answer with the causes of another (an Error with no
// cause). An explanation of another address changes nothing.
TEST(Wire, TheSupervisorsRefreshTakesEachRowsStateFromTheExplanationItTakesTheCausesFrom) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;
  auto ic = bus.ice.communicator();
  wire::ExplainEntry warning{};
  warning.machine = "C.s_F";
  warning.event = "EVT_W";
  warning.outstanding = true;
  warning.root.event = "EVT_W";
  warning.root.origin = "C.s_F";
  warning.root.level = wire::Level::Warning;
  RestartedMember member(
      bus,
      [&](const std::string& operation,
          std::pair<const Ice::Byte*, const Ice::Byte*> in) -> std::optional<std::vector<Ice::Byte>> {
        if (operation == "stateList") {
          return out_params(ic, wire::StateEntrySeq{{"C.s_A", "application", wire::Level::Error, ""},
                                                    {"C.s_F", "framework", wire::Level::Error, ""},
                                                    {"C.s_R.D0", "required", wire::Level::Error, ""}});
        }
        if (operation == "explain") {
          const auto address = in_param<std::string>(ic, in);
          if (address == "C.s_A") return out_params(ic, wire::ExplainReply{address, wire::Level::Normal, {}});
          if (address == "C.s_F") return out_params(ic, wire::ExplainReply{address, wire::Level::Warning, {warning}});
          return out_params(ic, wire::ExplainReply{"C.s_A", wire::Level::Normal, {}});  // not about the row asked
        }
        return std::nullopt;
      });
  member.beat_until_read();
  ASSERT_GE(member.lists.load(), 1) << "the supervisor read the member's list\n" << out.all();
  // Cleared between the reads: not shown in Error.
  EXPECT_TRUE(eventually([&] { return view_state(sup, "C.s_F") == State::Warning; })) << out.all();
  EXPECT_NE(view_state(sup, "C.s_A"), State::Error) << out.all();
  EXPECT_EQ(out.all().find("[wire-c] C.s_A Error"), std::string::npos) << out.all();
  // Eased between the reads: the explanation's state, with its cause.
  EXPECT_NE(out.all().find("[wire-c] C.s_F Warning (refreshed after missed records; root C.s_F:EVT_W)"),
            std::string::npos)
      << out.all();
  // An answer about another address: the list's state stands.
  EXPECT_EQ(view_state(sup, "C.s_R.D0"), State::Error) << out.all();
  supervisor->stop();
}

/// Attacks 3 and 4 of the review: a thief unsubscribes each subscription to `topic` whose
/// identity `whose` selects and subscribes an endpoint of its own under the same identity, at the
/// broker its certificate reaches (a tool's, the reader's: the tools' broker; a member's: the
/// members'). Returns the identities it took.
std::vector<Ice::Identity> take_subscriptions(Bus& bus, ImpostorProcess& thief, const std::string& topic,
                                              const std::function<bool(const Ice::Identity&)>& whose) {
  const auto broker = thief.certificate == "reader" ? fixture::Broker::Tools : fixture::Broker::Members;
  auto manager =
      Ice::uncheckedCast<IceStorm::TopicManagerPrx>(thief.ice->stringToProxy(fixture::topic_manager(bus.port, broker)));
  auto t = manager->retrieve(topic);
  std::vector<Ice::Identity> taken;
  for (const Ice::Identity& id : t->getSubscribers()) {
    if (!whose(id)) continue;
    t->unsubscribe(thief.ice->stringToProxy(Ice::identityToString(id)));
    t->subscribeAndGetPublisher(IceStorm::QoS{}, thief.adapter->add(thief.servant, id)->ice_oneway());
    taken.push_back(id);
  }
  return taken;
}
/// The subscriptions of a process whose subscriber categories start with `prefix`.
std::function<bool(const Ice::Identity&)> of(const std::string& prefix) {
  return [prefix](const Ice::Identity& id) { return id.category.starts_with(prefix); };
}
/// A thief's endpoint: takes every message it is sent and answers nothing.
const Relay::Answer kKeepsEverything =
    [](const std::string&, std::pair<const Ice::Byte*, const Ice::Byte*>) -> std::optional<std::vector<Ice::Byte>> {
  return std::vector<Ice::Byte>{};
};

// Attack 3 of the review: a coordinator's subscriber identity on its provider's state topic is
// taken (by a member now: a tool's certificate no longer reaches the members' broker). The client hears the provider's
// heartbeats but not its state: when the provider goes to Error, the client is at Error within the loss bound (the
// stream is lost), never at a stale Normal; it then subscribes under a new identity and holds the provider's true
// state.
TEST(Wire, AReceiverWhoseSubscriberIdentityIsTakenIsLostWithinTheBoundAndRecoversUnderANewIdentity) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.send(*bus.provider, {update("P.D0", 1, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return bus.node->stats().updates_applied >= 1; })) << bus.all_log();
  ImpostorProcess thief(bus.keys, "wire-p", kKeepsEverything);  // a member: tools cannot reach these topics
  ASSERT_GE(take_subscriptions(bus, thief, "safecass.state.wire-p", of("safecass-wire-c-")).size(), 1u);

  // The truth: wire-p's D0 fails. The victim must not stay at Normal past the bound.
  const auto sent = std::chrono::steady_clock::now();
  bus.send(*bus.provider, {update("P.D0", 2, "EVT_E", wire::Level::Error)});
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_R.D0") == State::Error; }, 3000ms)) << bus.all_log();
  const auto in_error = std::chrono::steady_clock::now() - sent;
  EXPECT_LT(in_error, 1000ms) << "the loss bound is 300 ms\n" << bus.all_log();
  std::printf("the victim is at Error %.0f ms after the provider's fault\n",
              std::chrono::duration<double, std::milli>(in_error).count());
  EXPECT_TRUE(eventually([&] { return !thief.servant->seen().empty(); })) << "the takeover held";

  // A new identity: what the provider sends next (its republish) reaches the victim again.
  ASSERT_TRUE(eventually([&] { return bus.all_log().find("under a new identity") != std::string::npos; }, 3000ms))
      << bus.all_log();
  // As a coordinator answers the victim's requests: republished once a period until it holds the
  // state again (under load the first one can come before the new subscription delivers).
  std::int64_t republished = 2;
  EXPECT_TRUE(eventually(
      [&] {
        bus.send(*bus.provider, {update("P.D0", ++republished, "EVT_E", wire::Level::Error)});
        return eventually([&] { return bus.state("C.s_R.D1") == State::Normal; }, 100ms);
      },
      3000ms))
      << bus.all_log();
  EXPECT_EQ(bus.state("C.s_R.D0"), State::Error);
  EXPECT_TRUE(bus.explains("C.s_R.D0", "EVT_E"));
  EXPECT_FALSE(bus.explains("C.s_R.D0", "EVT_COORDINATOR_LOST"));
}

// Attack 4 of the review: the same takeover against the supervisor, which follows records. Its
// state stream is lost when heartbeats show it behind, whether or not records are followed: no
// service row stays Normal beside the truth.
TEST(Wire, ASupervisorFollowingRecordsCountsAStateStreamBehindAsLost) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  const middleware::Supervisor& sup = *supervisor;
  bus.send(*bus.provider, {update("P.D0", 1, "", wire::Level::Normal)});
  ASSERT_TRUE(eventually([&] { return view_state(sup, "P.s_S.D0") == State::Normal; })) << out.all();
  // wire-p proven alive and caught up first: the attack is on a stream the supervisor believes. (A
  // supervisor that has not yet proven wire-p holds it lost from its start, and so sees no loss
  // begin, the trigger of its new identities: docs/security.md, "Subscriptions".)
  ASSERT_TRUE(eventually([&] { return sup.lost().empty(); })) << out.all();
  ImpostorProcess thief(bus.keys, "wire-p", kKeepsEverything);  // a member: tools cannot reach these topics
  ASSERT_GE(take_subscriptions(bus, thief, "safecass.state.wire-p", of("safecass-supervisor-")).size(), 1u);

  bus.send(*bus.provider, {update("P.D0", 2, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return sup.lost() == std::vector<std::string>{"wire-p"}; }, 2000ms)) << out.all();
  EXPECT_NE(out.all().find("its heartbeats list state of P.D0 not received"), std::string::npos) << out.all();
  EXPECT_EQ(sup.model().state(*sup.model().structure().find_machine("P.s_F")), State::Error) << out.all();

  ASSERT_TRUE(eventually([&] { return out.all().find("under a new identity") != std::string::npos; }, 3000ms))
      << out.all();
  bus.send(*bus.provider, {update("P.D0", 3, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return sup.lost().empty(); }, 3000ms)) << out.all();
  EXPECT_EQ(view_state(sup, "P.s_S.D0"), State::Error) << out.all();
  supervisor->stop();
}

// A process that has just started shows nothing it has not been told: until a provider is proven
// alive and what it lists as sent is received, the interfaces it feeds are at Error.
TEST(Wire, ANewcomerHoldsTheInterfacesOfAProviderNotYetProvenAliveAtError) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.node->stop();
  bus.node.reset();
  bus.proving.store(false);  // wire-p cannot prove itself (yet)
  const auto node = bus.start_node();
  ASSERT_TRUE(node);
  // At once, not after a loss bound.
  for (const char* r : {"C.s_R.D0", "C.s_R.D1", "C.s_R.D2", "C.s_R.D3"}) {
    EXPECT_EQ(bus.state(r), State::Error) << r;
    EXPECT_TRUE(bus.explains(r, "EVT_COORDINATOR_LOST")) << r;
  }
  EXPECT_NE(bus.all_log().find("coordinator 'wire-p' not proven alive yet (this node just started)"), std::string::npos)
      << bus.all_log();
  std::this_thread::sleep_for(500ms);  // heartbeats come, but no proof: still Error
  EXPECT_EQ(bus.state("C.s_R.D1"), State::Error) << bus.all_log();
  bus.proving.store(true);
  const auto proving = std::chrono::steady_clock::now();
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; })) << bus.all_log();
  std::printf("Normal %.0f ms after the provider can prove itself\n",
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - proving).count());
  EXPECT_FALSE(bus.explains("C.s_R.D1", "EVT_COORDINATOR_LOST"));
  node->stop();
}

// A newcomer holds its providers lost from its start, so no loss begins for them and no loss
// renews their subscriptions. A member that takes the newcomer's subscriptions in that window
// (here while wire-p is still silent) would keep wire-p at Error there for as long as it holds
// them: fail-safe, but never live again. A round on, each receiver still holding wire-p lost
// subscribes again under new identities, hears wire-p and believes it once it proves itself
// (verify --bus, class unsubscribed: the member takes a subscription of a receiver that has just
// started). wire-p is silent until the theft, so that no heartbeat heard before it starts a proof.
TEST(Wire, ANewcomerWhoseSubscriptionsAreTakenBeforeItsProviderIsProvenRenewsThemARoundLaterAndBelievesIt) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.silence();  // wire-p is silent yet: both receivers stay newcomers, and ask for no proof
  bus.node->stop();
  bus.node.reset();
  // The stopped node's subscriptions stay at IceStorm until it drops them as undeliverable: the
  // newcomers' are those made from now on.
  std::vector<Ice::Identity> before;
  for (const char* topic : {"safecass.heartbeat.wire-p", "safecass.state.wire-p"}) {
    const std::vector<Ice::Identity> ids = bus.subscribers(topic);
    before.insert(before.end(), ids.begin(), ids.end());
  }
  const auto newcomer = [&](const char* victim) {
    return [&before, victim](const Ice::Identity& id) {
      return of(victim)(id) && std::find(before.begin(), before.end(), id) == before.end();
    };
  };
  const auto node = bus.start_node();
  ASSERT_TRUE(node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out, "coordinator 'wire-p' not proven alive yet");
  ASSERT_TRUE(supervisor);
  ImpostorProcess thief(bus.keys, "wire-p", kKeepsEverything);  // a member: tools cannot reach these topics
  std::vector<Ice::Identity> taken;
  for (const char* victim : {"safecass-wire-c-", "safecass-supervisor-"}) {
    for (const char* topic : {"safecass.heartbeat.wire-p", "safecass.state.wire-p"}) {
      // Once the victim's subscription is there: it subscribes as it connects.
      std::vector<Ice::Identity> got;
      ASSERT_TRUE(eventually([&] { return !(got = take_subscriptions(bus, thief, topic, newcomer(victim))).empty(); }))
          << victim << " on " << topic;
      taken.insert(taken.end(), got.begin(), got.end());
    }
  }
  bus.beating.store(true);
  const auto beating = std::chrono::steady_clock::now();
  // A round (1 s) after each receiver's start, then the proof: both believe wire-p.
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_R.D1") == State::Normal; }, 5000ms)) << bus.all_log();
  EXPECT_TRUE(eventually([&] { return supervisor->lost().empty(); }, 5000ms)) << out.all();
  std::printf("both believe wire-p %.0f ms after it beats\n",
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - beating).count());
  EXPECT_NE(bus.all_log().find("coordinator 'wire-p' still lost a subscription round on"), std::string::npos)
      << bus.all_log();
  EXPECT_NE(out.all().find("coordinator 'wire-p' still lost a subscription round on"), std::string::npos) << out.all();
  EXPECT_TRUE(eventually([&] { return !thief.servant->seen().empty(); })) << "the takeover held";
  // Each receiver is subscribed to both topics under an identity the member did not take.
  for (const char* victim : {"safecass-wire-c-", "safecass-supervisor-"}) {
    for (const char* topic : {"safecass.heartbeat.wire-p", "safecass.state.wire-p"}) {
      const std::vector<Ice::Identity> now = bus.subscribers(topic);
      EXPECT_TRUE(std::any_of(now.begin(), now.end(),
                              [&](const Ice::Identity& id) {
                                return of(victim)(id) && std::find(taken.begin(), taken.end(), id) == taken.end();
                              }))
          << victim << " on " << topic;
    }
  }
  supervisor->stop();
  node->stop();
}

// Two supervisors may watch one system: the second is reported, and when the one the
// coordinators believe exits, they believe the other within a loss bound, instead of staying in
// Warning (EVT_SUPERVISOR_LOST) until one is restarted.
TEST(Wire, WhenEitherOfTwoSupervisorsExitsTheCoordinatorsBelieveTheOther) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  bus.beating.store(true);
  SupervisorOutput first_out;
  auto first = start_supervisor(bus, first_out);
  ASSERT_TRUE(first);
  SupervisorOutput second_out;
  auto second = start_supervisor(bus, second_out);
  ASSERT_TRUE(second);
  EXPECT_TRUE(eventually([&] {
    return (first_out.all() + second_out.all()).find("another supervisor runs on this bus") != std::string::npos;
  })) << first_out.all();
  // While both run (an observation window: nothing is to happen in it), nobody is in Warning.
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(bus.state("C.s_F"), State::Normal) << bus.all_log();

  // The newer one exits: the coordinator loses it, then comes back to the first.
  second->stop();
  second.reset();
  const auto said = [&](const char* line) { return bus.all_log().find(line) != std::string::npos; };
  EXPECT_TRUE(eventually([&] { return said("the supervisor is gone"); }, 3000ms)) << bus.all_log();
  EXPECT_TRUE(eventually([&] { return said("the supervisor is back") && bus.state("C.s_F") == State::Normal; }, 3000ms))
      << bus.all_log();
  // The first exits too: nothing is left to believe, and the coordinator says so.
  first->stop();
  EXPECT_TRUE(eventually([&] { return bus.state("C.s_F") == State::Warning; }, 2000ms)) << bus.all_log();
}

// The same takeover against a coordinator's subscription to the supervisor's heartbeats: the
// coordinator warns (EVT_SUPERVISOR_LOST) within the loss bound, never keeps a supervisor it no
// longer hears, and believes it again under a new identity.
TEST(Wire, ACoordinatorWhoseSupervisorSubscriptionIsTakenWarnsAndRecoversUnderANewIdentity) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  SupervisorOutput out;
  auto supervisor = start_supervisor(bus, out);
  ASSERT_TRUE(supervisor);
  ASSERT_TRUE(eventually([&] { return bus.state("C.s_F") == State::Normal; }, 3000ms)) << bus.all_log();
  ImpostorProcess thief(bus.keys, "wire-p", kKeepsEverything);  // a member: tools cannot reach these topics
  ASSERT_GE(take_subscriptions(bus, thief, "safecass.heartbeat.supervisor", of("safecass-wire-c-")).size(), 1u);
  const auto said = [&](const char* line) { return bus.all_log().find(line) != std::string::npos; };
  EXPECT_TRUE(eventually([&] { return said("the supervisor is gone"); }, 3000ms)) << bus.all_log();
  EXPECT_TRUE(eventually([&] { return said("under a new identity"); }, 3000ms)) << bus.all_log();
  EXPECT_TRUE(eventually([&] { return said("the supervisor is back") && bus.state("C.s_F") == State::Normal; }, 3000ms))
      << bus.all_log();
  supervisor->stop();
}

/// A RemoteClient of wire-c following its records into `shown` (event and text of each).
struct WireFollower {
  std::unique_ptr<middleware::RemoteClient> client;
  std::unique_ptr<introspect::Subscription> subscription;
  std::mutex mutex;
  std::vector<std::string> shown;
  std::vector<std::uint64_t> seqs;

  explicit WireFollower(Bus& bus) {
    middleware::ClientOptions o;
    o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
    o.coordinator = "wire-c";
    o.keys_dir = bus.keys;
    o.timeout = 3000ms;
    auto c = middleware::RemoteClient::connect(o);
    EXPECT_TRUE(c) << (c ? "" : c.error().message);
    if (!c) return;
    client = std::move(*c);
    auto f = client->follow([this](const introspect::HistoryEntry& e) {
      std::lock_guard lock(mutex);
      shown.push_back(e.event + " " + e.text);
      seqs.push_back(e.seq);
    });
    EXPECT_TRUE(f) << (f ? "" : f.error().message);
    if (f) subscription = std::move(*f);
  }
  bool shows(const std::string& text) {
    std::lock_guard lock(mutex);
    return std::any_of(shown.begin(), shown.end(),
                       [&](const std::string& s) { return s.find(text) != std::string::npos; });
  }
  /// wire-c resets C with `text`, and the follower shows it: it is following.
  bool shows_reset(Bus& bus, const std::string& text) {
    return reset(bus.co, "C", "operator", text).has_value() && eventually([&] { return shows(text); });
  }
  /// The follower is past its first heartbeat's read of the history: a reset reaches it from the
  /// batch that carried it, not from that read. The read goes on until an answer brings nothing
  /// new, so a record written while it runs (one the test has just seen shown) is read there.
  bool settled(Bus& bus) {
    for (int k = 0; k < 10; ++k) {
      const std::uint64_t read = client->records_read();
      if (!shows_reset(bus, "settle " + std::to_string(k))) return false;
      if (client->records_read() == read) return true;
    }
    return false;
  }
};

// Records travel once: a follower holds only the keyring, and takes each record from the batch
// that carried it once a heartbeat signed with the coordinator's key lists the batch's digest; it
// reads the coordinator's history only for what it did not receive.
TEST(Wire, AFollowerTakesEachRecordFromTheBatchAHeartbeatVouchesForAndReadsNoHistory) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  ASSERT_TRUE(follower.shows_reset(bus, "first")) << "the follower is following";
  ASSERT_TRUE(follower.settled(bus)) << "a record came in the batch that carried it";
  const std::uint64_t read = follower.client->records_read();
  const std::uint64_t gaps = follower.client->gaps_filled();
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(reset(bus.co, "C", "operator", "round " + std::to_string(k)).has_value());
  ASSERT_TRUE(eventually([&] { return follower.shows("round 9"); })) << "every record arrives";
  {
    std::lock_guard lock(follower.mutex);
    std::vector<std::string> rounds;
    for (const std::string& line : follower.shown) {
      // A reset writes a record per machine of C, each with its text.
      const auto at = line.find("round ");
      if (at != std::string::npos && (rounds.empty() || rounds.back() != line.substr(at)))
        rounds.push_back(line.substr(at));
    }
    std::vector<std::string> want;
    want.reserve(10);
    for (int k = 0; k < 10; ++k) want.push_back("round " + std::to_string(k));
    EXPECT_EQ(rounds, want) << "in order";
    EXPECT_TRUE(std::is_sorted(follower.seqs.begin(), follower.seqs.end()) &&
                std::adjacent_find(follower.seqs.begin(), follower.seqs.end()) == follower.seqs.end())
        << "each record once, in order";
  }
  EXPECT_EQ(follower.client->records_read(), read) << "each record came in the message that carried it";
  EXPECT_EQ(follower.client->gaps_filled(), gaps);
}

// A follower that starts listening just after a batch was sent hears its first heartbeats list
// that batch (a heartbeat lists two periods) and never receives it: its records were in the
// history read at the first heartbeat, so it awaits nothing and counts no gap.
TEST(Wire, AFollowerAwaitsNoBatchSentBeforeItListenedAndCountsNoGapForIt) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  ImpostorProcess tap(bus.keys, "reader", kKeepsEverything);  // counts wire-c's heartbeats
  const auto topic = bus.topic("safecass.heartbeat.wire-c");
  const auto tapped = tap.ice->stringToProxy(tap.proxy)->ice_oneway();
  topic->subscribeAndGetPublisher(IceStorm::QoS{}, tapped);
  const std::shared_ptr<void> untap(nullptr, [&](void*) { topic->unsubscribe(tapped); });
  const auto beats = [&] {
    const std::vector<std::string> seen = tap.servant->seen();
    return std::count(seen.begin(), seen.end(), "beat");
  };
  ASSERT_TRUE(reset(bus.co, "C", "operator", "before").has_value());
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  const auto joined = beats();
  ASSERT_TRUE(eventually([&] { return beats() >= joined + 4; })) << "wire-c's heartbeats go on";
  // Vouched for by a heartbeat sent after those four: the follower has taken them all.
  ASSERT_TRUE(follower.shows_reset(bus, "after"));
  EXPECT_EQ(follower.client->gaps_filled(), 0u);
  EXPECT_FALSE(follower.shows("before")) << "recorded before the follower started";
}

// A batch that claims a coordinator is believed only when that coordinator's signed heartbeat
// vouches for it: a member's batch in wire-c's name, with wire-c's incarnation and the next
// numbers (which a follower cannot tell from wire-c's own, its seal's tags being for members
// only), is never shown.
TEST(Wire, ABatchNoHeartbeatOfItsCoordinatorVouchesForIsNeverShown) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  // A tool taps the events topic for one genuine record of wire-c (its incarnation and numbers).
  std::mutex mutex;
  std::optional<wire::EventMessage> genuine;
  std::shared_ptr<Ice::Communicator> tap_ic;
  ImpostorProcess tap(
      bus.keys, "reader",
      [&](const std::string& operation,
          std::pair<const Ice::Byte*, const Ice::Byte*> in) -> std::optional<std::vector<Ice::Byte>> {
        if (operation != "records") return std::vector<Ice::Byte>{};
        const auto batch = in_param<wire::Signed>(tap_ic, in);
        wire::EventMessageSeq messages;
        if (batch.signer == "wire-c" && middleware::decode(tap_ic, batch.body, messages) && !messages.empty()) {
          std::lock_guard lock(mutex);
          genuine = messages.back();
        }
        return std::vector<Ice::Byte>{};
      });
  tap_ic = tap.ice.communicator();
  bus.topic("safecass.events")
      ->subscribeAndGetPublisher(IceStorm::QoS{}, tap.ice->stringToProxy(tap.proxy)->ice_oneway());
  ASSERT_TRUE(reset(bus.co, "C", "operator", "genuine").has_value());
  ASSERT_TRUE(eventually([&] { return follower.shows("genuine"); }));
  ASSERT_TRUE(eventually([&] {
    std::lock_guard lock(mutex);
    return genuine.has_value();
  }));
  wire::EventMessage forged = *genuine;
  forged.seq += 1;
  forged.record.seq += 100;
  forged.record.text = "operator: FORGED";
  const std::uint64_t refused = follower.client->records_refused();
  wire::Signed batch =
      bus.provider->seal(middleware::kKindEvents, encode(bus.ice.communicator(), wire::EventMessageSeq{forged}));
  batch.signer = "wire-c";  // in wire-c's name, with wire-p's tags: only members could tell
  Ice::uncheckedCast<wire::EventTopicPrx>(bus.topic("safecass.events")->getPublisher()->ice_twoway())->records(batch);
  EXPECT_TRUE(eventually([&] { return follower.client->records_refused() > refused; }, 3000ms))
      << "dropped once no heartbeat vouched for it";
  // What wire-c really records is still shown, the forgery never.
  ASSERT_TRUE(reset(bus.co, "C", "operator", "after").has_value());
  ASSERT_TRUE(eventually([&] { return follower.shows("after"); }));
  EXPECT_FALSE(follower.shows("FORGED"));
}

/// A tool (`thief`) takes the subscriptions of wire-c's followers to its heartbeats (the nodes'
/// identities have a category, a follower's none); the identities it took.
std::vector<Ice::Identity> take_followers_beats(Bus& bus, ImpostorProcess& thief) {
  return take_subscriptions(bus, thief, "safecass.heartbeat.wire-c", of(std::string(middleware::kFollowerCategory)));
}

// Every gap fails toward completeness: a follower whose records stop coming (its subscription to
// the events topic taken) while the coordinator's heartbeats go on listing what it sent reads
// those records from the coordinator's history, at once and without being asked (EventStream: what
// the heartbeat two before listed and has not come is missed), in order and once each.
TEST(Wire, AFollowerReadsFromTheHistoryTheRecordsItsHeartbeatsListAndThatNeverCame) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  ASSERT_TRUE(follower.shows_reset(bus, "before"));
  const std::uint64_t read = follower.client->records_read();
  const std::uint64_t gaps = follower.client->gaps_filled();
  ImpostorProcess thief(bus.keys, "reader", kKeepsEverything);
  ASSERT_EQ(take_subscriptions(bus, thief, "safecass.events", of(std::string(middleware::kFollowerCategory))).size(),
            1u);
  ASSERT_TRUE(reset(bus.co, "C", "operator", "never came").has_value());
  EXPECT_TRUE(eventually([&] { return follower.shows("never came"); }, 3000ms)) << "read from the history";
  EXPECT_TRUE(eventually([&] { return !thief.servant->seen().empty(); })) << "the stream went to the thief";
  EXPECT_GT(follower.client->records_read(), read);
  EXPECT_GT(follower.client->gaps_filled(), gaps);
  std::lock_guard lock(follower.mutex);
  EXPECT_TRUE(std::is_sorted(follower.seqs.begin(), follower.seqs.end()) &&
              std::adjacent_find(follower.seqs.begin(), follower.seqs.end()) == follower.seqs.end())
      << "each record once, in order";
}

// A tool's own subscriptions are not kept from it: a follower that hears no heartbeat of the
// process it follows for a second subscribes again under new identities when it catches up (the
// viewer does after every 0.5 s of quiet), and takes records from the stream again.
TEST(Wire, AFollowerWhoseHeartbeatSubscriptionIsTakenSubscribesAgainWhenItCatchesUp) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  ASSERT_TRUE(follower.shows_reset(bus, "before"));
  ImpostorProcess thief(bus.keys, "reader", kKeepsEverything);
  const std::vector<Ice::Identity> taken = take_followers_beats(bus, thief);
  ASSERT_EQ(taken.size(), 1u);
  ASSERT_TRUE(reset(bus.co, "C", "operator", "while taken").has_value());
  // Catching up shows what the stream could not vouch for, and after a second of silence the
  // follower subscribes under a new identity (unsubscribing its old one, which the thief held).
  const auto subscribed_anew = [&] {
    for (const Ice::Identity& id : bus.subscribers("safecass.heartbeat.wire-c", fixture::Broker::Tools))
      if (id.category.starts_with(middleware::kFollowerCategory) && id != taken[0]) return true;
    return false;
  };
  ASSERT_TRUE(eventually(
      [&] {
        EXPECT_TRUE(follower.subscription->catch_up());
        return follower.shows("while taken") && subscribed_anew();
      },
      5000ms))
      << "shown: " << follower.shows("while taken");
  const std::uint64_t read = follower.client->records_read();
  ASSERT_TRUE(reset(bus.co, "C", "operator", "after").has_value());
  ASSERT_TRUE(eventually([&] { return follower.shows("after"); }));
  EXPECT_EQ(follower.client->records_read(), read) << "from the stream again, vouched for by a heartbeat";
}

// Batches held for a voucher are bounded in number and bytes: a flood of large batches in a
// coordinator's name that no heartbeat lists (here the follower hears no heartbeat at all: a tool
// took its subscription) does not grow a follower's memory with the flood.
TEST(Wire, AFloodOfBatchesNoHeartbeatVouchesForDoesNotGrowAFollowersMemory) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  WireFollower follower(bus);
  ASSERT_TRUE(follower.subscription);
  ASSERT_TRUE(follower.shows_reset(bus, "before"));
  // A tool takes the follower's subscription to wire-c's heartbeats.
  ImpostorProcess thief(bus.keys, "reader", kKeepsEverything);
  ASSERT_EQ(take_followers_beats(bus, thief).size(), 1u);
  wire::EventMessage big{};
  big.coordinator = "wire-c";
  big.seq = 1;
  big.record.kind = wire::RecordKind::Reset;
  big.record.component = "C";
  big.record.text = std::string(std::size_t{256} << 10, 'x');
  // The tool floods at the tools' broker, where the follower listens (a member's flood would
  // cross the link from the members' broker, which IceStorm may drop under load: that is not what
  // this test measures).
  auto tools = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(
      thief.ice->stringToProxy(fixture::topic_manager(bus.port, fixture::Broker::Tools)));
  auto events = Ice::uncheckedCast<wire::EventTopicPrx>(
      middleware::topic(tools, "safecass.events")->getPublisher()->ice_twoway());
  const long rss_before = rss_kib();
  const std::uint64_t refused = follower.client->records_refused();
  constexpr int kBatches = 400;  // 100 MiB in all
  for (int i = 0; i < kBatches; ++i) {
    big.seq = 1000 + i;
    wire::Signed batch =
        bus.provider->seal(middleware::kKindEvents, encode(bus.ice.communicator(), wire::EventMessageSeq{big}));
    batch.signer = "wire-c";
    events->records(batch);
  }
  // Each batch is either held or dropped for one held longer: at most 8 MiB stay.
  EXPECT_TRUE(eventually([&] { return follower.client->records_refused() >= refused + kBatches - 40; }, 10000ms))
      << follower.client->records_refused() - refused;
  const long grown = rss_kib() - rss_before;
  std::printf("[flood] %d batches of 256 KiB to a follower: RSS %+ld KiB\n", kBatches, grown);
  EXPECT_LT(grown, 48L * 1024L) << "memory does not grow with the flood (100 MiB sent)";
  EXPECT_FALSE(follower.shows("xxxx"));
}

// Every private key the system makes is refused when others can read it: a member's TLS key and
// the tools' reader key, as a member's secret already was.
TEST(Wire, APrivateKeyOthersCanReadIsRefused) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus;
  ASSERT_TRUE(bus.node);
  const std::string copy = bus.scratch + "/wire-open-keys";
  std::filesystem::remove_all(copy);
  std::filesystem::copy(bus.keys, copy);
  std::filesystem::permissions(copy + "/reader.key", std::filesystem::perms::others_read,
                               std::filesystem::perm_options::add);
  middleware::ClientOptions o;
  o.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + bus.port);
  o.coordinator = "wire-c";
  o.keys_dir = copy;
  auto console = middleware::RemoteClient::connect(o);
  ASSERT_FALSE(console);
  EXPECT_EQ(console.error().code, ErrorCode::Denied);
  EXPECT_NE(console.error().message.find("reader.key: a private key must be owned by its user and have mode 0600"),
            std::string::npos)
      << console.error().message;

  std::filesystem::permissions(copy + "/wire-c.key", std::filesystem::perms::group_read,
                               std::filesystem::perm_options::add);
  middleware::NodeOptions options;
  options.ice = o.ice;
  options.keys_dir = copy;
  auto node =
      middleware::CoordinatorNode::create(bus.co, *bus.monitor, bus.registry, *bus.load.system, "wire-c", options);
  ASSERT_FALSE(node);
  EXPECT_NE(node.error().message.find("wire-c.key: a private key must be owned by its user and have mode 0600"),
            std::string::npos)
      << node.error().message;
}

}  // namespace
}  // namespace safecass
