#include "safecass/viewer/server.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <deque>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "viewer_assets.hpp"

namespace safecass::viewer {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

namespace {

constexpr std::size_t kMaxWebSocketFrame = 1024 * 1024;  ///< beyond this the connection is closed
constexpr std::uint32_t kMaxRequestBody = 8 * 1024;
constexpr auto kHttpTimeout = std::chrono::seconds(30);

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

long long monotonic_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void log_line(const std::string& text) {
  std::fprintf(stderr, "safecass viewer: %s\n", text.c_str());
  std::fflush(stderr);
}

}  // namespace

class WebSocketSession;

/// Everything the sessions share; lives as long as the Server.

struct ServerCore {
  ServerCore(ViewSource& s, const ProtocolOptions& p, const ServerOptions& o)
      : source(s), protocol(s, p), options(o), acceptor(ioc), accept_timer(ioc), timer(ioc), signals(ioc) {}

  asio::io_context ioc{1};  // first member: destroyed last, after the sessions its handlers hold
  ViewSource& source;
  Protocol protocol;
  ServerOptions options;
  tcp::acceptor acceptor;
  asio::steady_timer accept_timer;  ///< the wait before accepting again after a failed accept
  AcceptBackoff backoff;
  asio::steady_timer timer;
  asio::signal_set signals;
  std::vector<std::weak_ptr<WebSocketSession>> sessions;
  std::set<std::string> allowed_hosts;  ///< empty: any Host (bound to a wildcard address)
  std::uint16_t port = 0;
  std::string url;
  std::atomic<bool> stopped{false};

  void accept();
  void schedule_poll();
  void poll();
  void broadcast(const std::string& message);
  bool host_allowed(std::string_view host) const {
    return allowed_hosts.empty() || allowed_hosts.count(lower(host)) != 0;
  }
  void shutdown();
};

// ---- WebSocket ---------------------------------------------------------------------------------

class WebSocketSession : public std::enable_shared_from_this<WebSocketSession> {
public:
  WebSocketSession(tcp::socket&& socket, ServerCore& server) : ws_(std::move(socket)), server_(server) {}

  void start(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "safecass-viewer"); }));
    ws_.read_message_max(kMaxWebSocketFrame);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->open_ = true;
      self->send(std::make_shared<const std::string>(self->server_.protocol.hello()));
      self->read();
    });
  }

  /// Queues a message. Before the handshake has completed nothing is queued: the hello, sent
  /// first, holds everything an earlier update would have said.
  void send(std::shared_ptr<const std::string> message) {
    if (closing_ || !open_) return;
    if (queue_.size() >= server_.options.max_queued) {
      // A page that does not read its updates is dropped rather than buffered without limit.
      closing_ = true;
      beast::get_lowest_layer(ws_).socket().close();
      return;
    }
    queue_.push_back(std::move(message));
    if (queue_.size() == 1) write();
  }

  void close() {
    if (closing_) return;
    closing_ = true;
    if (!open_) {
      beast::get_lowest_layer(ws_).socket().close();
      return;
    }
    ws_.async_close(websocket::close_code::going_away, [self = shared_from_this()](beast::error_code) {});
  }

private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return;  // closed, or a frame too big: the connection ends, nothing changed
      std::string reply;
      if (!self->ws_.got_text()) {
        reply = R"({"type":"error","error":"binary messages are not accepted: send JSON text"})";
      } else {
        const std::string text = beast::buffers_to_string(self->buffer_.data());
        try {
          reply = self->server_.protocol.handle(text);
        } catch (const std::exception& e) {
          reply = R"({"type":"error","error":"internal error"})";
          log_line(std::string("error while handling a message: ") + e.what());
        }
      }
      self->buffer_.consume(self->buffer_.size());
      self->send(std::make_shared<const std::string>(std::move(reply)));
      self->read();
    });
  }

  void write() {
    ws_.text(true);
    ws_.async_write(asio::buffer(*queue_.front()), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->queue_.clear();
        return;
      }
      self->queue_.pop_front();
      if (!self->queue_.empty()) self->write();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  ServerCore& server_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  bool open_ = false;
  bool closing_ = false;
};

// ---- HTTP ----------------------------------------------------------------------------------------

class HttpSession : public std::enable_shared_from_this<HttpSession> {
public:
  HttpSession(tcp::socket&& socket, ServerCore& server) : stream_(std::move(socket)), server_(server) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(kMaxRequestBody);
    stream_.expires_after(kHttpTimeout);
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec != http::error::end_of_stream) self->stream_.socket().close(ec);
        return;
      }
      self->handle(self->parser_->release());
    });
  }

private:
  void handle(http::request<http::string_body> req) {
    const std::string host(req[http::field::host]);
    if (!server_.host_allowed(host)) {
      return respond(req, http::status::misdirected_request, "text/plain", "unknown host '" + host + "'\n");
    }
    if (websocket::is_upgrade(req)) {
      if (req.target() != "/ws")
        return respond(req, http::status::not_found, "text/plain", "the WebSocket is at /ws\n");
      const auto origin = req.find(http::field::origin);
      if (origin != req.end() &&
          lower(std::string_view(origin->value().data(), origin->value().size())) != "http://" + lower(host)) {
        return respond(req, http::status::forbidden, "text/plain", "WebSocket from another origin refused\n");
      }
      stream_.expires_never();
      auto ws = std::make_shared<WebSocketSession>(stream_.release_socket(), server_);
      server_.sessions.push_back(ws);
      ws->start(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      return respond(req, http::status::method_not_allowed, "text/plain", "only GET and HEAD\n");
    }
    std::string_view target(req.target().data(), req.target().size());
    target = target.substr(0, target.find('?'));
    if (target == "/" || target == "/index.html")
      return respond(req, http::status::ok, "text/html; charset=utf-8", std::string(web::kViewerHtml));
    if (target == "/viewer.js")
      return respond(req, http::status::ok, "text/javascript; charset=utf-8", std::string(web::kViewerJs));
    if (target == "/viewer.css")
      return respond(req, http::status::ok, "text/css; charset=utf-8", std::string(web::kViewerCss));
    if (target == "/dagre.js")
      return respond(req, http::status::ok, "text/javascript; charset=utf-8", std::string(web::kDagreJs));
    if (target == "/dagre.esm.js.LEGAL.txt")
      return respond(req, http::status::ok, "text/plain; charset=utf-8", std::string(web::kDagreLicense));
    if (target == "/api/view") return respond(req, http::status::ok, "application/json", server_.protocol.view_json());
    return respond(req, http::status::not_found, "text/plain", "not found: " + std::string(target) + "\n");
  }

  void respond(const http::request<http::string_body>& req, http::status status, std::string_view type,
               std::string body) {
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version());
    res->set(http::field::server, "safecass-viewer");
    res->set(http::field::content_type, std::string(type));
    res->set(http::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    res->set("Referrer-Policy", "no-referrer");
    res->set("Content-Security-Policy",
             "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; connect-src 'self'; "
             "base-uri 'none'; form-action 'none'; frame-ancestors 'none'");
    res->keep_alive(req.keep_alive());
    res->body() = std::move(body);
    res->prepare_payload();  // Content-Length of the body, for HEAD too
    if (req.method() == http::verb::head) res->body().clear();
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec) return;
      if (!res->keep_alive()) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        return;
      }
      self->read();
    });
  }

  beast::tcp_stream stream_;
  ServerCore& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

// ---- server ----------------------------------------------------------------------------------------

struct Server::Impl : ServerCore {
  using ServerCore::ServerCore;
};

AcceptBackoff::Step AcceptBackoff::failed(Clock::time_point now) noexcept {
  Step step{delay_, false, 0};
  delay_ = std::min(delay_ * 2, kMaxDelay);
  if (!last_log_ || now - *last_log_ >= kLogInterval) {
    step.log = true;
    step.not_logged = not_logged_;
    not_logged_ = 0;
    last_log_ = now;
  } else {
    ++not_logged_;
  }
  return step;
}

void ServerCore::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (ec == asio::error::operation_aborted || stopped) return;
      // Out of file descriptors (EMFILE) and the like: the pending connection stays in the
      // backlog, so accepting again at once fails again at once. Wait, and say so rarely.
      const AcceptBackoff::Step step = backoff.failed(AcceptBackoff::Clock::now());
      if (step.log) {
        log_line("accept: " + ec.message() + "; trying again in " + std::to_string(step.delay.count()) +
                 " ms, up to every " + std::to_string(AcceptBackoff::kMaxDelay.count()) + " ms" +
                 (step.not_logged == 0
                      ? std::string()
                      : " (" + std::to_string(step.not_logged) + " failed accepts not logged since the last line)"));
      }
      accept_timer.expires_after(step.delay);
      accept_timer.async_wait([this](beast::error_code e) {
        if (e || stopped) return;
        accept();
      });
      return;
    }
    backoff.succeeded();
    std::make_shared<HttpSession>(std::move(socket), *this)->read();
    accept();
  });
}

void ServerCore::schedule_poll() {
  timer.expires_at(timer.expiry() + std::chrono::milliseconds(options.poll_ms));
  timer.async_wait([this](beast::error_code ec) {
    if (ec || stopped) return;
    poll();
    // After a stall (a slow poll), start again from now instead of firing in a burst.
    if (timer.expiry() + std::chrono::milliseconds(options.poll_ms) < asio::steady_timer::clock_type::now()) {
      timer.expires_at(asio::steady_timer::clock_type::now());
    }
    schedule_poll();
  });
}

void ServerCore::poll() {
  std::string message;
  try {
    message = protocol.update(monotonic_ms());
  } catch (const std::exception& e) {
    log_line(std::string("error while polling the system: ") + e.what());
    return;
  }
  if (!message.empty()) broadcast(message);
}

void ServerCore::broadcast(const std::string& message) {
  auto shared = std::make_shared<const std::string>(message);
  std::erase_if(sessions, [](const std::weak_ptr<WebSocketSession>& w) { return w.expired(); });
  for (const auto& w : sessions) {
    if (auto s = w.lock()) s->send(shared);
  }
}

void ServerCore::shutdown() {
  if (stopped.exchange(true)) return;
  asio::post(ioc, [this] {
    beast::error_code ignored;
    acceptor.close(ignored);
    accept_timer.cancel();
    timer.cancel();
    signals.cancel(ignored);
    for (const auto& w : sessions) {
      if (auto s = w.lock()) s->close();
    }
    // Give the close frames a moment, then stop whatever is left.
    auto done = std::make_shared<asio::steady_timer>(ioc, std::chrono::milliseconds(200));
    done->async_wait([this, done](beast::error_code) { ioc.stop(); });
  });
}

Server::Server(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() = default;

Expected<std::unique_ptr<Server>> Server::open(ViewSource& source, const ProtocolOptions& protocol,
                                               const ServerOptions& options) {
  if (protocol.allow_write && protocol.token.empty())
    return fail(ErrorCode::InvalidArgument, "write access needs a token");
  if (options.poll_ms <= 0 || options.poll_ms > 1000)
    return fail(ErrorCode::InvalidArgument, "poll period must be 1 to 1000 ms");
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.bind, ec);
  if (ec) return fail(ErrorCode::InvalidArgument, "--bind: '" + options.bind + "' is not an IPv4 or IPv6 address");
  auto impl = std::make_shared<Impl>(source, protocol, options);
  const tcp::endpoint endpoint(address, options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl->acceptor.bind(endpoint, ec);
  if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return fail(ErrorCode::Io,
                "cannot listen on " + options.bind + ":" + std::to_string(options.port) + ": " + ec.message());
  }
  impl->port = impl->acceptor.local_endpoint().port();
  const std::string p = ":" + std::to_string(impl->port);
  const std::string host = address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
  impl->url = "http://" + host + p + "/";
  if (!address.is_unspecified()) {
    impl->allowed_hosts.insert(lower(host) + p);
    if (address.is_loopback()) {
      impl->allowed_hosts.insert("localhost" + p);
      impl->allowed_hosts.insert("127.0.0.1" + p);
      impl->allowed_hosts.insert("[::1]" + p);
    }
  }
  return std::unique_ptr<Server>(new Server(std::move(impl)));
}

std::uint16_t Server::port() const noexcept { return impl_->port; }

std::string Server::url() const { return impl_->url; }

void Server::run() {
  Impl& s = *impl_;
  if (s.options.handle_signals) {
    s.signals.add(SIGINT);
    s.signals.add(SIGTERM);
    s.signals.async_wait([&s](beast::error_code ec, int) {
      if (!ec) s.shutdown();
    });
  }
  s.accept();
  s.timer.expires_after(std::chrono::milliseconds(0));
  s.schedule_poll();
  s.ioc.run();
}

void Server::stop() { impl_->shutdown(); }

}  // namespace safecass::viewer
