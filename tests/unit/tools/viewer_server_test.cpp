// `safecass viewer`, its server (safecass/viewer/server.hpp) through real sockets on 127.0.0.1 with a
// port picked by the system: the embedded page, the JSON view, refused hosts, methods and
// origins, the WebSocket protocol with its push of updates, and the backoff after a failed accept.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "safecass/json/read.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/server.hpp"

namespace safecass::viewer {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using ::testing::HasSubstr;

/// A viewer on the robodoc story at speed 1 (real time), served from a thread; stopped and
/// joined by the destructor.
class RunningViewer {
public:
  explicit RunningViewer(ProtocolOptions protocol = {}) {
    InProcessOptions o;
    o.scenario = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/story.json";
    o.log = nullptr;
    auto s = InProcessSource::open(o);
    if (!s) throw std::runtime_error(s.error().message);
    source_ = std::move(*s);
    ServerOptions options;
    options.port = 0;
    auto server = Server::open(*source_, protocol, options);
    if (!server) throw std::runtime_error(server.error().message);
    server_ = std::move(*server);
    thread_ = std::thread([this] { server_->run(); });
  }
  ~RunningViewer() {
    server_->stop();
    thread_.join();
  }
  std::uint16_t port() const { return server_->port(); }

private:
  std::unique_ptr<InProcessSource> source_;
  std::unique_ptr<Server> server_;
  std::thread thread_;
};

struct Response {
  unsigned status = 0;
  std::string type;
  std::string body;
};

Response get(std::uint16_t port, const std::string& target, const std::string& host = {},
             http::verb method = http::verb::get) {
  asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.expires_after(std::chrono::seconds(10));
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req(method, target, 11);
  req.set(http::field::host, host.empty() ? "127.0.0.1:" + std::to_string(port) : host);
  req.prepare_payload();
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  beast::error_code ignored;
  stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
  return {res.result_int(), std::string(res[http::field::content_type]), res.body()};
}

/// A WebSocket client of the viewer.
class Client {
public:
  explicit Client(std::uint16_t port, const std::string& origin = {}) : ws_(ioc_) {
    beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    if (!origin.empty()) {
      ws_.set_option(websocket::stream_base::decorator(
          [origin](websocket::request_type& r) { r.set(http::field::origin, origin); }));
    }
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws");
  }
  std::string read() {
    beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
    beast::flat_buffer buffer;
    ws_.read(buffer);
    return beast::buffers_to_string(buffer.data());
  }
  /// The next message that is not a pushed update/time message.
  std::string ask(const std::string& message) {
    ws_.text(true);
    ws_.write(asio::buffer(message));
    for (;;) {
      std::string m = read();
      if (m.find(R"("type":"update")") == std::string::npos && m.find(R"("type":"time")") == std::string::npos)
        return m;
    }
  }
  void send_binary(const std::string& message) {
    ws_.binary(true);
    ws_.write(asio::buffer(message));
  }

private:
  asio::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
};

TEST(ViewerServer, ServesTheEmbeddedPageAndTheViewOnLoopback) {
  RunningViewer viewer;
  const Response page = get(viewer.port(), "/");
  EXPECT_EQ(page.status, 200u);
  EXPECT_THAT(page.type, HasSubstr("text/html"));
  EXPECT_THAT(page.body, HasSubstr("<script type=\"module\" src=\"viewer.js\"></script>"));
  const Response js = get(viewer.port(), "/viewer.js");
  EXPECT_EQ(js.status, 200u);
  EXPECT_THAT(js.type, HasSubstr("text/javascript"));
  EXPECT_THAT(js.body, HasSubstr("new WebSocket"));
  EXPECT_EQ(get(viewer.port(), "/viewer.css").status, 200u);
  // The graph's layout library, beside the page (the page imports ./dagre.js), and its licence.
  EXPECT_THAT(page.body, HasSubstr(R"(id="graph")"));
  EXPECT_THAT(js.body, HasSubstr("from './dagre.js'"));
  const Response dagre = get(viewer.port(), "/dagre.js");
  EXPECT_EQ(dagre.status, 200u);
  EXPECT_THAT(dagre.type, HasSubstr("text/javascript"));
  EXPECT_THAT(dagre.body, HasSubstr("export{"));
  const Response licence = get(viewer.port(), "/dagre.esm.js.LEGAL.txt");
  EXPECT_EQ(licence.status, 200u);
  EXPECT_THAT(licence.body, HasSubstr("Permission is hereby granted"));
  const Response view = get(viewer.port(), "/api/view", "localhost:" + std::to_string(viewer.port()));
  EXPECT_EQ(view.status, 200u);
  EXPECT_THAT(view.type, HasSubstr("application/json"));
  EXPECT_THAT(view.body, HasSubstr(R"("system":"robodoc")"));
}

TEST(ViewerServer, RefusesUnknownPathsMethodsAndHosts) {
  RunningViewer viewer;
  EXPECT_EQ(get(viewer.port(), "/etc/passwd").status, 404u);
  EXPECT_EQ(get(viewer.port(), "/", {}, http::verb::post).status, 405u);
  // A page of another site that resolves its name to 127.0.0.1 (DNS rebinding) is not answered.
  EXPECT_EQ(get(viewer.port(), "/api/view", "attacker.example:" + std::to_string(viewer.port())).status, 421u);
  EXPECT_EQ(get(viewer.port(), "/", "127.0.0.1:1").status, 421u);
}

TEST(ViewerServer, RefusesAWebSocketFromAnotherOrigin) {
  RunningViewer viewer;
  EXPECT_THROW(Client(viewer.port(), "http://attacker.example"), boost::system::system_error);
  EXPECT_NO_THROW(Client(viewer.port(), "http://127.0.0.1:" + std::to_string(viewer.port())));
}

TEST(ViewerServer, WebSocketSaysHelloAnswersRequestsAndRefusesBadOnes) {
  RunningViewer viewer;
  Client client(viewer.port());
  const std::string hello = client.read();
  EXPECT_THAT(hello, HasSubstr(R"("type":"hello","write":false)"));
  EXPECT_THAT(client.ask(R"({"id":1,"op":"explain","address":"SYSTEM"})"),
              HasSubstr(R"("type":"reply","id":1,"op":"explain")"));
  EXPECT_THAT(client.ask("{oops"), HasSubstr(R"("type":"error")"));
  EXPECT_THAT(client.ask(R"({"op":"reset","target":"SYSTEM"})"), HasSubstr("refused: this viewer is read-only"));
  client.send_binary("\x01\x02");
  std::string reply;
  do reply = client.read();
  while (reply.find(R"("type":"error")") == std::string::npos);
  EXPECT_THAT(reply, HasSubstr("binary messages are not accepted"));
  // The connection is still usable after every refusal.
  EXPECT_THAT(client.ask(R"({"op":"view"})"), HasSubstr(R"("system":"robodoc")"));
}

TEST(ViewerServer, PushesTheTransitionsOfTheScenarioAsTheyHappen) {
  RunningViewer viewer;
  Client client(viewer.port());
  client.read();  // hello
  // The story's force crosses 30 N at about t = 0.49 s (real time at speed 1).
  const auto start = std::chrono::steady_clock::now();
  bool seen = false;
  while (!seen && std::chrono::steady_clock::now() - start < std::chrono::seconds(8)) {
    const std::string m = client.read();
    if (m.find(R"("type":"update")") == std::string::npos) continue;
    const json::JsonParse p = json::parse_json(m);
    ASSERT_TRUE(p.value.has_value()) << m;
    const json::JsonValue* control = p.value->find("states")->find("CONTROL");
    if (control == nullptr || control->array[0].string != "Error") continue;
    seen = true;
    // Pushed within one poll of the transition: the update's clock is at most 100 ms later.
    double transition_t = -1;
    for (const json::JsonValue& r : p.value->find("records")->array) {
      const json::JsonValue* c = r.find("component");
      if (r.find("kind")->string == "component-transition" && c != nullptr && c->string == "CONTROL")
        transition_t = r.find("t")->number;
    }
    ASSERT_GE(transition_t, 0.0) << m;
    EXPECT_LT(p.value->find("t")->number - transition_t, 0.1);
  }
  EXPECT_TRUE(seen) << "CONTROL never went to Error";
}

TEST(ViewerServer, WriteNeedsTheTokenOverTheWebSocket) {
  ProtocolOptions protocol;
  protocol.allow_write = true;
  protocol.token = "0123abcd";
  RunningViewer viewer(protocol);
  Client client(viewer.port());
  EXPECT_THAT(client.read(), HasSubstr(R"("write":true)"));
  const std::string generate = R"({"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A")";
  EXPECT_THAT(client.ask(generate + "}"), HasSubstr("refused: a write needs the token"));
  EXPECT_THAT(client.ask(generate + R"(,"token":"0123abce"})"), HasSubstr("refused: wrong token"));
  EXPECT_THAT(client.ask(R"({"op":"explain","address":"CONTROL.s_A"})"), HasSubstr(R"("state":"Normal")"));
  EXPECT_THAT(client.ask(generate + R"(,"token":"0123abcd"})"), HasSubstr("generated EVT_CONTROL_FORCE_FREEZE"));
  EXPECT_THAT(client.ask(R"({"op":"explain","address":"CONTROL.s_A"})"), HasSubstr(R"("state":"Error")"));
}

TEST(ViewerServer, OpenReportsABusyPortAndABadAddress) {
  RunningViewer viewer;
  InProcessOptions o;
  o.system = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";
  auto source = InProcessSource::open(o);
  ASSERT_TRUE(source.has_value());
  ServerOptions busy;
  busy.port = viewer.port();
  auto a = Server::open(**source, {}, busy);
  ASSERT_FALSE(a.has_value());
  EXPECT_THAT(a.error().message, HasSubstr("cannot listen on 127.0.0.1:" + std::to_string(viewer.port())));
  ServerOptions bad;
  bad.bind = "localhost.invalid";
  auto b = Server::open(**source, {}, bad);
  ASSERT_FALSE(b.has_value());
  EXPECT_THAT(b.error().message, HasSubstr("not an IPv4 or IPv6 address"));
  ProtocolOptions no_token;
  no_token.allow_write = true;
  EXPECT_FALSE(Server::open(**source, no_token, bad).has_value());
}

TEST(ViewerAcceptBackoff, WaitsTenMillisecondsDoublingToOneSecondAndStartsAgainAfterASuccess) {
  AcceptBackoff b;
  const auto t0 = AcceptBackoff::Clock::now();
  std::vector<long> delays;
  for (int i = 0; i < 10; ++i) delays.push_back(static_cast<long>(b.failed(t0).delay.count()));
  EXPECT_EQ(delays, (std::vector<long>{10, 20, 40, 80, 160, 320, 640, 1000, 1000, 1000}));
  b.succeeded();
  EXPECT_EQ(b.failed(t0).delay.count(), 10);
  EXPECT_EQ(b.failed(t0).delay.count(), 20);
}

TEST(ViewerAcceptBackoff, LogsTheFirstFailureThenAtMostOnceEveryTenSecondsWithTheCountNotLogged) {
  AcceptBackoff b;
  const auto t0 = AcceptBackoff::Clock::now();
  const AcceptBackoff::Step first = b.failed(t0);
  EXPECT_TRUE(first.log);
  EXPECT_EQ(first.not_logged, 0u);
  int logged = 0;
  for (int ms = 1; ms < 10000; ms += 10) logged += b.failed(t0 + std::chrono::milliseconds(ms)).log ? 1 : 0;
  EXPECT_EQ(logged, 0) << "nothing more within ten seconds";
  b.succeeded();  // a success does not reopen the log: a flapping error is not logged more often
  EXPECT_FALSE(b.failed(t0 + std::chrono::milliseconds(9995)).log);
  const AcceptBackoff::Step later = b.failed(t0 + std::chrono::seconds(10));
  EXPECT_TRUE(later.log);
  EXPECT_EQ(later.not_logged, 1001u);
  EXPECT_FALSE(b.failed(t0 + std::chrono::seconds(11)).log);
}

}  // namespace
}  // namespace safecass::viewer
