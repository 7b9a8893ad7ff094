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
/// Lifecycle: construct (binds and listens: port() is known), then run() on one thread until
/// stop() is called from any thread (or SIGINT/SIGTERM when handle_signals is set).

#include <cstdint>
#include <memory>
#include <string>

#include "safecass/core/expected.hpp"
#include "safecass/viewer/protocol.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

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
  static Expected<std::unique_ptr<Server>> open(ViewSource& source, const ProtocolOptions& protocol,
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

/// A token for write access: 32 random bytes as 64 hex digits (from the operating system's
/// random source). Errors: Io when no random source is available.
Expected<std::string> make_token();

/// Writes `token` to a new file readable by its owner alone (mode 0600) in a new private
/// directory under `dir` (default: $TMPDIR or /tmp) and returns the file's path. The caller
/// removes it with remove_token_file(). Errors: Io.
Expected<std::string> write_token_file(const std::string& token, const std::string& dir = {});
/// Removes the file and its directory; ignores errors.
void remove_token_file(const std::string& path) noexcept;

}  // namespace safecass::viewer
