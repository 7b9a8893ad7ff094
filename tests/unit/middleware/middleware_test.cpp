// The parts of the middleware that need no IceStorm: endpoints, tokens, remote providers of a
// system split into coordinators.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::middleware {
namespace {

TEST(IceEndpoint, HostAndPortAreParsed) {
  auto e = parse_ice_endpoint("127.0.0.1:24061");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->host, "127.0.0.1");
  EXPECT_EQ(e->port, 24061);
  auto p = parse_ice_endpoint("4061");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->host, "127.0.0.1") << "loopback by default";
}

TEST(IceEndpoint, MalformedEndpointsAreParseErrorsThatSayWhy) {
  for (const char* bad : {"", "host:", ":4061", "host:port", "host:70000", "host:0", "host:-1", "host:123456"}) {
    auto e = parse_ice_endpoint(bad);
    ASSERT_FALSE(e) << bad;
    EXPECT_EQ(e.error().code, ErrorCode::Parse);
    EXPECT_NE(e.error().message.find("--ice"), std::string::npos);
  }
}

std::string temp_path(const char* name) { return ::testing::TempDir() + "/" + name + std::to_string(::getpid()); }

TEST(Token, TokenFileIsPrivateAndReadsBack) {
  const std::string path = temp_path("token");
  auto secret = create_token_file(path);
  ASSERT_TRUE(secret) << secret.error().message;
  EXPECT_EQ(secret->size(), 64u);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto read = read_token_file(path);
  ASSERT_TRUE(read);
  EXPECT_EQ(*read, *secret);
  auto again = create_token_file(path);
  ASSERT_TRUE(again);
  EXPECT_NE(*again, *secret) << "every start makes a new secret";
  ::unlink(path.c_str());
}

TEST(Token, AFileThatIsNotATokenIsRefused) {
  const std::string path = temp_path("not-a-token");
  std::ofstream(path) << "hello\n";
  auto r = read_token_file(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Parse);
  ::unlink(path.c_str());
  EXPECT_EQ(read_token_file(path).error().code, ErrorCode::Io);
  EXPECT_FALSE(create_token_file("/nonexistent-dir/x.token"));
}

TEST(Token, OnlyTheExactTokenMatches) {
  const std::string t(64, 'a');
  EXPECT_TRUE(token_matches(t, t));
  EXPECT_FALSE(token_matches(t, std::string(64, 'b')));
  EXPECT_FALSE(token_matches(t, t.substr(1)));
  EXPECT_FALSE(token_matches("", "")) << "no token configured: nothing matches";
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
  auto control = co.find_component("CONTROL");
  ASSERT_TRUE(control);
  EXPECT_TRUE(co.is_remote(*control));
  ASSERT_EQ(co.connections().size(), 1u);
  EXPECT_EQ(co.service(*control, 0).propagate, State::Warning) << "the provider's propagation level";
  EXPECT_FALSE(co.find_component("JR3")) << "only what the ui's components require";
}

TEST(RemoteProviders, TheRobotCoordinatorHasNoRemoteProvider) {
  Robodoc r;
  Coordinator co("robot");
  Monitor monitor(co, r.registry);
  ASSERT_TRUE(spec::instantiate(*r.load.system, co, monitor, "robot"));
  const auto before = co.connections().size();
  ASSERT_TRUE(connect_remote_providers(*r.load.system, "robot", co));
  EXPECT_EQ(co.connections().size(), before);
  for (ComponentId c = 0; c < co.component_count(); ++c) EXPECT_FALSE(co.is_remote(c));
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
  auto node = CoordinatorNode::create(co, monitor, r.registry, *r.load.system, "robot", options);
  ASSERT_TRUE(node);
  EXPECT_FALSE((*node)->stats().connected);
}

}  // namespace
}  // namespace safecass::middleware
