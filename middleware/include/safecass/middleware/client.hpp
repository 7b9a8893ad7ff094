#pragma once
/// @file client.hpp
/// RemoteClient: the console's commands against a live coordinator process, through the
/// middleware (DESIGN §6 "against a live system through the middleware").
///
/// Usage:
/// ```
///   auto client = RemoteClient::connect({.ice = *parse_ice_endpoint("127.0.0.1:4061"),
///                                        .coordinator = "robot", .token = token});
///   if (!client) { print(client.error().message); return; }
///   auto states = (*client)->state_list("CONTROL");        // Expected<std::vector<introspect::StateRow>>
///   auto why = (*client)->explain("PENDANT");               // Expected<introspect::ExplainAnswer>
///   auto done = (*client)->apply(introspect::GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"});  // needs the token
/// ```
/// connect() finds the coordinator by listening to the heartbeats on IceStorm: one signed by that
/// coordinator's key (the system's keyring) gives its Control endpoint, which must be on this host
/// unless `insecure`, and which must prove itself alive (sign a nonce of the client's) before
/// anything else is sent to it. Requests and the token go only there.
///
/// Every call is a synchronous request/reply with a timeout. Errors carry the coordinator's
/// answer: Denied (a write without --allow-write or with a wrong token), NotFound / Parse /
/// InvalidArgument / InvalidState (bad names or arguments: nothing was changed), Io (the
/// coordinator cannot be reached or did not answer in time). Thread-safety: one thread at a time.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/introspect/query.hpp"
#include "safecass/middleware/node.hpp"

namespace safecass::middleware {

struct ClientOptions {
  IceEndpoint ice;          ///< IceStorm, to find the coordinator by its heartbeat
  std::string coordinator;  ///< the coordinator's name
  std::string token;        ///< the write token (from its token file); empty: read-only
  /// The read credential (from its read token file), sent with every request; the write token
  /// is sent as the read credential when this is empty.
  std::string read_token;
  /// The system's bus keys (keys.hpp); only the keyring is read. Empty: $SAFECASS_KEYS.
  std::string keys_dir;
  /// Mutual TLS; the certificate name defaults to "console".
  TlsOptions tls;
  /// Accept IceStorm or a coordinator that is not on this host without TLS.
  bool insecure = false;
  std::chrono::milliseconds timeout{2000};
  /// Where the client listens for the heartbeats and records IceStorm pushes to it. Empty: the
  /// address of this host that reaches IceStorm (127.0.0.1 when IceStorm is local), so that a
  /// console on another host than the broker works without one more option.
  std::string listen_host;
};

/// The SystemQuery of one live coordinator process (the read model's remote implementation):
/// every read is one request to the coordinator's Control object, answered by the coordinator's
/// own LocalQuery, so it carries every field an in-process answer has. follow() subscribes to the
/// coordinator's records on the events topic (pushed, never polled) and to its heartbeats: a
/// client holds only the keyring and cannot check a sealed batch, so it believes one once a
/// heartbeat of the process proven alive, signed with its key, lists the batch's digest, and
/// delivers its records in order and once (records travel once, one heartbeat late at most). What
/// was sent before it listened, and what was lost on the bus, are read from the coordinator's
/// history (Control::recordsSince, bounded reads) at the endpoint proven alive.
class RemoteClient final : public introspect::SystemQuery {
public:
  /// Errors: Io (IceStorm or the coordinator unreachable; no heartbeat from it within timeout).
  [[nodiscard]] static Expected<std::unique_ptr<RemoteClient>> connect(ClientOptions options);
  ~RemoteClient() override;
  RemoteClient(const RemoteClient&) = delete;
  RemoteClient& operator=(const RemoteClient&) = delete;

  /// The coordinator's name as it reports it.
  [[nodiscard]] Expected<std::string> coordinator();

  std::string name() const override;
  [[nodiscard]] Expected<introspect::ClockInfo> clock() override;
  [[nodiscard]] Expected<std::vector<introspect::StateRow>> state_list(std::string_view component = {}) override;
  [[nodiscard]] Expected<std::vector<introspect::HistoryEntry>> history(
      std::string_view scope, std::size_t last,
      introspect::HistoryFilter filter = introspect::HistoryFilter::All) override;
  [[nodiscard]] Expected<std::vector<introspect::HistoryEntry>> records_since(std::uint64_t seq,
                                                                              std::size_t max) override;
  [[nodiscard]] Expected<std::vector<introspect::FilterRow>> filter_list() override;
  [[nodiscard]] Expected<introspect::FilterInfo> filter_info(std::string_view name) override;
  [[nodiscard]] Expected<std::vector<introspect::EventRow>> event_list() override;
  [[nodiscard]] Expected<std::vector<introspect::ConnectionRow>> connection_list() override;
  [[nodiscard]] Expected<std::vector<introspect::ServiceRow>> service_list() override;
  [[nodiscard]] Expected<introspect::ExplainAnswer> explain(std::string_view address) override;
  [[nodiscard]] Expected<introspect::Names> names() override;
  [[nodiscard]] Expected<std::string> read(std::string_view name, const std::vector<std::string>& args) override;
  /// Errors: Io (IceStorm cannot be reached to subscribe).
  [[nodiscard]] Expected<std::unique_ptr<introspect::Subscription>> follow(introspect::RecordSink sink) override;
  /// Sends a write to the coordinator's Control with the token (a sample: refused here, see
  /// SystemQuery::apply).
  [[nodiscard]] Expected<void> apply(const introspect::Action& action) override;

  /// Records refused on the events topic (unauthenticated, forged, replayed or malformed) since
  /// connect(), and gaps filled from the coordinator's history.
  std::uint64_t records_refused() const;
  std::uint64_t gaps_filled() const;
  /// Records follow() delivered from the coordinator's history rather than from the stream.
  std::uint64_t records_read() const;

  struct Impl;

private:
  explicit RemoteClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::middleware
