// Crafted wire messages against a real coordinator node (DESIGN §7 "bad input"): a batch of state
// updates published straight to IceStorm, some of them malformed. Each update of a batch is
// checked on its own: a bad one is refused alone and changes nothing, the others apply.
//
// Environment (set by tests/integration/middleware/CMakeLists.txt):
//   SAFECASS_ICESTORM_ENV    file written by the fixture's scripts/start-icestorm --env

#include <gtest/gtest.h>

#include <Ice/Ice.h>
#include <IceStorm/IceStorm.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "safecass.h"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/node.hpp"
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

wire::StateUpdate update(const std::string& iface, std::int64_t seq, const std::string& event, wire::Level level) {
  wire::StateUpdate u;
  u.coordinator = "wire-p";
  u.incarnation = 42;
  u.seq = seq;
  u.iface = iface;
  u.state = level;
  u.roots.push_back(wire::Root{event, "P.s_A", 1000, level, "", "", 0.0, 0, false, {"P.s_A", "P.s_S." + iface.substr(2)}});
  return u;
}

TEST(Wire, ABadUpdateInABatchIsRefusedAloneAndTheOthersApply) {
  const std::string port = fixture_port();
  ASSERT_FALSE(port.empty()) << "no IceStorm fixture";
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system_from_text(kSystem, "wire.json", registry);
  ASSERT_TRUE(load.ok());
  middleware::HostClock clock;
  Coordinator co("wire-c", &clock);
  Monitor monitor(co, registry);
  ASSERT_TRUE(spec::instantiate(*load.system, co, monitor, "wire-c"));
  ASSERT_TRUE(middleware::connect_remote_providers(*load.system, "wire-c", co));
  std::mutex mutex;
  std::vector<std::string> log;
  middleware::NodeOptions options;
  options.ice = *middleware::parse_ice_endpoint("127.0.0.1:" + port);
  options.log = [&](const std::string& line) {
    std::lock_guard lock(mutex);
    log.push_back(line);
  };
  auto node = middleware::CoordinatorNode::create(co, monitor, registry, *load.system, "wire-c", options);
  ASSERT_TRUE(node);
  ASSERT_TRUE((*node)->start());
  ASSERT_TRUE(eventually([&] { return (*node)->stats().connected; }, 10000ms));

  Ice::CommunicatorHolder ice(Ice::initialize());
  auto manager = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(
      ice->stringToProxy("SafecassIceStorm/TopicManager:tcp -h 127.0.0.1 -p " + port));
  std::shared_ptr<IceStorm::TopicPrx> topic;
  try {
    topic = manager->retrieve("safecass.state.wire-p");
  } catch (const IceStorm::NoSuchTopic&) {
    topic = manager->create("safecass.state.wire-p");
  }
  auto publisher = Ice::uncheckedCast<wire::StateTopicPrx>(topic->getPublisher()->ice_oneway());
  std::this_thread::sleep_for(300ms);  // the node's subscription is in place

  wire::StateUpdateSeq batch{update("P.D0", 1, "EVT_E", wire::Level::Error),
                             update("P.D1", 1, "EVT_UNKNOWN", wire::Level::Error),            // unknown event
                             update("P.D2", 1, "EVT_E", wire::Level::Normal),                 // a Normal root
                             update("P.D3", 1, "EVT_E", wire::Level::Error)};
  publisher->updates(batch);
  auto state = [&](const char* m) { return co.state(*co.find_machine(m)); };
  ASSERT_TRUE(eventually([&] { return (*node)->stats().updates_applied + (*node)->stats().updates_rejected >= 4; }));
  EXPECT_EQ(state("C.s_R.D0"), State::Error);
  EXPECT_EQ(state("C.s_R.D1"), State::Normal) << "refused: nothing changed";
  EXPECT_EQ(state("C.s_R.D2"), State::Normal) << "refused: nothing changed";
  EXPECT_EQ(state("C.s_R.D3"), State::Error);
  EXPECT_EQ((*node)->stats().updates_applied, 2u);
  EXPECT_EQ((*node)->stats().updates_rejected, 2u);
  {
    std::lock_guard lock(mutex);
    std::string all;
    for (const std::string& line : log) all += line + "\n";
    EXPECT_NE(all.find("state update P.D1 seq 1 from coordinator 'wire-p' rejected, nothing changed"), std::string::npos) << all;
    EXPECT_NE(all.find("no event 'EVT_UNKNOWN'"), std::string::npos) << all;
    EXPECT_NE(all.find("state update P.D2 seq 1 from coordinator 'wire-p' rejected, nothing changed"), std::string::npos)
        << all;
    EXPECT_NE(all.find("level Normal is not a condition"), std::string::npos) << all;
  }

  // The refused streams are not stuck: their next update applies; a repeated number is ignored.
  publisher->updates({update("P.D1", 2, "EVT_E", wire::Level::Error), update("P.D0", 1, "EVT_E", wire::Level::Error)});
  EXPECT_TRUE(eventually([&] { return state("C.s_R.D1") == State::Error; }));
  EXPECT_TRUE(eventually([&] { return (*node)->stats().updates_rejected == 3u; })) << "P.D0 seq 1 again: stale";
  (*node)->stop();
}

}  // namespace
}  // namespace safecass
