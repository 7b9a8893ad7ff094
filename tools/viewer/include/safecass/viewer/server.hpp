#pragma once
/// @file server.hpp
/// The viewer's HTTP + WebSocket server (Boost.Beast, one thread). It serves the page compiled
/// into the binary (GET /, /viewer.js, /viewer.css), answers GET /api/view with the VIEW object,
/// and speaks the protocol of protocol.hpp on the WebSocket at /ws: a hello when a page connects,
/// then an update pushed to every page within one poll period (10 ms) of a change.
///
/// Security: it binds 127.0.0.1 unless told otherwise; with a loopback address it only answers
/// requests whose Host is that address or localhost with the right port (against DNS
/// rebinding), and a WebSocket whose Origin is not the page's own is refused. Write requests are
/// checked by the Protocol (write access and token). A page that does not read its updates is
/// disconnected rather than buffered without limit.
///
/// Resources: when accept() fails (no file descriptor left), it waits before trying again
/// (AcceptBackoff) and logs the failure at most once every 10 s.
///
/// Lifecycle: construct (binds and listens: port() is known), then run() on one thread until
/// stop() is called from any thread (or SIGINT/SIGTERM when handle_signals is set).

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "safecass/core/expected.hpp"
#include "safecass/viewer/protocol.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

/// What the server does when accept() fails, e.g. when the process has no file descriptor left
/// (EMFILE): it waits before trying again instead of retrying at once (which would spin a core
/// and flood the log while the error lasts). The wait is 10 ms, doubling after each failure up to
/// 1 s, and back to 10 ms once a connection is accepted. A failure is logged at most once every
/// 10 s, with the number of failures not logged since the line before.
class AcceptBackoff {
public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kFirstDelay{10};
  static constexpr std::chrono::milliseconds kMaxDelay{1000};
  static constexpr std::chrono::seconds kLogInterval{10};

  struct Step {
    std::chrono::milliseconds delay;  ///< how long to wait before accepting again
    bool log;                         ///< whether to log this failure
    std::uint64_t not_logged;         ///< with log: failures not logged since the last line
  };
  /// A failed accept at `now`.
  Step failed(Clock::time_point now) noexcept;
  /// A connection was accepted: the next failure waits kFirstDelay again.
  void succeeded() noexcept { delay_ = kFirstDelay; }

private:
  std::chrono::milliseconds delay_ = kFirstDelay;
  std::optional<Clock::time_point> last_log_;
  std::uint64_t not_logged_ = 0;
};

struct ServerOptions {
  std::string bind = "127.0.0.1";  ///< IPv4 or IPv6 address
  std::uint16_t port = 8765;       ///< 0: pick a free port
  int poll_ms = 10;                ///< how often the source is polled
  bool handle_signals = false;     ///< stop on SIGINT / SIGTERM
  std::size_t max_queued = 512;    ///< messages waiting for a slow page before it is dropped
};

class Server {
public:
  /// Binds and listens. Errors: InvalidArgument (bad address), Io (cannot bind: the port is in
  /// use or not allowed). `source` must outlive the server.
  [[nodiscard]] static Expected<std::unique_ptr<Server>> open(ViewSource& source, const ProtocolOptions& protocol,
                                                              const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port actually bound.
  std::uint16_t port() const noexcept;
  /// "http://127.0.0.1:PORT/".
  std::string url() const;
  /// Serves until stop(). Call from one thread only.
  void run();
  /// Thread-safe; run() returns soon after.
  void stop();

private:
  struct Impl;
  explicit Server(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace safecass::viewer
