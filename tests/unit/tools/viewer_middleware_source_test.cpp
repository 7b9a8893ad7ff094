// `safecass viewer --ice` (safecass/viewer/middleware_source.hpp) without a running system: what
// open() refuses, and how a system none of whose coordinators answers is shown and handled (no
// IceStorm listens on the port). The live system is tested in tests/integration/viewer_ice/.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#ifdef SAFECASS_VIEWER_WITH_ICE

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "safecass/viewer/middleware_source.hpp"
#include "safecass/viewer/protocol.hpp"
#include "viewer_test_support.hpp"

namespace safecass::viewer {
namespace {

using test::kSystem;

using ::testing::HasSubstr;

/// A TCP port on 127.0.0.1 that nobody listens on (bound, then released).
int closed_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t n = sizeof a;
  // Unchecked, a failed bind would hand out port 0 (or a port someone listens on) and the test
  // would check nothing.
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n) != 0) {
    ADD_FAILURE() << "closed_port: no free port on 127.0.0.1: " << std::strerror(errno);
    if (fd >= 0) ::close(fd);
    return -1;
  }
  const int port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

MiddlewareOptions options_for(int port) {
  MiddlewareOptions o;
  o.ice = "127.0.0.1:" + std::to_string(port);
  o.system = kSystem;
  o.timeout = std::chrono::milliseconds(300);
  o.retry = std::chrono::milliseconds(100);
  o.first_wait = std::chrono::milliseconds(3000);
  return o;
}

TEST(ViewerMiddlewareSource, OpenRefusesBadArgumentsWithWhatIsWrong) {
  MiddlewareOptions o = options_for(closed_port());
  o.ice = "127.0.0.1:notaport";
  auto r = MiddlewareSource::open(o);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("--ice"));

  o = options_for(closed_port());
  o.system = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/jr3.json";  // one component, no coordinators
  r = MiddlewareSource::open(o);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("has no \"coordinators\""));

  o = options_for(closed_port());
  o.system = "no/such/system.json";
  r = MiddlewareSource::open(o);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("no/such/system.json"));

  o = options_for(closed_port());
  o.token_files["arm"] = "/nonexistent";
  r = MiddlewareSource::open(o);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("has no coordinator 'arm' (it has robot, ui)"));

  o = options_for(closed_port());
  o.token_files["robot"] = "/nonexistent/robot.token";
  r = MiddlewareSource::open(o);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("--token-file robot=/nonexistent/robot.token"));
}

TEST(ViewerMiddlewareSource, CoordinatorsThatDoNotAnswerAreShownUnreachableWithTheShapeOfTheSystemFile) {
  auto source = MiddlewareSource::open(options_for(closed_port()));
  ASSERT_TRUE(source.has_value()) << source.error().message;
  MiddlewareSource& s = **source;
  EXPECT_EQ(s.status("robot"), "unreachable");
  EXPECT_EQ(s.status("ui"), "unreachable");
  EXPECT_TRUE(s.running());  // live: no scenario that ends
  const SystemView v = s.view();
  EXPECT_EQ(v.system, "robodoc");
  EXPECT_THAT(v.description, HasSubstr("live: robodoc.json through IceStorm 127.0.0.1:"));
  ASSERT_EQ(v.coordinators.size(), 2u);
  EXPECT_EQ(v.coordinators[0].name, "robot");
  EXPECT_EQ(v.coordinators[0].status, "unreachable");
  EXPECT_EQ(v.coordinators[0].components.size(), 4u);
  EXPECT_EQ(v.coordinators[1].components.at(0).name, "PENDANT");
  // The side list says so, once per coordinator, whatever the retries.
  std::vector<std::string> records = s.take_records();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  s.poll();
  for (std::string& r : s.take_records()) records.push_back(std::move(r));
  ASSERT_EQ(records.size(), 2u);
  EXPECT_THAT(records[0], HasSubstr("\"kind\":\"coordinator\""));
  EXPECT_THAT(records[0] + records[1], HasSubstr("\"coordinator\":\"robot\",\"text\":\"unreachable: "));
  EXPECT_THAT(records[0] + records[1], HasSubstr("\"coordinator\":\"ui\",\"text\":\"unreachable: "));

  // Explain and writes need the coordinator: clear errors, nothing sent.
  auto why = s.explain("CONTROL");
  ASSERT_FALSE(why.has_value());
  EXPECT_THAT(why.error().message, HasSubstr("coordinator 'robot' is unreachable"));
  why = s.explain("NOPE.s_A");
  ASSERT_FALSE(why.has_value());
  EXPECT_THAT(why.error().message, HasSubstr("no component 'NOPE' in system 'robodoc'"));
  EXPECT_FALSE(s.explain("coordinator:arm").has_value());
  auto done = s.apply(introspect::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"});
  ASSERT_FALSE(done.has_value());
  EXPECT_THAT(done.error().message, HasSubstr("read-only"));
}

TEST(ViewerMiddlewareSource, ALiveSystemsTimesAreTheHostClockShownAsWallClockTimeWithItsConnections) {
  auto source = MiddlewareSource::open(options_for(closed_port()));
  ASSERT_TRUE(source.has_value()) << source.error().message;
  const SystemView v = (*source)->view();
  EXPECT_TRUE(v.host_clock);
  // Wall-clock time of the host clock's now = now + offset: the system clock's now, give or take.
  const auto wall =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  const auto shown = static_cast<std::int64_t>((*source)->now() * 1e9) + v.wall_offset_ns;
  EXPECT_LT(std::abs(wall - shown), 1'000'000'000LL)
      << "the page would show a time " << (wall - shown) / 1000000 << " ms away from the wall clock";
  // The page says so: a "host" clock with the offset in milliseconds (ISO 8601 on the page).
  Protocol protocol(**source, ProtocolOptions{});
  EXPECT_THAT(protocol.view_json(), HasSubstr(R"("clock":{"base":"host","wall_offset_ms":)"));
  // The graph's edges: every connection of the system file.
  ASSERT_FALSE(v.connections.empty());
  EXPECT_EQ(v.connections[0].required, "CONTROL.ForceData");
  EXPECT_EQ(v.connections[0].provided, "JR3.ForceData");
}

TEST(ViewerMiddlewareSource, WritesNeedTheTokenOfTheCoordinatorThatOwnsTheTarget) {
  std::string dir = (std::filesystem::temp_directory_path() / "safecass-viewer-test-XXXXXX").string();
  ASSERT_NE(::mkdtemp(dir.data()), nullptr);
  const std::string token_file = dir + "/robot.token";
  std::ofstream(token_file) << std::string(64, 'a') << "\n";
  MiddlewareOptions o = options_for(closed_port());
  o.allow_write = true;
  o.token_files["robot"] = token_file;
  auto source = MiddlewareSource::open(o);
  std::remove(token_file.c_str());
  ::rmdir(dir.c_str());
  ASSERT_TRUE(source.has_value()) << source.error().message;
  MiddlewareSource& s = **source;
  auto r = s.apply(introspect::ResetState{"PENDANT", "viewer", "test"});
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("no token for coordinator 'ui'"));
  r = s.apply(introspect::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"});  // robot has a token, but does not answer
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("coordinator 'robot' is unreachable"));
  r = s.apply(introspect::InjectShallow{"no_such_filter", {{1.0}}});
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("no filter 'no_such_filter'"));
  r = s.apply(introspect::InjectDeep{"JR3.NoSignal", {{1.0}}});
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("no signal 'JR3.NoSignal'"));
  r = s.apply(introspect::InjectShallow{"force_limit", {{1.0}}});  // robot's filter: routed to robot
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("coordinator 'robot' is unreachable"));
}

}  // namespace
}  // namespace safecass::viewer

#endif  // SAFECASS_VIEWER_WITH_ICE
