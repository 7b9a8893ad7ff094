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
///   auto states = (*client)->state_list("CONTROL");        // Expected<std::vector<StateRow>>
///   auto why = (*client)->explain("PENDANT");               // Expected<std::vector<Explanation>>
///   auto done = (*client)->generate("EVT_FORCE_ERROR", "JR3.s_A");  // a write: needs the token
/// ```
/// connect() finds the coordinator by listening to the heartbeats on IceStorm: the first one
/// signed by that coordinator's key (the system's keyring) gives its Control endpoint, which must
/// be on this host unless `insecure`. Requests and the token go only there.
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
#include "safecass/middleware/node.hpp"

namespace safecass::middleware {

struct ClientOptions {
  IceEndpoint ice;           ///< IceStorm, to find the coordinator by its heartbeat
  std::string coordinator;   ///< the coordinator's name
  std::string token;         ///< the write token (from its token file); empty: read-only
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
};

/// One machine, service or component state (`state list`).
struct StateRow {
  std::string address;
  std::string kind;          ///< component, s_F, s_A, s_P, s_R, s_S
  State state = State::Normal;
  std::string outstanding;   ///< outstanding event, empty when Normal
};

/// One history record (`state history`, `event history`).
struct HistoryRow {
  std::uint64_t seq = 0;
  Time time{};
  std::string kind;          ///< event, transition, component-transition, reset, injection
  std::string outcome;
  std::string address;
  std::string event;
  State from = State::Normal, to = State::Normal, level = State::Normal;
  bool mirror = false;
  std::string root_event, root_origin;
  std::string text;
};

struct FilterRow {
  std::string name, type, target, execution, detection;
  bool enabled = true, detected = false;
  std::vector<std::string> inputs, outputs;
};

struct ParamRow {
  std::string name, type, value, default_value, doc;
};

struct FilterDetails {
  FilterRow filter;          ///< name empty when the answer describes a filter type
  std::string doc;
  std::uint64_t missed_samples = 0;
  std::vector<ParamRow> params;
};

struct EventRow {
  std::string name;
  int severity = 0;
  bool onset = true;
  std::vector<std::string> transitions;
  std::string completes;
  bool latched = false;
  std::string hazard, description;
};

struct ConnectionRow {
  std::string required, provided;
  bool remote = false;       ///< the provider runs in another process
};

struct ServiceRow {
  std::string address;       ///< C.s_S.p
  State state = State::Normal;
  std::string propagate;     ///< Warning or Error
  std::vector<std::string> depends_on;
};

class RemoteClient {
public:
  /// Errors: Io (IceStorm or the coordinator unreachable; no heartbeat from it within timeout).
  static Expected<std::unique_ptr<RemoteClient>> connect(ClientOptions options);
  ~RemoteClient();
  RemoteClient(const RemoteClient&) = delete;
  RemoteClient& operator=(const RemoteClient&) = delete;

  /// The coordinator's name as it reports it.
  Expected<std::string> coordinator();
  Expected<std::vector<StateRow>> state_list(const std::string& component = {});
  Expected<std::vector<HistoryRow>> state_history(const std::string& address, int last = 20);
  Expected<std::vector<FilterRow>> filter_list();
  Expected<FilterDetails> filter_info(const std::string& name);
  Expected<void> filter_inject(const std::string& filter, const std::vector<std::vector<double>>& samples);
  Expected<void> filter_dinject(const std::string& signal, const std::vector<std::vector<double>>& samples);
  /// `text`: one sample per line, numbers separated by spaces or commas ('#' comments).
  Expected<void> filter_dinload(const std::string& signal, const std::string& text);
  Expected<std::vector<EventRow>> event_list();
  Expected<std::vector<HistoryRow>> event_history(int last = 20);
  Expected<void> generate(const std::string& event, const std::string& target);
  Expected<void> broadcast(const std::string& event);
  Expected<std::vector<ConnectionRow>> connection_list();
  Expected<std::vector<ServiceRow>> service_list();
  Expected<void> reset(const std::string& target, const std::string& who, const std::string& why);
  /// Each active condition at `address` with its root cause and hop path (Explanation::path).
  Expected<std::vector<Explanation>> explain(const std::string& address);

  struct Impl;

private:
  explicit RemoteClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::middleware
