// The parts of the middleware that need no IceStorm: endpoints, tokens, remote providers of a
// system split into coordinators.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include "certificates.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/supervisor.hpp"
#include "safecass/spec/load.hpp"

#include "../../../examples/custom_filter/frozen_filter.hpp"

namespace safecass::middleware {
namespace {

/// A directory of this test's own under the test temp dir, removed before (a PID is reused: a
/// run killed before its end leaves one) and after the test.
class FreshDir {
public:
  explicit FreshDir(const std::string& name) : path_(::testing::TempDir() + name + "-" + std::to_string(::getpid())) {
    remove();
  }
  FreshDir(const FreshDir&) = delete;
  FreshDir& operator=(const FreshDir&) = delete;
  ~FreshDir() { remove(); }
  operator const std::string&() const { return path_; }  // NOLINT(google-explicit-constructor): a path

private:
  void remove() const {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
    std::filesystem::remove_all(path_ + "-shared", ec);
  }
  std::string path_;
};

TEST(IceEndpoint, HostAndPortAreParsed) {
  auto e = parse_ice_endpoint("127.0.0.1:24061");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->host, "127.0.0.1");
  EXPECT_EQ(e->port, 24061);
  auto p = parse_ice_endpoint("4061");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->host, "127.0.0.1") << "loopback by default";
}

TEST(IceEndpoint, ALocatorPrefixNamesTheIceGridRegistryOfAReplicatedIceStormAndPrintsBackAsWritten) {
  auto e = parse_ice_endpoint("locator:10.77.0.3:4061");
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->locator);
  EXPECT_EQ(e->host, "10.77.0.3");
  EXPECT_EQ(e->port, 4061);
  EXPECT_EQ(to_string(*e), "locator:10.77.0.3:4061");
  auto direct = parse_ice_endpoint("127.0.0.1:4061");
  ASSERT_TRUE(direct);
  EXPECT_FALSE(direct->locator);
  EXPECT_EQ(to_string(*direct), "127.0.0.1:4061");
}

TEST(IceEndpoint, AListNamesThisHostsBrokerFirstThenTheOtherHostsBrokersAndPrintsBackAsWritten) {
  auto e = parse_ice_endpoint("a=10.77.0.1:4061,b=10.77.0.2:4061,host-c=10.77.0.3:5061");
  ASSERT_TRUE(e) << e.error().message;
  EXPECT_EQ(e->host, "10.77.0.1");
  EXPECT_EQ(e->port, 4061);
  EXPECT_EQ(e->name, "a");
  ASSERT_EQ(e->peers.size(), 2u);
  EXPECT_EQ(e->peers[0].host, "10.77.0.2");
  EXPECT_EQ(e->peers[1].port, 5061);
  EXPECT_FALSE(e->peers[1].locator);
  EXPECT_EQ(to_string(*e), "a=10.77.0.1:4061,b=10.77.0.2:4061,host-c=10.77.0.3:5061");
  EXPECT_TRUE(parse_ice_endpoint("127.0.0.1:4061")->peers.empty());
}

TEST(IceEndpoint, EachBrokerOfAHostHasAnInstanceNameOfItsOwnSoThatItsTopicsCanBeLinkedApart) {
  auto e = parse_ice_endpoint("a=10.77.0.1:4061,b=10.77.0.2:4061");
  ASSERT_TRUE(e);
  EXPECT_EQ(instance_name(*e), "SafecassIceStorm.a");
  EXPECT_EQ(instance_name(tools_broker(e->peers[0])), "SafecassToolStorm.b");
  EXPECT_EQ(tools_broker(e->peers[0]).port, 4062);
  EXPECT_EQ(instance_name(*parse_ice_endpoint("127.0.0.1:4061")), "SafecassIceStorm");
  EXPECT_EQ(instance_name(*parse_ice_endpoint("b=127.0.0.1:4061")), "SafecassIceStorm.b") << "a named broker alone";
}

TEST(IceEndpoint, MalformedEndpointsAreParseErrorsThatSayWhy) {
  for (const char* bad : {"",
                          "host:",
                          ":4061",
                          "host:port",
                          "host:70000",
                          "host:0",
                          "host:-1",
                          "host:123456",
                          "locator:",
                          "locator:4061",
                          "locator::4061",
                          "locator:host:port",
                          "x=a:4061,",
                          "x=a:4061,,y=b:4061",
                          "x=a:4061,y=b:port",
                          "x=a:4061,locator:b:4061",
                          "locator:a:4061,y=b:4061",
                          "x=a:4061,y=a:4061",
                          "x=a:4061,y=b:4061,z=b:4061",
                          "a:4061,b:4061",
                          "x=a:4061,b:4061",
                          "x=a:4061,x=b:4061",
                          "=a:4061",
                          "x y=a:4061",
                          "x=locator:a:4061",
                          "x=a:4061,y=locator:b:4061"}) {
    auto e = parse_ice_endpoint(bad);
    ASSERT_FALSE(e) << bad;
    EXPECT_EQ(e.error().code, ErrorCode::Parse);
    EXPECT_NE(e.error().message.find("--ice"), std::string::npos);
  }
}

struct Robodoc {
  FilterRegistry registry;
  spec::LoadResult load;
  Robodoc() {
    register_builtin_filters(registry);
    load = spec::load_system(std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json", registry);
  }
};

TEST(RemoteProviders, TheUiCoordinatorGetsCONTROLStatusAsARemoteProvider) {
  Robodoc r;
  ASSERT_TRUE(r.load.ok());
  Coordinator co("ui");
  Monitor monitor(co, r.registry);
  ASSERT_TRUE(spec::instantiate(*r.load.system, co, monitor, "ui"));
  ASSERT_TRUE(connect_remote_providers(*r.load.system, "ui", co));
  auto control = co.structure().find_component("CONTROL");
  ASSERT_TRUE(control);
  EXPECT_TRUE(co.structure().is_remote(*control));
  ASSERT_EQ(co.structure().connections().size(), 1u);
  EXPECT_EQ(co.structure().service(*control, 0).propagate, State::Warning) << "the provider's propagation level";
  EXPECT_FALSE(co.structure().find_component("JR3")) << "only what the ui's components require";
}

TEST(RemoteProviders, TheRobotCoordinatorHasNoRemoteProvider) {
  Robodoc r;
  Coordinator co("robot");
  Monitor monitor(co, r.registry);
  ASSERT_TRUE(spec::instantiate(*r.load.system, co, monitor, "robot"));
  const auto before = co.structure().connections().size();
  ASSERT_TRUE(connect_remote_providers(*r.load.system, "robot", co));
  EXPECT_EQ(co.structure().connections().size(), before);
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count()))
    EXPECT_FALSE(co.structure().is_remote(c));
}

TEST(RemoteProviders, AnUnknownCoordinatorIsNotFound) {
  Robodoc r;
  Coordinator co("x");
  auto e = connect_remote_providers(*r.load.system, "nowhere", co);
  ASSERT_FALSE(e);
  EXPECT_EQ(e.error().code, ErrorCode::NotFound);
}

TEST(CoordinatorNode, CreationChecksItsOptionsWithoutTouchingTheNetwork) {
  Robodoc r;
  Coordinator co("robot");
  Monitor monitor(co, r.registry);
  ASSERT_TRUE(spec::instantiate(*r.load.system, co, monitor, "robot"));
  NodeOptions options;
  EXPECT_FALSE(CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options)) << "no port";
  options.ice.port = 1;
  auto unknown = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "nowhere", options);
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::NotFound);

  const FreshDir keys_dir("safecass-node-keys");
  const std::string& keys = keys_dir;
  options.keys_dir = keys + "-missing";
  auto no_keys = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options);
  ASSERT_FALSE(no_keys) << "the bus is authenticated: no keys, no node";
  EXPECT_NE(no_keys.error().message.find("safecass keys"), std::string::npos) << no_keys.error().message;

  ASSERT_TRUE(create_bus_keys(*r.load.system, keys, KeyOptions::replacing()));
  options.keys_dir = keys;
  options.ice.host = "192.0.2.7";
  EXPECT_TRUE(CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options))
      << "keys with the system's certificates: mutual TLS, so another host is allowed";
  ASSERT_EQ(::rename((keys + "/ca.pem").c_str(), (keys + "/ca.pem.away").c_str()), 0);
  auto far = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options);
  ASSERT_FALSE(far) << "a non-loopback IceStorm without TLS and without --insecure";
  EXPECT_EQ(far.error().code, ErrorCode::InvalidArgument);
  ASSERT_EQ(::rename((keys + "/ca.pem.away").c_str(), (keys + "/ca.pem").c_str()), 0);
  options.ice.host = "127.0.0.1";

  ASSERT_EQ(::chmod((keys + "/robot.secret").c_str(), 0640), 0);
  auto exposed = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options);
  ASSERT_FALSE(exposed) << "a secret key others can read is refused";
  EXPECT_EQ(exposed.error().code, ErrorCode::Denied);
  ASSERT_EQ(::chmod((keys + "/robot.secret").c_str(), 0600), 0);

  auto node = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options);
  ASSERT_TRUE(node) << node.error().message;
  EXPECT_FALSE((*node)->stats().connected);
}

TEST(Supervisor, BuildsItsViewWithTheApplicationsFilterRegistryAndWithoutItNamesTheUnknownType) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  ASSERT_TRUE(registry.add<Frozen>("Frozen"));
  auto load = spec::load_system(std::string(SAFECASS_SOURCE_DIR) + "/tests/data/custom_filter/encoders.json", registry);
  ASSERT_TRUE(load.ok()) << spec::to_text(load.diagnostics);
  const FreshDir keys_dir("safecass-supervisor-keys");
  const std::string& keys = keys_dir;
  ASSERT_TRUE(create_bus_keys(*load.system, keys, KeyOptions::replacing()));
  SupervisorOptions options;
  options.ice = *parse_ice_endpoint("127.0.0.1:1");  // never reached: create() touches no network
  options.keys_dir = keys;
  options.print = [](const std::string&) {};
  options.registry = &registry;
  auto supervisor = Supervisor::create(*load.system, options);
  ASSERT_TRUE(supervisor) << supervisor.error().message;
  EXPECT_TRUE((*supervisor)->model().structure().find_component("ENCODER"));

  options.registry = nullptr;  // the built-in types alone
  auto builtin_only = Supervisor::create(*load.system, options);
  ASSERT_FALSE(builtin_only);
  EXPECT_NE(builtin_only.error().message.find("Frozen"), std::string::npos) << builtin_only.error().message;
}

TEST(BusKeys, AreCreatedPrivateOncePerSignerAndNeverOverwriteAForeignFile) {
  Robodoc r;
  const FreshDir keys_dir("safecass-keys");
  const std::string& keys = keys_dir;
  auto names = create_bus_keys(*r.load.system, keys, KeyOptions::replacing());
  ASSERT_TRUE(names) << names.error().message;
  EXPECT_EQ(*names, (std::vector<std::string>{"robot", "ui", "supervisor"}));
  struct stat st {};
  ASSERT_EQ(::stat(keys.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  ASSERT_EQ(::stat((keys + "/robot.secret").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto again = create_bus_keys(*r.load.system, keys);
  ASSERT_FALSE(again) << "existing keys are kept unless replaced";
  EXPECT_EQ(again.error().code, ErrorCode::Duplicate);
  // A file that is not a key is never overwritten, even with replace.
  ::unlink((keys + "/ui.secret").c_str());
  { std::ofstream(keys + "/ui.secret") << "my notes\n"; }
  auto foreign = create_bus_keys(*r.load.system, keys, KeyOptions::replacing());
  ASSERT_FALSE(foreign);
  std::ifstream in(keys + "/ui.secret");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "my notes");
}

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

KeyOptions with_addresses(std::vector<std::string> addresses) {
  KeyOptions o = KeyOptions::replacing();
  o.addresses = std::move(addresses);
  return o;
}

KeyOptions with_ca(const std::string& dir) {
  KeyOptions o = KeyOptions::replacing();
  o.ca_dir = dir;
  return o;
}

mode_t file_mode(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 0777) : 0;
}

// Members only at the broker (docs/security.md): the one key set-up makes the system's CA and a
// certificate signed by it for every member, IceStorm and the tools' reader; private keys 0600.
TEST(BusKeys, MakeTheSystemsCaAndACertificateSignedByItForEveryMemberIceStormAndTheReader) {
  Robodoc r;
  const FreshDir keys_dir("safecass-certs");
  const std::string& keys = keys_dir;
  ASSERT_TRUE(create_bus_keys(*r.load.system, keys, with_addresses({"IP:10.0.0.5", "DNS:robot.local"})));
  const std::string ca = file_text(keys + "/ca.pem");
  ASSERT_EQ(ca.rfind("-----BEGIN CERTIFICATE-----", 0), 0u);
  EXPECT_EQ(file_mode(keys + "/ca.key"), 0600u);
  for (const char* name : {"robot", "ui", "supervisor", "icestorm", "reader"}) {
    const std::string path = keys + "/" + name;
    EXPECT_TRUE(signed_by(file_text(path + ".pem"), ca)) << name;
    EXPECT_EQ(file_mode(path + ".pem"), 0644u) << name;
    EXPECT_EQ(file_mode(path + ".key"), 0600u) << name;
  }
  // Made again (--replace), the keys are new and the CA is kept: IceStorm, started with the first
  // certificates, still admits the members' new ones.
  const std::string first_robot = file_text(keys + "/robot.pem");
  ASSERT_TRUE(create_bus_keys(*r.load.system, keys, KeyOptions::replacing()));
  EXPECT_EQ(file_text(keys + "/ca.pem"), ca);
  EXPECT_NE(file_text(keys + "/robot.pem"), first_robot);
  EXPECT_TRUE(signed_by(file_text(keys + "/robot.pem"), ca));

  // Another system's CA does not vouch for these certificates.
  const std::string other = keys + "-other";
  ASSERT_TRUE(create_bus_keys(*r.load.system, other, KeyOptions::replacing()));
  EXPECT_FALSE(signed_by(file_text(keys + "/robot.pem"), file_text(other + "/ca.pem")));

  // A system that shares the broker signs with its CA (--ca DIR): the CA's key is not copied.
  const std::string shared = keys + "-shared";
  ASSERT_TRUE(create_bus_keys(*r.load.system, shared, with_ca(keys)));
  EXPECT_EQ(file_text(shared + "/ca.pem"), ca);
  EXPECT_TRUE(signed_by(file_text(shared + "/robot.pem"), ca));
  EXPECT_EQ(file_mode(shared + "/ca.key"), 0u) << "the CA's key stays where it is";
}

TEST(BusKeys, AreRefusedWithAClearErrorForAReservedNameABadAddressOrACaWithoutItsKey) {
  Robodoc r;
  const FreshDir keys_dir("safecass-certs-bad");
  const std::string& keys = keys_dir;
  auto address = create_bus_keys(*r.load.system, keys, with_addresses({"10.0.0.5"}));
  ASSERT_FALSE(address);
  EXPECT_EQ(address.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(address.error().message.find("IP:ADDRESS or DNS:NAME"), std::string::npos) << address.error().message;
  struct stat st {};
  EXPECT_NE(::stat(keys.c_str(), &st), 0) << "a refused address writes nothing";

  spec::SystemSpec reserved = *r.load.system;
  reserved.coordinators.emplace_back("icestorm", std::vector<std::string>{});
  auto name = create_bus_keys(reserved, keys, KeyOptions::replacing());
  ASSERT_FALSE(name);
  EXPECT_NE(name.error().message.find("'icestorm' is reserved"), std::string::npos) << name.error().message;

  ASSERT_TRUE(create_bus_keys(*r.load.system, keys, KeyOptions::replacing()));
  ASSERT_EQ(::unlink((keys + "/ca.key").c_str()), 0);
  auto half = create_bus_keys(*r.load.system, keys, KeyOptions::replacing());
  ASSERT_FALSE(half) << "ca.pem without ca.key cannot sign";
  EXPECT_NE(half.error().message.find("ca.pem and ca.key go together"), std::string::npos) << half.error().message;
}

TEST(BusKeys, ACaWhoseKeyOthersCanReadSignsNothingAndChangesNothing) {
  Robodoc r;
  const FreshDir keys_dir("safecass-certs-open-ca");
  const std::string& keys = keys_dir;
  ASSERT_TRUE(create_bus_keys(*r.load.system, keys, KeyOptions::replacing()));
  const std::string robot = file_text(keys + "/robot.pem");
  ASSERT_EQ(::chmod((keys + "/ca.key").c_str(), 0640), 0);
  for (const std::string& dir : {keys, keys + "-shared"}) {
    SCOPED_TRACE(dir);
    auto made = create_bus_keys(*r.load.system, dir, dir == keys ? KeyOptions::replacing() : with_ca(keys));
    ASSERT_FALSE(made) << "a CA key others can read is refused";
    EXPECT_EQ(made.error().code, ErrorCode::Denied);
    EXPECT_NE(made.error().message.find("ca.key: a private key must be owned by its user and have mode 0600"),
              std::string::npos)
        << made.error().message;
  }
  EXPECT_EQ(file_text(keys + "/robot.pem"), robot) << "nothing was made again";
}

TEST(BusKeys, LoopbackHostsAreRecognised) {
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("127.1.2.3"));
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_FALSE(is_loopback_host("10.0.0.1"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("robot.example"));
}

// ---- the publisher's snapshot: service_roots() built from the conditions ----------------------

/// The full state of a service as the publisher used to build it: from explain() of the service
/// address, one root per (event, origin, time), the level of its first explanation and the
/// shortest path.
std::vector<RemoteRoot> roots_from_explain(const Coordinator& co, ComponentId component, std::uint32_t service) {
  Address a;
  a.kind = Address::Kind::Service;
  a.component = component;
  a.service = service;
  std::vector<RemoteRoot> out;
  for (const Explanation& e : co.explain(a)) {
    auto it = std::find_if(out.begin(), out.end(), [&](const RemoteRoot& r) {
      return r.root.event == e.root.event && r.root.origin == e.root.origin && r.root.time == e.root.time;
    });
    if (it != out.end()) {
      if (e.path.size() < it->path.size()) it->path = e.path;
      continue;
    }
    out.push_back(RemoteRoot{e.root, e.level, e.path});
  }
  return out;
}

std::string text_of(const std::vector<RemoteRoot>& roots) {
  std::string out;
  for (const RemoteRoot& r : roots) {
    out += r.root.origin + ":" + r.root.event + "@" + std::to_string(r.root.time.count()) + " " +
           std::string(to_string(r.level)) + " filter=" + r.root.filter + " signal=" + r.root.signal + "=" +
           std::to_string(r.root.value) + "@" + std::to_string(r.root.sample_time.count()) +
           (r.root.injected ? " injected" : "") + " path";
    for (const std::string& hop : r.path) out += " " + hop;
    out += "\n";
  }
  return out;
}

// S runs in "left"; A and B in "right", which holds S.out as a remote provided interface.
constexpr const char* kChain = R"({
  "safecass": 1, "system": "chain",
  "components": [
    { "component": "S", "interfaces": { "provided": ["out"], "required": [] },
      "event": [ { "name": "EVT_E", "severity": 50, "state_transition": ["N2E", "W2E"] },
                 { "name": "/EVT_E", "severity": 50, "state_transition": ["E2N", "E2W"] },
                 { "name": "EVT_F", "severity": 70, "state_transition": ["N2E", "W2E"] },
                 { "name": "/EVT_F", "severity": 70, "state_transition": ["E2N", "E2W"] },
                 { "name": "EVT_W", "severity": 30, "state_transition": ["N2W"] },
                 { "name": "/EVT_W", "severity": 30, "state_transition": ["W2N"] } ],
      "service": [ { "name": "out", "dependency": { "s_F": true, "s_A": true }, "propagate": "warning" } ] },
    { "component": "A", "interfaces": { "provided": ["p", "q"], "required": ["in"] },
      "service": [ { "name": "p", "dependency": { "s_F": true, "s_A": true, "s_R": ["in"] }, "propagate": "warning" },
                   { "name": "q", "dependency": { "s_A": true } } ] },
    { "component": "B", "interfaces": { "provided": ["r"], "required": ["a"] },
      "service": [ { "name": "r", "dependency": { "s_A": true, "s_R": ["a"] } } ] } ],
  "connections": [ { "required": "A.in", "provided": "S.out" }, { "required": "B.a", "provided": "A.p" } ],
  "coordinators": { "left": ["S"], "right": ["A", "B"] } })";

TEST(ServiceRoots, TheSnapshotBuiltFromConditionsEqualsTheOneBuiltFromExplain) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto load = spec::load_system_from_text(kChain, "chain.json", registry);
  ASSERT_TRUE(load.ok());
  SimulatedClock clock;
  Coordinator co("right", &clock);
  Monitor monitor(co, registry);
  ASSERT_TRUE(spec::instantiate(*load.system, co, monitor, "right"));
  ASSERT_TRUE(connect_remote_providers(*load.system, "right", co));
  const MachineId remote = *co.structure().find_machine("S.s_P.out");
  const std::vector<std::string> onsets{"EVT_E", "EVT_F", "EVT_W"};
  const std::vector<std::string> events{"EVT_E", "/EVT_E", "EVT_F", "/EVT_F", "EVT_W", "/EVT_W"};
  std::vector<MachineId> local;
  for (const char* m : {"A.s_F", "A.s_A", "A.s_P.p", "A.s_P.q", "A.s_R.in", "B.s_A", "B.s_P.r", "B.s_R.a"}) {
    local.push_back(*co.structure().find_machine(m));
  }
  std::mt19937 random(20261121);
  std::size_t mixed = 0;  // steps where A.p held a remote and a local root together
  for (int step = 0; step < 3000; ++step) {
    clock.advance(std::chrono::milliseconds(1));
    if (random() % 4 == 0) {
      // A new full state of S.out: up to three roots of S's process, Warning or Error.
      std::vector<RemoteRoot> roots;
      const std::size_t n = random() % 4;
      for (std::size_t i = 0; i < n; ++i) {
        RemoteRoot r;
        r.root.event = onsets[random() % onsets.size()];
        r.root.origin = random() % 2 == 0 ? "S.s_A" : "S.s_F";
        r.root.time = Time{static_cast<std::int64_t>(random() % 3) * 1000};
        r.level = r.root.event == "EVT_W" ? State::Warning : State::Error;
        r.path = {r.root.origin, "S.s_S.out"};
        if (random() % 2 == 0) {
          r.root.filter = "f";
          r.root.signal = "force";
          r.root.value = 1.5;
        }
        if (std::none_of(roots.begin(), roots.end(), [&](const RemoteRoot& x) {
              return x.root.event == r.root.event && x.root.origin == r.root.origin && x.root.time == r.root.time;
            })) {
          roots.push_back(r);
        }
      }
      ASSERT_TRUE(co.apply_remote(remote, roots));
    } else {
      co.generate(*co.structure().find_event(events[random() % events.size()]), local[random() % local.size()]);
    }
    for (const char* name : {"A", "B"}) {
      const ComponentId c = *co.structure().find_component(name);
      for (std::uint32_t p = 0; p < co.structure().provided_machines(c).size(); ++p) {
        const auto got = co.service_roots(c, p);
        ASSERT_EQ(text_of(got), text_of(roots_from_explain(co, c, p)))
            << "step " << step << ", service " << name << " #" << p;
        if (std::string(name) == "A" && p == 0) {
          const bool any_remote =
              std::any_of(got.begin(), got.end(), [](const RemoteRoot& r) { return r.root.origin[0] == 'S'; });
          const bool any_local =
              std::any_of(got.begin(), got.end(), [](const RemoteRoot& r) { return r.root.origin[0] != 'S'; });
          mixed += any_remote && any_local ? 1 : 0;
        }
      }
    }
  }
  EXPECT_GT(mixed, 100u) << "the sequence must exercise remote and local roots together";
}

}  // namespace
}  // namespace safecass::middleware
