#pragma once
// Internal: Ice helpers shared by the node, the supervisor and the client. Only .cpp files of
// this module include it (public headers include no third-party headers).

#include <Ice/Ice.h>
#include <IceStorm/IceStorm.h>

#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ice_sequences.hpp"  // before the generated header: its sequences' reader
#include "safecass.h"
#include "safecass/core/coordinator.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/node.hpp"

namespace safecass::middleware {

/// State updates go to one topic per coordinator, "safecass.state.<coordinator>": a process
/// receives only the streams of the providers it holds, never its own.
inline constexpr const char* kStateTopic = "safecass.state";
inline std::string state_topic(std::string_view coordinator) {
  return std::string(kStateTopic) + "." + std::string(coordinator);
}
inline constexpr const char* kEventTopic = "safecass.events";
/// Heartbeats go to one topic per signer too, "safecass.heartbeat.<signer>" (a coordinator, or
/// the supervisor): a coordinator hears only itself (its own heartbeat coming back proves its
/// subscriptions work), the providers it holds and the supervisor; the supervisor hears every
/// coordinator of the system file. Deliveries grow with the connections, not with the square of
/// the members (docs/scaling.md).
inline constexpr const char* kHeartbeatTopic = "safecass.heartbeat";
inline std::string heartbeat_topic(std::string_view signer) {
  return std::string(kHeartbeatTopic) + "." + std::string(signer);
}
/// The topics on which a peer's messages reach a receiver: the supervisor's heartbeats, or a
/// coordinator's state and heartbeats. What a receiver subscribes to again when it holds the peer lost.
inline std::vector<std::string> peer_topics(std::string_view signer) {
  if (signer == kSupervisorSigner) return {heartbeat_topic(signer)};
  return {state_topic(signer), heartbeat_topic(signer)};
}
inline constexpr const char* kResyncTopic = "safecass.resync";
/// The subscriber categories of a tool's follower start with this (RemoteClient::follow).
inline constexpr std::string_view kFollowerCategory = "safecass-follow-";
/// The topics tools hear: the events and the heartbeats. A tool cannot reach the members' broker
/// (its certificate is refused there); each member links the topics of these it publishes on to
/// the topics of the same names at the tools' broker (tools_broker()), which forward what is
/// published to the tools' subscriptions. The state and resync topics stay among the members.
inline bool tools_hear(std::string_view topic) {
  return topic == kEventTopic || topic.starts_with(std::string(kHeartbeatTopic) + ".");
}

/// Every this many heartbeat periods (1 s at the default 100 ms) a process's link checks that
/// IceStorm still holds each of its subscriptions (Link::check); in between it pings IceStorm
/// only when the process's own heartbeat did not come back round.
/// A check is an update at IceStorm (a replicated one forwards it to its master): every 3 periods
/// it cost the broker half of its CPU at 50 coordinators (docs/scaling.md). A lost subscription
/// fails toward safe without it (a silent heartbeat or a stream behind counts as lost within the
/// loss bound); the check only bounds how long until the view recovers.
inline constexpr std::uint64_t kResubscribeCheckEvery = 10;
/// How long a subscription round takes with heartbeats every `period`: also how often a receiver
/// subscribes again, under new identities, to a peer it still holds lost (Liveness::renew_due).
constexpr std::chrono::nanoseconds subscription_round(std::chrono::milliseconds period) noexcept {
  return period * static_cast<std::int64_t>(kResubscribeCheckEvery);
}
/// The log line (without the process's prefix) for subscriptions Link::check made again.
std::string resubscribed_line(const std::vector<std::string>& topics);

/// A communicator that fails fast (short connect and invocation timeouts, no retries) so that a
/// dead IceStorm is noticed quickly; one dispatch thread keeps updates in order.
/// With `tls` enabled, IceSSL is loaded with the CA and the process's certificate, and every peer
/// must present a certificate signed by that CA (IceSSL.VerifyPeer=2).
/// With `ice` naming an IceGrid registry (a replicated IceStorm), its locator is the default one.
std::shared_ptr<Ice::Communicator> make_communicator(const TlsOptions& tls = {}, const IceEndpoint& ice = {});
/// The IceSSL properties of mutual TLS with `tls` (enabled): the CA, this process's certificate,
/// every peer verified. make_communicator sets them; a test's own communicator too.
void set_tls_properties(const Ice::PropertiesPtr& properties, const TlsOptions& tls);
/// Where a process that did not choose an address listens for what IceStorm pushes to it: the
/// address of this host that reaches `ice` (the interface facing the broker, never every
/// interface), or 127.0.0.1 when the broker is local or cannot be routed to (connecting then
/// fails with its own clear error).
std::string listen_host_towards(const IceEndpoint& ice);

/// "ssl" with TLS, else "tcp": the protocol of every endpoint the process creates or names.
inline std::string protocol(const TlsOptions& tls) { return tls.enabled() ? "ssl" : "tcp"; }
/// "SafecassIceStorm/TopicManager:tcp -h HOST -p PORT" (ssl with TLS; the instance_name() of a
/// named broker), or through the locator.
std::shared_ptr<IceStorm::TopicManagerPrx> topic_manager(const std::shared_ptr<Ice::Communicator>& ic,
                                                         const IceEndpoint& ice, const TlsOptions& tls = {});
/// Retrieves a topic, creating it when it does not exist yet.
std::shared_ptr<IceStorm::TopicPrx> topic(const std::shared_ptr<IceStorm::TopicManagerPrx>& manager,
                                          const std::string& name);
/// A proxy for `servant` under which a Link subscribes it, each subscription with an identity of
/// its own: the servant is the adapter's default servant of `category` (unique to it), so that an
/// identity can be replaced (Link::renew) without registering the servant again.
std::shared_ptr<Ice::ObjectPrx> add_subscriber(const std::shared_ptr<Ice::ObjectAdapter>& adapter,
                                               std::shared_ptr<Ice::Object> servant, const std::string& category);
/// Makes `from` (a topic of the members' broker) forward to its namesake at the broker `to` (the
/// tools' broker, or another host's broker), created there when missing, unless that link is in
/// place; a link to that topic elsewhere (its broker restarted on another port) is replaced.
/// Asynchronous, so that a broker out of reach never holds up a member: what fails is tried again
/// at the next round of Link::check.
void link_topic(const std::shared_ptr<IceStorm::TopicPrx>& from, const std::shared_ptr<IceStorm::TopicManagerPrx>& to,
                const std::string& name);
/// Subscribes `subscriber` oneway (IceStorm's default reliability): batched, in order over one
/// connection. A message the subscriber cannot decode fails there alone: IceStorm never learns of
/// it, so one bad message drops nobody's subscription (a twoway subscriber whose dispatch fails is
/// dropped). A loss shows as a gap in sequence numbers and is repaired by a resync. Returns true
/// when IceStorm did not hold the subscription (a new one), false when it was already there.
bool subscribe(const std::shared_ptr<IceStorm::TopicPrx>& topic, const std::shared_ptr<Ice::ObjectPrx>& subscriber);

/// The warning of a process whose key directory holds no TLS certificates (keys made by an
/// earlier `safecass keys`): IceStorm then admits any local process.
std::string plain_tcp_warning(const std::string& keys_dir);

wire::Level to_wire(State s) noexcept;
/// Errors: a value outside the enum (a malformed message).
bool from_wire(wire::Level l, State& out) noexcept;
/// The core's name of an outcome, empty for Outcome::None (the wire's "no outcome").
std::string_view outcome_text(Outcome o) noexcept;
std::int64_t steady_ns() noexcept;

}  // namespace safecass::middleware

namespace safecass::middleware {

/// A connection to IceStorm: the topics a process subscribes to and publishes on. connect() may
/// be called again after a failure (IceStorm restarted, a partition healed): it closes the old
/// connections, opens new ones, resubscribes and refreshes publishers.
class Link {
public:
  Link(std::shared_ptr<Ice::Communicator> ic, IceEndpoint ice, TlsOptions tls = {})
      : ic_(std::move(ic)), ice_(std::move(ice)), tls_(std::move(tls)) {}
  /// Registers a subscriber of `topic` (a proxy of add_subscriber(), used by every connect()).
  void subscribe_to(std::string topic, std::shared_ptr<Ice::ObjectPrx> subscriber) {
    subscriptions_.push_back(Subscription{std::move(topic), std::move(subscriber), nullptr, nullptr, {}});
  }
  /// Throws Ice exceptions when IceStorm cannot be reached.
  void connect(const std::vector<std::string>& publish_on);
  /// Removes every subscription of this link from IceStorm (a follower that stops); what IceStorm
  /// does not answer it drops by itself once delivery fails.
  void unsubscribe() noexcept;
  /// The oneway publisher of a topic given to connect().
  std::shared_ptr<Ice::ObjectPrx> publisher(const std::string& topic) const;
  /// Throws when IceStorm does not answer.
  void ping() const;
  /// Subscribes again to `topic` under a new identity: IceStorm lists subscriber identities to
  /// whoever may call the topic (not where they deliver), so another holder of a certificate can
  /// unsubscribe an identity and subscribe its own endpoint under it, and a subscription IceStorm
  /// holds is not proof that it reaches this process. The owner asks for it when a stream of the
  /// topic is lost (Liveness). check() reports it made, as any subscription made again.
  void renew(const std::string& topic);
  /// Called once a heartbeat period: pings IceStorm when `ping_broker` (the caller's own last
  /// heartbeat has not come back: one that came back round proved the link), and every
  /// kResubscribeCheckEvery-th call also asks IceStorm to make again each subscription it no
  /// longer holds. The asking is asynchronous (a replicated IceStorm answers it only once its
  /// replicas have a master, which after the master's death takes seconds, and the caller's
  /// heartbeats must not wait for that); a later call returns the topics whose subscription was
  /// made again (empty: all were there; the caller resynchronises otherwise). IceStorm drops a
  /// subscriber whose delivery failed or timed out (a process starved or stopped for longer than
  /// IceStorm's send timeout), and a subscription can be removed from outside; without this check
  /// such a process would go on unaware that nothing reaches it. The same rounds make again each
  /// link to the tools' broker and to the other hosts' brokers that is missing (a tool may destroy
  /// a topic at the tools' broker; a broker restarted empty holds no topic). Throws Ice
  /// exceptions when IceStorm cannot be reached or refuses the subscription.
  std::vector<std::string> check(bool ping_broker);

private:
  std::shared_ptr<Ice::Communicator> ic_;
  IceEndpoint ice_;
  TlsOptions tls_;
  std::shared_ptr<IceStorm::TopicManagerPrx> manager_;
  struct Subscription {
    std::string topic;
    std::shared_ptr<Ice::ObjectPrx> servant;             ///< add_subscriber()'s proxy: its category
    std::shared_ptr<Ice::ObjectPrx> subscriber;          ///< the identity subscribed now (renew())
    std::shared_ptr<IceStorm::TopicPrx> proxy;           ///< set by connect()
    std::future<std::shared_ptr<Ice::ObjectPrx>> check;  ///< a pending subscription, if any
  };
  /// Subscribes `s` under a new identity, and drops the old one from the topic (whoever's
  /// endpoint it delivers to now). Asynchronous when `async` (the answer is taken by check()),
  /// else waits (connect()).
  void renew(Subscription& s, bool async);
  std::vector<Subscription> subscriptions_;
  std::vector<std::pair<std::string, std::shared_ptr<Ice::ObjectPrx>>> publishers_;
  /// A broker the topics this process publishes on are linked to (link_topic()): its tools'
  /// broker, for the topics tools hear (tools_hear()); with one broker per host, each other host's
  /// members' broker (every topic) and tools' broker. Made again with the subscriptions' checks.
  struct LinkTarget {
    std::shared_ptr<IceStorm::TopicManagerPrx> manager;
    bool tools_only = false;  ///< only the topics tools hear
  };
  void make_links();
  std::vector<LinkTarget> targets_;
  std::vector<std::pair<std::string, std::shared_ptr<IceStorm::TopicPrx>>> linked_;  ///< published on
  std::uint64_t checks_ = 0;
  std::uint64_t generation_ = 0;  ///< connect() attempts: each on connections of its own
};

}  // namespace safecass::middleware
