#pragma once
/// @file node.hpp
/// A coordinator process on the middleware (DESIGN §4): CoordinatorNode connects one Coordinator
/// (and its Monitor) to ZeroC IceStorm. It
/// - publishes, for every provided interface of the local components, a full-state update (the
///   roots active at s_S.p with their hop paths) whenever that set changes — the interfaces that
///   changed since the last publishing cycle go out together in one message on this
///   coordinator's state topic — plus every record of the observer stream (batched, after the
///   state) and a heartbeat;
/// - applies the updates of the remote providers this coordinator's components require
///   (Coordinator::apply_remote), checking sequence numbers and asking for a republish (resync)
///   when it detects a loss, a provider restart or a reconnection;
/// - serves the remote operations of the console (state, filter, event, connection, service,
///   reset, explain); write operations need --allow-write and the token.
///
/// Threads: the coordinator's threads only copy records into a bounded queue (never the network);
/// a publisher thread turns them into messages; a link thread (re)connects to IceStorm, sends
/// heartbeats and watches that its own heartbeat comes back; Ice's dispatch thread applies
/// incoming updates and serves requests. Local safety never waits on the network: while IceStorm
/// is down everything local keeps working and the node reconnects and resynchronises when it
/// returns.
///
/// Lifecycle: configure the coordinator (spec::instantiate + connect_remote_providers), create
/// the node, start(), ... , stop() (or the destructor), which shuts the Ice communicator down.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

/// Where a process finds IceStorm: "HOST:PORT", the TopicManager endpoint of one IceStorm, or
/// "locator:HOST:PORT", the locator of the IceGrid registry of a replicated IceStorm
/// (`scripts/start-icestorm --replicas N`, docs/deployment.md "A replicated broker"), or
/// "NAME=HOST:PORT", a broker named for its host (`scripts/start-icestorm --name NAME`), and
/// "NAME=HOST:PORT,PEER=HOST:PORT,...", one broker per host: this host's first, then the other
/// hosts' (docs/deployment.md "One broker per host"). Host defaults to 127.0.0.1.
struct IceEndpoint {
  std::string host = "127.0.0.1";
  int port = 0;
  bool locator = false;  ///< host:port is an IceGrid registry, not an IceStorm
  bool tools = false;    ///< the tools' broker (tools_broker()), not the members'
  /// A named broker's name: its instance is kIceStormInstance + "." + name (its tools' broker's
  /// kToolStormInstance + "." + name). Empty: the one broker, kIceStormInstance. With one broker
  /// per host each broker is named, differently: IceStorm tells topics (and links between them)
  /// apart by identity, which is the instance name and the topic's name.
  std::string name;
  /// One broker per host: the other hosts' members' brokers. A member links each topic it
  /// publishes on at its own broker to the topic of that name at each of them (and, for the topics
  /// tools hear, at their tools' brokers), so that a host cut off holds up no other host's messages.
  std::vector<IceEndpoint> peers;
};
/// The instance name of the broker `ice` names (a members' or a tools' broker).
[[nodiscard]] std::string instance_name(const IceEndpoint& ice);
/// The tools' broker of the system whose members' broker is `members`: the second IceStorm that
/// scripts/start-icestorm runs beside the members' (instance kToolStormInstance, on the next port,
/// or through the same locator). The members' broker refuses the tools' certificate; the topics
/// tools hear are linked from it to the tools' broker (docs/security.md "Rights at the broker").
[[nodiscard]] IceEndpoint tools_broker(IceEndpoint members);
/// Parses "HOST:PORT", "PORT", "locator:HOST:PORT", "NAME=HOST:PORT" or
/// "NAME=HOST:PORT,PEER=HOST:PORT,..." (with peers every broker is named, each name and address
/// once; a name is letters, digits, '-' and '_'). Errors: Parse (with what was wrong).
[[nodiscard]] Expected<IceEndpoint> parse_ice_endpoint(std::string_view whole);
/// The text parse_ice_endpoint reads: "HOST:PORT", "locator:HOST:PORT" or "NAME=HOST:PORT,...".
std::string to_string(const IceEndpoint& ice);

/// Mutual TLS (IceSSL) on every connection of a process: to IceStorm, from IceStorm to its
/// subscribers, and to and from Control and Alive endpoints (docs/security.md). `dir` holds the
/// system's `ca.pem` and this process's `NAME.pem` / `NAME.key` (`safecass keys` makes them in the
/// key directory); every peer must present a certificate signed by that CA. Empty `dir`: plain TCP,
/// loopback only unless --insecure.
struct TlsOptions {
  std::string dir;
  std::string name;  ///< the certificate to present (NAME.pem, NAME.key)
  bool enabled() const noexcept { return !dir.empty(); }
};

/// The transport of the process that presents certificate `name`: `given` when it names a
/// directory (--tls DIR), else the key directory `keys_dir` when it holds the system's CA
/// (`ca.pem`): members only at the broker by default. Else plain TCP (keys made without
/// certificates, by an earlier `safecass keys`).
[[nodiscard]] TlsOptions tls_from_keys(const std::string& keys_dir, TlsOptions given, std::string_view name);

/// Checks the TLS files of `tls` (when enabled) and that `hosts` are loopback unless TLS or
/// `insecure`. `who` names the caller in the message. Errors: InvalidArgument, NotFound.
[[nodiscard]] Expected<void> check_transport(std::string_view who, const TlsOptions& tls, bool insecure,
                                             std::initializer_list<std::string_view> hosts);

/// The host's monotonic clock (CLOCK_MONOTONIC, epoch: boot), the same in every process of the
/// host: root times and latencies can be compared across the processes of one machine.
class HostClock final : public Clock {
public:
  Time now() const noexcept override {
    return std::chrono::duration_cast<Time>(std::chrono::steady_clock::now().time_since_epoch());
  }
};

/// The IceStorm instance name scripts/start-icestorm configures.
inline constexpr std::string_view kIceStormInstance = "SafecassIceStorm";
/// The instance name of the tools' broker (tools_broker()).
inline constexpr std::string_view kToolStormInstance = "SafecassToolStorm";
/// What --ice starts with when it names an IceGrid registry: "locator:HOST:PORT".
inline constexpr std::string_view kLocatorPrefix = "locator:";

/// The default NodeOptions::max_message_bytes: Ice.MessageSizeMax (4096 KiB, set in every
/// SAFECASS process and in scripts/start-icestorm's IceStorm) less 64 KiB for what is added to a
/// body on its way (the signature, the Signed envelope, Ice's request headers).
inline constexpr std::size_t kDefaultMaxMessageBytes = std::size_t{4096 - 64} * 1024;

/// Declares, in `coordinator`, every provided interface of another coordinator of `system` that a
/// component of `coordinator_name` requires (Coordinator::add_remote_provided, with the
/// provider's propagation level) and makes those connections. Call after spec::instantiate(...,
/// coordinator_name). Errors: NotFound (no such coordinator), as the coordinator reports.
[[nodiscard]] Expected<void> connect_remote_providers(const spec::SystemSpec& system, std::string_view coordinator_name,
                                                      Coordinator& coordinator);

struct NodeOptions {
  IceEndpoint ice;                        ///< IceStorm
  std::string listen_host = "127.0.0.1";  ///< the node's own endpoint (subscribers, Control)
  int control_port = 0;                   ///< 0: any free port (advertised in the heartbeat)
  std::chrono::milliseconds heartbeat{100};
  bool allow_write = false;  ///< accept write operations
  std::string token;         ///< the secret write requests must carry
  /// When not empty, reads (state, history, filters, events, connections, services, explain)
  /// must carry this credential (or the write token); empty: reads are open to local clients.
  std::string read_token;
  /// The system's bus keys (keys.hpp): this node signs with DIR/<coordinator>.secret and checks
  /// every message it receives against DIR/keyring. Empty: $SAFECASS_KEYS.
  std::string keys_dir;
  /// A provider coordinator whose heartbeat stopped for this long is lost (EVT_COORDINATOR_LOST
  /// on every required interface it feeds); likewise the supervisor (EVT_SUPERVISOR_LOST on s_F).
  /// Zero: 3 heartbeat periods.
  std::chrono::milliseconds lost_after{0};
  /// The largest body this node sends in one message: the Ice encoding of one `updates` or
  /// `records` batch, measured before it is signed (bytes). A batch over it is split; a state
  /// update too large on its own goes out with as many of its roots as fit, the most severe first
  /// (a client's view never gets better than the provider's), and an event record too large on
  /// its own with its text cut; each is logged and counted (NodeStats::oversized_messages,
  /// roots_truncated). A message over Ice.MessageSizeMax would be dropped by IceStorm unseen.
  std::size_t max_message_bytes = kDefaultMaxMessageBytes;
  /// Mutual TLS; the certificate name defaults to the coordinator's name.
  TlsOptions tls;
  /// Accept an IceStorm or listening endpoint that is not loopback without TLS (docs/security.md).
  bool insecure = false;
  /// How remote tools are told to read this coordinator's times (introspect::ClockInfo): the
  /// host's monotonic clock (HostClock, shown as wall-clock time), or simulated time with its tick,
  /// scenario and duration (a node over a scenario run, shown as scenario seconds). The name is
  /// the node's.
  introspect::LocalOptions clock{{}, introspect::TimeBase::Host, 0.0, {}, 0.0};
  /// Receives every log line (errors about bad messages, reconnections). Default: stderr.
  std::function<void(const std::string&)> log;
};

/// Counters, readable at any time (thread-safe).
struct NodeStats {
  std::uint64_t updates_published = 0;         ///< interface full states sent (each differs from the last one sent)
  std::uint64_t state_messages_published = 0;  ///< Ice messages carrying them (one per publishing cycle)
  std::uint64_t updates_applied = 0;
  std::uint64_t updates_rejected = 0;  ///< malformed, unknown interface or stale sequence number
  std::uint64_t updates_missed = 0;    ///< gaps seen in sequence numbers
  std::uint64_t events_published = 0;
  std::uint64_t event_messages_published = 0;  ///< Ice messages carrying the event records
  std::uint64_t events_dropped = 0;            ///< observer queue overflow (never silent: counted here)
  std::uint64_t resyncs_requested = 0;
  std::uint64_t connects = 0;  ///< successful (re)connections to IceStorm
  /// Subscriptions IceStorm no longer held (dropped as undeliverable, or removed from outside),
  /// noticed within kResubscribeCheckEvery heartbeat periods and made again, with a resync.
  std::uint64_t resubscriptions = 0;
  /// Times IceStorm was pinged because this process's heartbeat had not come back round within a
  /// period (a healthy link costs none: the echo proves the whole way works).
  std::uint64_t broker_pings = 0;
  std::uint64_t messages_refused = 0;  ///< unauthenticated, forged, replayed or malformed bus messages
  std::uint64_t providers_lost = 0;    ///< times a provider coordinator was declared lost
  std::uint64_t duplicates_seen = 0;   ///< heartbeats of another process using this node's name
  /// State updates and event records too large for one message on their own
  /// (NodeOptions::max_message_bytes): sent cut down (roots left out, text cut), each logged. A
  /// record too large even without its text is dropped and also counted in events_dropped.
  std::uint64_t oversized_messages = 0;
  std::uint64_t roots_truncated = 0;  ///< roots left out of those state updates (the least severe)
  std::uint64_t updates_unproven =
      0;  ///< state updates of a provider process not proven alive yet (dropped; taken from its republish once proven)
  bool connected = false;
};

class CoordinatorNode {
public:
  /// `coordinator`, `monitor`, `registry` and `system` must outlive the node; `coordinator_name`
  /// names this process in the system's "coordinators". Nothing touches the network before
  /// start(). Errors: NotFound (unknown coordinator name, no keys), InvalidArgument (bad options,
  /// a non-loopback endpoint without `insecure`), Denied/Parse/Io (the keys, as keys.hpp says).
  [[nodiscard]] static Expected<std::unique_ptr<CoordinatorNode>> create(Coordinator& coordinator, Monitor& monitor,
                                                                         const FilterRegistry& registry,
                                                                         const spec::SystemSpec& system,
                                                                         std::string coordinator_name,
                                                                         NodeOptions options);
  ~CoordinatorNode();
  CoordinatorNode(const CoordinatorNode&) = delete;
  CoordinatorNode& operator=(const CoordinatorNode&) = delete;

  /// Creates the Ice communicator and its adapter and starts the threads; the node connects to
  /// IceStorm in the background (and keeps retrying). Errors: Io (the adapter cannot listen).
  [[nodiscard]] Expected<void> start();
  /// Stops the threads and shuts the communicator down. Idempotent.
  void stop() noexcept;

  NodeStats stats() const;
  /// The stringified proxy of this node's Control object (empty before start()).
  std::string control_proxy() const;

  struct Impl;

private:
  explicit CoordinatorNode(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::middleware
