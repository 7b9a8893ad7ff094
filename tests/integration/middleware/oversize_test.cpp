// Messages too large for one Ice message (DESIGN §7 "say what was lost", §4 "fail toward safe"):
// a provider node with a small NodeOptions::max_message_bytes against the fixture's IceStorm, a
// real client node, and taps on the provider's topics that see every body it sends.
// - a state update whose roots do not fit goes out with the roots that fit, the most severe first:
//   the client ends in Error (never better than the provider), and the cut is logged with the
//   interface, the size, the limit and the roots left out, and counted;
// - a batch of updates that does not fit is split, and every update arrives whole;
// - an event record whose text does not fit goes out with its text cut (logged with its size),
//   and a batch of records that does not fit is split without losing or reordering one.
//
// Environment (set by tests/integration/middleware/CMakeLists.txt):
//   SAFECASS_ICESTORM_ENV    file written by the fixture's scripts/start-icestorm --env
//   SAFECASS_SCRATCH         a directory for key files

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Ice/Ice.h>
#include <IceStorm/IceStorm.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "auth.hpp"
#include "fixture.hpp"
#include "receiver.hpp"
#include "safecass.h"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/spec/load.hpp"

namespace safecass {
namespace {

using namespace std::chrono_literals;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;

constexpr std::size_t kLimit = 4096;

std::string fixture_port() {
  const char* file = std::getenv("SAFECASS_ICESTORM_ENV");
  std::ifstream in(file != nullptr ? file : "");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ICESTORM_PORT=", 0) == 0) return line.substr(14);
  }
  return "";
}

bool eventually(const std::function<bool()>& ok, std::chrono::milliseconds timeout = 10000ms) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (ok()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return ok();
}

/// A long event name: roots of these make an interface's state large (`n` is its number).
std::string long_event(const std::string& kind, int n, std::size_t length = 150) {
  return "EVT_" + kind + "_" + std::string(length, kind[0]) + "_" + std::to_string(n);
}

/// P (coordinator "over-p", the node under test) provides D, whose service depends on s_A (and
/// passes warnings on to its clients), and
/// E0..E7, each depending on its own s_P.Ei alone; C ("over-c") requires them all. P has
/// `warnings` Warning and `errors` Error events with long names.
std::string system_text(int warnings, int errors, std::size_t length) {
  std::string events;
  auto add = [&](const std::string& name, int severity, const char* on, const char* off) {
    if (!events.empty()) events += ",\n";
    events += R"({ "name": ")" + name + R"(", "severity": )" + std::to_string(severity) + R"(, "state_transition": )" +
              on + R"( }, { "name": "/)" + name + R"(", "severity": )" + std::to_string(severity) +
              R"(, "state_transition": )" + off + " }";
  };
  for (int i = 0; i < warnings; ++i) add(long_event("WARNING", i, length), 30, R"(["N2W"])", R"(["W2N"])");
  for (int i = 0; i < errors; ++i) add(long_event("ERROR", i, length), 100, R"(["N2E", "W2E"])", R"(["E2N", "E2W"])");
  std::string provided = R"("D")";
  std::string services = R"({ "name": "D", "dependency": { "s_F": true, "s_A": true }, "propagate": "warning" })";
  std::string connections = R"({ "required": "C.D", "provided": "P.D" })";
  for (int i = 0; i < 8; ++i) {
    const std::string e = "E" + std::to_string(i);
    provided += R"(, ")" + e + "\"";
    services += R"(, { "name": ")" + e + R"(", "dependency": {} })";
    connections += R"(, { "required": "C.)" + e + R"(", "provided": "P.)" + e + "\" }";
  }
  return R"({ "safecass": 1, "system": "over",
  "components": [
    { "component": "P", "interfaces": { "provided": [)" +
         provided + R"(], "required": [] },
      "event": [ )" +
         events + R"( ],
      "service": [ )" +
         services + R"( ] },
    { "component": "C", "interfaces": { "provided": [], "required": [)" +
         provided + R"(] } } ],
  "connections": [ )" +
         connections + R"( ],
  "coordinators": { "over-p": ["P"], "over-c": ["C"] } })";
}

/// Every message body published on a topic, as the subscribers receive it.
template <class Topic, class Batch>
class Tap : public Topic {
public:
  explicit Tap(std::shared_ptr<Ice::Communicator> ic) : ic_(std::move(ic)) {}
  void take(const wire::Signed& m) {
    Batch batch;
    const bool ok = middleware::decode(ic_, m.body, batch);
    std::lock_guard lock(mutex_);
    sizes_.push_back(m.body.size());
    signed_sizes_.emplace_back(m.signer, m.body.size());
    if (ok) batches_.push_back(std::move(batch));
  }
  std::vector<std::size_t> sizes() const {
    std::lock_guard lock(mutex_);
    return sizes_;
  }
  /// The sizes of the messages `signer` published (the other nodes have the default limit).
  std::vector<std::size_t> sizes_of(const std::string& signer) const {
    std::lock_guard lock(mutex_);
    std::vector<std::size_t> out;
    for (const auto& [who, size] : signed_sizes_) {
      if (who == signer) out.push_back(size);
    }
    return out;
  }
  std::vector<Batch> batches() const {
    std::lock_guard lock(mutex_);
    return batches_;
  }

private:
  std::shared_ptr<Ice::Communicator> ic_;
  mutable std::mutex mutex_;
  std::vector<std::size_t> sizes_;
  std::vector<std::pair<std::string, std::size_t>> signed_sizes_;
  std::vector<Batch> batches_;
};

class StateTap final : public Tap<wire::StateTopic, wire::StateBatch> {
public:
  using Tap::Tap;
  void updates(wire::Signed m, const Ice::Current&) override { take(m); }
};

class EventTap final : public Tap<wire::EventTopic, wire::EventMessageSeq> {
public:
  using Tap::Tap;
  void records(wire::Signed m, const Ice::Current&) override { take(m); }
};

/// One coordinator process of the system, in this test process.
struct Node {
  middleware::HostClock clock;
  std::unique_ptr<Coordinator> co;
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<middleware::CoordinatorNode> node;
  std::mutex mutex;
  std::vector<std::string> log;

  std::string all_log() {
    std::lock_guard lock(mutex);
    std::string all;
    for (const std::string& line : log) all += line + "\n";
    return all;
  }
};

/// The provider (message limit `limit`) and the client on the fixture's IceStorm, and taps on
/// the provider's state topic and on the event topic. Every communicator here accepts messages
/// as large as a SAFECASS process does (Ice.MessageSizeMax 4096 KiB).
struct Bus {
  std::string port = fixture_port();
  std::string keys =
      std::string(std::getenv("SAFECASS_SCRATCH") != nullptr ? std::getenv("SAFECASS_SCRATCH") : "/tmp") +
      "/oversize-keys";
  FilterRegistry registry;
  spec::LoadResult load;
  Node provider, client;
  std::size_t limit;
  Ice::CommunicatorHolder ice;  ///< the taps': presents the reader's certificate (made with the keys)
  std::shared_ptr<Ice::ObjectAdapter> adapter;
  std::shared_ptr<StateTap> states;
  std::shared_ptr<EventTap> events;
  std::vector<std::pair<std::shared_ptr<IceStorm::TopicPrx>, std::shared_ptr<Ice::ObjectPrx>>> taps;

  Bus(int warnings, int errors, std::size_t name_length = 150, std::size_t provider_limit = kLimit)
      : limit(provider_limit) {
    register_builtin_filters(registry);
    load = spec::load_system_from_text(system_text(warnings, errors, name_length), "over.json", registry);
    EXPECT_TRUE(load.ok());
    EXPECT_TRUE(fixture::make_keys(*load.system, keys));
    // Taps on the members' topics: a member's certificate (the members' broker refuses a tool's).
    ice = Ice::CommunicatorHolder(fixture::communicator(keys, "supervisor", {{"Ice.MessageSizeMax", "4096"}}));
    states = std::make_shared<StateTap>(ice.communicator());
    events = std::make_shared<EventTap>(ice.communicator());

    auto manager = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(ice->stringToProxy(fixture::topic_manager(port)));
    auto topic = [&](const std::string& name) {
      try {
        return manager->retrieve(name);
      } catch (const IceStorm::NoSuchTopic&) {
        return manager->create(name);
      }
    };
    adapter = ice->createObjectAdapterWithEndpoints("OversizeTaps", fixture::kAdapterEndpoint);
    adapter->activate();
    for (const auto& [name, servant] : std::vector<std::pair<std::string, std::shared_ptr<Ice::Object>>>{
             {"safecass.state.over-p", states}, {"safecass.events", events}}) {
      auto subscriber = adapter->addWithUUID(servant)->ice_oneway();
      auto t = topic(name);
      t->subscribeAndGetPublisher({}, subscriber);
      taps.emplace_back(t, subscriber);
    }
    build(client, "over-c");
    build(provider, "over-p");
    start(client, "over-c", middleware::kDefaultMaxMessageBytes);
  }
  ~Bus() {
    if (provider.node) provider.node->stop();
    if (client.node) client.node->stop();
    for (const auto& [t, subscriber] : taps) {
      try {
        t->unsubscribe(subscriber);
      } catch (const Ice::Exception&) {
      }
    }
  }

  void build(Node& n, const std::string& name) {
    n.co = std::make_unique<Coordinator>(name, &n.clock);
    n.monitor = std::make_unique<Monitor>(*n.co, registry);
    EXPECT_TRUE(spec::instantiate(*load.system, *n.co, *n.monitor, name));
    EXPECT_TRUE(middleware::connect_remote_providers(*load.system, name, *n.co));
  }
  /// The provider's node: on connecting it publishes every interface in one cycle.
  void start_provider() { start(provider, "over-p", limit); }
  void start(Node& n, const std::string& name, std::size_t message_limit) {
    middleware::NodeOptions options;
    options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + port);
    options.keys_dir = keys;
    options.max_message_bytes = message_limit;
    options.log = [&n](const std::string& line) {
      std::lock_guard lock(n.mutex);
      n.log.push_back(line);
    };
    auto created = middleware::CoordinatorNode::create(*n.co, *n.monitor, registry, *load.system, name, options);
    EXPECT_TRUE(created) << (created ? "" : created.error().message);
    if (!created) return;
    n.node = std::move(*created);
    EXPECT_TRUE(n.node->start());
    EXPECT_TRUE(eventually([&] { return n.node->stats().connected; }));
  }

  State client_state(const std::string& address) {
    return client.co->state_of(*client.co->structure().resolve(address));
  }
  /// The roots the client holds for P's interface `iface` (its stand-in P.s_P.iface).
  std::vector<Condition> held(const std::string& iface) {
    return client.co->conditions(*client.co->structure().find_machine("P.s_P." + iface));
  }
  /// The interface "P.x" of an update of P's coordinator.
  std::string iface_of(const wire::StateUpdate& u) const {
    return middleware::Members(*load.system).state_streams("over-p").ifaces.at(static_cast<std::size_t>(u.stream));
  }
  /// The last update of P.`iface` the tap saw.
  std::optional<wire::StateUpdate> last_update(const std::string& iface) {
    std::optional<wire::StateUpdate> last;
    for (const wire::StateBatch& batch : states->batches()) {
      for (const wire::StateUpdate& u : batch.updates) {
        if (iface_of(u) == "P." + iface) last = u;
      }
    }
    return last;
  }
};

TEST(Oversize, AStateUpdateTooLargeForOneMessageGoesOutWithItsMostSevereRootsAndTheClientEndsInError) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  constexpr int kWarnings = 40;
  constexpr int kErrors = 3;
  Bus bus(kWarnings, kErrors);
  Coordinator& p = *bus.provider.co;
  for (int i = 0; i < kWarnings; ++i) ASSERT_TRUE(generate(p, long_event("WARNING", i), "P.s_A"));
  for (int i = 0; i < kErrors; ++i) ASSERT_TRUE(generate(p, long_event("ERROR", i), "P.s_A"));
  const ComponentId pc = *p.structure().find_component("P");
  ASSERT_EQ(p.service_roots(pc, 0).size(), std::size_t{kWarnings + kErrors});
  bus.start_provider();  // its first message carries the whole state: about 10 KB of roots
  ASSERT_TRUE(bus.provider.node && bus.client.node);

  // The client ends in Error, holding every Error root and as many Warning roots as fit.
  ASSERT_TRUE(eventually([&] {
    const auto last = bus.last_update("D");
    return last && last->roots.size() > kErrors && bus.held("D").size() == last->roots.size();
  })) << bus.provider.all_log();
  EXPECT_EQ(bus.client_state("C.s_R.D"), State::Error);
  const wire::StateUpdate last = *bus.last_update("D");
  std::size_t errors = 0;
  for (std::size_t i = 0; i < last.roots.size(); ++i) {
    if (last.roots[i].level == wire::Level::Error) {
      EXPECT_EQ(i, errors) << "the Error roots come first";
      ++errors;
    }
  }
  EXPECT_EQ(errors, std::size_t{kErrors}) << "every Error root fits and is kept";
  EXPECT_LT(last.roots.size(), std::size_t{kWarnings + kErrors}) << "some Warning roots were left out";
  std::size_t held_errors = 0;
  for (const Condition& c : bus.held("D")) held_errors += c.level == State::Error ? 1 : 0;
  EXPECT_EQ(held_errors, std::size_t{kErrors});

  // Every message the provider sent fits; the cut is counted and said.
  for (std::size_t size : bus.states->sizes()) EXPECT_LE(size, kLimit);
  const middleware::NodeStats stats = bus.provider.node->stats();
  EXPECT_GE(stats.oversized_messages, 1u);
  EXPECT_GE(stats.roots_truncated, kWarnings + kErrors - last.roots.size());
  const std::string log = bus.provider.all_log();
  EXPECT_THAT(log, ContainsRegex("middleware: over-p: state update of P\\.D \\(seq [0-9]+\\) is [0-9]+ bytes, over "
                                 "the 4096-byte message limit: sent with [0-9]+ of its [0-9]+ roots, the most severe "
                                 "first; [0-9]+ left out"))
      << log;
  EXPECT_THAT(log, HasSubstr("sent with " + std::to_string(last.roots.size()) + " of its " +
                             std::to_string(kWarnings + kErrors) + " roots, the most severe first; " +
                             std::to_string(kWarnings + kErrors - last.roots.size()) + " left out"))
      << log;

  // The errors clear: the state is still too large, the client follows it down to Warning, and
  // to Normal when the warnings clear too.
  for (int i = 0; i < kErrors; ++i) ASSERT_TRUE(generate(p, "/" + long_event("ERROR", i), "P.s_A"));
  EXPECT_TRUE(eventually([&] { return bus.client_state("C.s_R.D") == State::Warning; }))
      << bus.provider.all_log() << bus.client.all_log();
  for (int i = 0; i < kWarnings; ++i) ASSERT_TRUE(generate(p, "/" + long_event("WARNING", i), "P.s_A"));
  EXPECT_TRUE(eventually([&] { return bus.client_state("C.s_R.D") == State::Normal && bus.held("D").empty(); }))
      << bus.provider.all_log();
  for (std::size_t size : bus.states->sizes()) EXPECT_LE(size, kLimit);
  EXPECT_EQ(bus.client.node->stats().updates_rejected, 0u);
}

TEST(Oversize, ABatchTooLargeForOneMessageIsSplitAndEveryUpdateArrivesWhole) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  // Five roots of ~230 bytes on each of E0..E7: about 9 KB of updates, all dirty in one cycle.
  Bus bus(0, 5);
  Coordinator& p = *bus.provider.co;
  for (int i = 0; i < 5; ++i) {
    for (int e = 0; e < 8; ++e) ASSERT_TRUE(generate(p, long_event("ERROR", i), "P.s_P.E" + std::to_string(e)));
  }
  const std::size_t before = bus.states->batches().size();
  bus.start_provider();  // on connecting it sends every interface in one cycle
  ASSERT_TRUE(bus.provider.node && bus.client.node);

  for (int e = 0; e < 8; ++e) {
    const std::string iface = "E" + std::to_string(e);
    EXPECT_TRUE(eventually([&] {
      return bus.client_state("C.s_R." + iface) == State::Error && bus.held(iface).size() == 5;
    })) << iface
        << "\n"
        << bus.provider.all_log() << bus.client.all_log();
  }
  const auto batches = bus.states->batches();
  std::size_t most = 0;
  std::size_t after = 0;
  for (std::size_t i = before; i < batches.size(); ++i) {
    most = std::max(most, batches[i].updates.size());
    for (const wire::StateUpdate& u : batches[i].updates) after += bus.iface_of(u)[2] == 'E' ? 1 : 0;
  }
  EXPECT_GE(after, 8u);
  EXPECT_GE(most, 2u) << "updates still share messages";
  for (std::size_t size : bus.states->sizes()) EXPECT_LE(size, kLimit);
  EXPECT_EQ(bus.provider.node->stats().oversized_messages, 0u) << "no update was too large alone";
  EXPECT_EQ(bus.provider.node->stats().roots_truncated, 0u);
  EXPECT_GT(bus.provider.node->stats().state_messages_published, 1u);
}

TEST(Oversize, AnEventRecordTooLargeForOneMessageGoesOutWithItsTextCutAndNoRecordIsLostOrReordered) {
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  Bus bus(0, 1);
  bus.start_provider();
  ASSERT_TRUE(bus.provider.node && bus.client.node);
  Coordinator& p = *bus.provider.co;
  // About 17 records of ~400 bytes (events and transitions on every interface): more than one
  // message when they share a cycle.
  for (int e = 0; e < 8; ++e) ASSERT_TRUE(generate(p, long_event("ERROR", 0), "P.s_P.E" + std::to_string(e)));
  // A reset whose reason is 10,000 bytes: its record alone does not fit.
  const std::string reason(10000, 'r');
  ASSERT_TRUE(reset(p, "P.s_A", "operator", reason));

  std::vector<wire::EventMessage> seen;
  ASSERT_TRUE(eventually([&] {
    seen.clear();
    for (const wire::EventMessageSeq& batch : bus.events->batches()) {
      for (const wire::EventMessage& m : batch) {
        if (m.coordinator == "over-p") seen.push_back(m);
      }
    }
    return !seen.empty() && seen.back().record.kind == wire::RecordKind::Reset;
  })) << bus.provider.all_log();
  for (std::size_t i = 0; i < seen.size(); ++i)
    EXPECT_EQ(seen[i].seq, static_cast<std::int64_t>(i + 1)) << "in order, none lost";
  for (std::size_t size : bus.events->sizes_of("over-p")) EXPECT_LE(size, kLimit);
  const middleware::NodeStats stats = bus.provider.node->stats();
  EXPECT_EQ(stats.events_published, seen.size());
  EXPECT_EQ(stats.events_dropped, 0u);
  EXPECT_GT(stats.event_messages_published, 1u);
  EXPECT_EQ(stats.oversized_messages, 1u);

  const wire::EventMessage& reset = seen.back();
  EXPECT_THAT(reset.record.text, MatchesRegex("operator: r+ \\[cut: 10010 bytes\\]"));
  EXPECT_LT(reset.record.text.size(), kLimit);
  EXPECT_THAT(
      bus.provider.all_log(),
      ContainsRegex("middleware: over-p: event record seq [0-9]+ \\(reset of P\\.s_A\\) is [0-9]+ bytes, over the "
                    "4096-byte message limit: sent with its text cut from 10010 to [0-9]+ bytes"))
      << bus.provider.all_log();
}

TEST(Oversize, AStateOfMegabytesIsCutToTheDefaultLimitAndCrossesIceStormWhole) {
  // The default limit is what the whole path accepts: a state of about 5 MB goes out cut to
  // under 4 MiB, and IceStorm (scripts/start-icestorm) delivers it to the client.
  ASSERT_FALSE(fixture_port().empty()) << "no IceStorm fixture";
  constexpr int kErrors = 12;
  constexpr std::size_t kName = 400'000;
  Bus bus(0, kErrors, kName, middleware::kDefaultMaxMessageBytes);
  Coordinator& p = *bus.provider.co;
  for (int i = 0; i < kErrors; ++i) ASSERT_TRUE(generate(p, long_event("ERROR", i, kName), "P.s_A"));
  bus.start_provider();
  ASSERT_TRUE(bus.provider.node && bus.client.node);
  ASSERT_TRUE(
      eventually([&] { return bus.client_state("C.s_R.D") == State::Error && !bus.held("D").empty(); }, 20000ms))
      << bus.provider.all_log() << bus.client.all_log();
  const std::size_t held = bus.held("D").size();
  EXPECT_LT(held, std::size_t{kErrors});
  EXPECT_GE(held, std::size_t{kErrors} * 3 / 4) << "about 4 MB of 4.8 MB";
  for (std::size_t size : bus.states->sizes()) EXPECT_LE(size, middleware::kDefaultMaxMessageBytes);
  EXPECT_THAT(bus.provider.all_log(), HasSubstr("-byte message limit: sent with " + std::to_string(held) + " of its " +
                                                std::to_string(kErrors) + " roots, the most severe first; " +
                                                std::to_string(kErrors - static_cast<int>(held)) + " left out"));
  EXPECT_EQ(bus.provider.node->stats().roots_truncated % (kErrors - held), 0u);
}

}  // namespace
}  // namespace safecass
