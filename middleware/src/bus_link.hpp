#pragma once
// Internal: one member process's link to the bus, the same for the coordinator node and the
// supervisor (DESIGN §7 "The bus, precisely"). It keeps the connection to IceStorm: connects, and
// reconnects when IceStorm is lost; makes again every subscription IceStorm no longer holds; and
// reconnects when the process's own heartbeat stops coming back (its subscriptions do not work).
// It sends the process's heartbeat every period. Whenever what arrived meanwhile may be lost
// (connected, a subscription made again) it tells its owner, who asks for a republish: nothing
// is taken for current that may have been missed.

#include <Ice/Ice.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ice_sequences.hpp"  // before the generated header: its sequences' reader
#include "ice_util.hpp"
#include "safecass.h"
#include "sleeper.hpp"

namespace safecass::middleware {

/// What a BusLink needs of its owner.
struct BusLinkOptions {
  std::string who;                          ///< the prefix of its log lines ("middleware: robot", "supervisor")
  std::vector<std::string> publish_on;      ///< the topics the process publishes on (BusLink::publisher)
  std::size_t heartbeat_topic = 0;          ///< the index in `publish_on` of its own heartbeat topic
  std::chrono::milliseconds period{100};    ///< between two heartbeats
  std::string while_down;                   ///< what the process does meanwhile, said when IceStorm is lost
  std::function<wire::Signed()> heartbeat;  ///< the next signed heartbeat
  /// Connected, or subscriptions made again: what arrived meanwhile may be lost. Link thread;
  /// the publishers are set.
  std::function<void()> rejoined;
  std::function<void()> every_period;  ///< after each heartbeat sent (optional), link thread
  std::function<void(const std::string&)> log;
};

/// The heartbeats a process sent last, so that it knows its own when they come back without
/// checking their signatures (BusLink::heard_own). Thread-safe.
class SentHeartbeats {
public:
  static constexpr std::size_t kKept = 8;  ///< 0.8 s of heartbeats at the default period
  /// `m` is about to be sent; the oldest of those kept goes.
  void sent(const wire::Signed& m);
  /// Whether `m` equals one of those kept in every field.
  [[nodiscard]] bool holds(const wire::Signed& m) const;

private:
  mutable std::mutex mutex_;
  std::array<wire::Signed, kKept> kept_;
  std::size_t next_ = 0;    ///< the slot the next one takes
  std::size_t filled_ = 0;  ///< slots holding a heartbeat sent
};

class BusLink {
public:
  BusLink(std::shared_ptr<Ice::Communicator> ic, const IceEndpoint& ice, const TlsOptions& tls, BusLinkOptions options);
  ~BusLink() { stop(); }
  BusLink(const BusLink&) = delete;
  BusLink& operator=(const BusLink&) = delete;

  /// Subscribes `subscriber` to `topic` on every connection; before start().
  void subscribe_to(std::string topic, std::shared_ptr<Ice::ObjectPrx> subscriber) {
    link_.subscribe_to(std::move(topic), std::move(subscriber));
  }
  /// Starts the link thread: it connects, then beats every period until stop().
  void start();
  /// Stops and joins the link thread (before the communicator is destroyed).
  void stop() noexcept;

  /// The oneway publisher on `publish_on[topic]`; nullptr until connected. Any thread.
  [[nodiscard]] std::shared_ptr<Ice::ObjectPrx> publisher(std::size_t topic) const;
  /// A stream of `topics` was lost while its heartbeats came (any thread): the link thread
  /// subscribes to them again under new identities (Link::renew) at its next period. Said in the
  /// log once made, and every provider is asked to republish (BusLinkOptions::rejoined). `quiet`:
  /// a renewal repeated while a peer stays lost (Liveness::renew_due), which its owner says once
  /// per loss: neither said nor followed by a republish of every provider (the owner asks the
  /// lost peer once its heartbeats are believed again, as after any loss).
  void renew(const std::vector<std::string>& topics, bool quiet = false);
  /// Sending on the link failed (another thread): the link thread reconnects and resynchronises.
  void reconnect() noexcept { connected_.store(false); }
  /// Whether `m` is, byte for byte, one of the last heartbeats this link sent (SentHeartbeats; its
  /// dispatch thread). If so its subscriptions work (own_heartbeat_heard), and there is nothing
  /// else to read in it: its signature is not checked again. Anything else is checked as any
  /// heartbeat is; an older one of this run (late) is then heard as well.
  [[nodiscard]] bool heard_own(const wire::Signed& m);
  /// The process's own heartbeat of this run came back (its dispatch thread): its subscriptions work.
  void own_heartbeat_heard() noexcept { last_own_heartbeat_.store(steady_ns()); }

  [[nodiscard]] bool connected() const noexcept { return connected_.load(); }
  [[nodiscard]] std::uint64_t connects() const noexcept { return connects_.load(); }
  /// Subscriptions made again after IceStorm had lost them.
  [[nodiscard]] std::uint64_t resubscriptions() const noexcept { return resubscriptions_.load(); }
  /// Times IceStorm was pinged because the heartbeat sent a period before had not come back.
  [[nodiscard]] std::uint64_t pings() const noexcept { return pings_.load(); }

private:
  void loop();
  /// Connects; false (said, rate-limited) when IceStorm cannot be reached.
  bool connect();
  /// Until `d` has passed or stop().
  void sleep_for(std::chrono::milliseconds d);
  /// Of the subscriptions Link::check() made again, those that are not quiet renewals (renew()).
  std::vector<std::string> loud(std::vector<std::string> made);

  std::string where_;  ///< IceStorm's endpoint, as said in the log
  BusLinkOptions options_;
  Link link_;  ///< link thread only
  std::mutex renew_mutex_;
  std::vector<std::string> renew_;  ///< topics to subscribe to again (renew())
  std::vector<std::string> quiet_;  ///< of those, the ones renewed quietly and not yet made (renew_mutex_)
  mutable std::mutex publishers_mutex_;
  std::vector<std::shared_ptr<Ice::ObjectPrx>> publishers_;
  std::atomic<bool> running_{false};
  Sleeper sleeper_;  ///< the link thread's waits, ended by stop()
  std::atomic<bool> connected_{false};
  std::atomic<std::int64_t> last_own_heartbeat_{0};  ///< when an own heartbeat of this run last came back
  SentHeartbeats sent_;
  std::atomic<std::uint64_t> connects_{0};
  std::atomic<std::uint64_t> resubscriptions_{0};
  std::atomic<std::uint64_t> pings_{0};
  std::int64_t last_beat_sent_ = 0;  ///< link thread: when its last heartbeat was sent (0: none since connected)
  // Link thread only: how the failures to connect are said (once, then every 5 s with a count).
  std::uint64_t failed_connects_ = 0;
  std::int64_t last_down_report_ = 0;
  bool reported_down_ = false;
  std::int64_t connected_at_ = 0;
  std::thread thread_;
};

/// A typed publisher of one of a BusLink's topics, for a thread that publishes often: the typed
/// proxy is made again only when the link's publisher changed (a reconnection). One thread only.
template <class Prx>
class TypedPublisher {
public:
  TypedPublisher(const BusLink& link, std::size_t topic) : link_(link), topic_(topic) {}
  /// nullptr until the link is connected.
  [[nodiscard]] const std::shared_ptr<Prx>& get() {
    std::shared_ptr<Ice::ObjectPrx> now = link_.publisher(topic_);
    if (now != raw_) {
      raw_ = std::move(now);
      typed_ = raw_ == nullptr ? nullptr : Ice::uncheckedCast<Prx>(raw_);
    }
    return typed_;
  }

private:
  const BusLink& link_;
  std::size_t topic_;
  std::shared_ptr<Ice::ObjectPrx> raw_;
  std::shared_ptr<Prx> typed_;
};

}  // namespace safecass::middleware
