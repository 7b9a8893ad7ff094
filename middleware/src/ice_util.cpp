#include "ice_util.hpp"

#include <IceSSL/IceSSL.h>
#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "safecass/middleware/keys.hpp"

namespace safecass::middleware {

TlsOptions tls_from_keys(const std::string& keys_dir, TlsOptions given, std::string_view name) {
  struct stat st {};
  if (!given.enabled() && ::stat((keys_dir + "/ca.pem").c_str(), &st) == 0) given.dir = keys_dir;
  if (given.enabled() && given.name.empty()) given.name = std::string(name);
  return given;
}

[[nodiscard]] Expected<void> check_transport(std::string_view who, const TlsOptions& tls, bool insecure,
                                             std::initializer_list<std::string_view> hosts) {
  if (tls.enabled()) {
    for (const std::string& file :
         {tls.dir + "/ca.pem", tls.dir + "/" + tls.name + ".pem", tls.dir + "/" + tls.name + ".key"}) {
      struct stat st {};
      if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        return fail(ErrorCode::NotFound,
                    std::string(who) + ": TLS: " + file +
                        " is missing (`safecass keys SYSTEM --out DIR` makes the system's certificates)");
      }
    }
    // A private key others can read is no longer private: refused, as a member's secret is.
    const std::string key = tls.dir + "/" + tls.name + ".key";
    struct stat st {};
    if (::stat(key.c_str(), &st) == 0 && (st.st_uid != ::geteuid() || (st.st_mode & 077) != 0)) {
      return fail(ErrorCode::Denied,
                  std::string(who) + ": TLS: " + key + ": a private key must be owned by its user and have mode 0600");
    }
    return {};
  }
  if (insecure) return {};
  for (std::string_view host : hosts) {
    if (!is_loopback_host(host)) {
      return fail(
          ErrorCode::InvalidArgument,
          std::string(who) + ": '" + std::string(host) +
              "' is not a loopback address and the bus would cross "
              "the network unencrypted: use keys with the system's certificates (`safecass keys SYSTEM --out DIR`, "
              "mutual TLS, docs/security.md), or --insecure to accept that");
    }
  }
  return {};
}

}  // namespace safecass::middleware

namespace safecass::middleware {

std::string listen_host_towards(const IceEndpoint& ice) {
  if (is_loopback_host(ice.host)) return "127.0.0.1";
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(ice.host.c_str(), std::to_string(ice.port).c_str(), &hints, &found) != 0 || found == nullptr)
    return "127.0.0.1";
  std::string out = "127.0.0.1";
  // A UDP socket "connected" to the broker sends nothing; the kernel picks the route and so the
  // local address.
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in local{};
  socklen_t size = sizeof local;
  char text[INET_ADDRSTRLEN] = {};
  if (fd >= 0 && ::connect(fd, found->ai_addr, found->ai_addrlen) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &size) == 0 &&
      ::inet_ntop(AF_INET, &local.sin_addr, text, sizeof text) != nullptr)
    out = text;
  if (fd >= 0) ::close(fd);
  ::freeaddrinfo(found);
  return out;
}

std::string plain_tcp_warning(const std::string& keys_dir) {
  return "no TLS certificates in " + keys_dir +
         " (ca.pem): the bus runs over plain TCP and IceStorm admits any local process; make the keys again "
         "with `safecass keys SYSTEM --out DIR --replace` and start IceStorm with --keys DIR (docs/security.md)";
}

void set_tls_properties(const Ice::PropertiesPtr& properties, const TlsOptions& tls) {
  static const bool registered = [] {
    Ice::registerIceSSL(false);  // linked in; loaded only by the property below
    return true;
  }();
  (void)registered;
  properties->setProperty("Ice.Plugin.IceSSL", "IceSSL:createIceSSL");
  properties->setProperty("IceSSL.DefaultDir", tls.dir);
  properties->setProperty("IceSSL.CAs", "ca.pem");
  properties->setProperty("IceSSL.CertFile", tls.name + ".pem");
  properties->setProperty("IceSSL.KeyFile", tls.name + ".key");
  properties->setProperty("IceSSL.VerifyPeer", "2");  // mutual: every peer shows a CA-signed certificate
  properties->setProperty("IceSSL.Protocols", "tls1_2, tls1_3");
}

std::shared_ptr<Ice::Communicator> make_communicator(const TlsOptions& tls, const IceEndpoint& ice) {
  Ice::InitializationData init;
  init.properties = Ice::createProperties();
  if (tls.enabled()) set_tls_properties(init.properties, tls);
  if (ice.locator) {
    // IceStorm's proxies (topics, publishers) name replica groups; the registry resolves them.
    // Every process takes the replicas in the registry's priority order, so all publish to the
    // same one while it lives and move to the next together; endpoints are asked again every
    // 2 s, so a replica restarted on another port is found.
    init.properties->setProperty("Ice.Default.Locator", "IceGrid/Locator:" + protocol(tls) + " -h " + ice.host +
                                                            " -p " + std::to_string(ice.port) + " -t 2000");
    init.properties->setProperty("Ice.Default.EndpointSelection", "Ordered");
    init.properties->setProperty("Ice.Default.LocatorCacheTimeout", "2");
  }
  init.properties->setProperty("Ice.Default.Host", "127.0.0.1");
  // A TLS handshake costs a few round trips and some CPU: give it longer on a loaded machine. With
  // replicas, a connection attempt to one on a host cut off must give up well within a call's
  // 2 s, so that the same call still reaches the next replica.
  init.properties->setProperty("Ice.Override.ConnectTimeout", ice.locator ? "700" : tls.enabled() ? "2000" : "500");
  init.properties->setProperty("Ice.Default.InvocationTimeout", "2000");
  // Closing a connection waits for the peer to acknowledge, by default up to the endpoint's
  // timeout (60 s): a process stopping (a console quitting) beside a stalled peer would wait that
  // long in Communicator::destroy. One second is enough for a live peer on any of our links.
  init.properties->setProperty("Ice.Override.CloseTimeout", "1000");
  init.properties->setProperty("Ice.RetryIntervals", "-1");
  init.properties->setProperty("Ice.Warn.Connections", "0");
  // A message that fails to dispatch is counted and logged, rate-limited, by the servant's Guard
  // (receiver.hpp): Ice's own warning would print a line for each one of a flood.
  init.properties->setProperty("Ice.Warn.Dispatch", "0");
  init.properties->setProperty("Ice.ThreadPool.Server.Size", "1");
  init.properties->setProperty("Ice.ThreadPool.Server.SizeMax", "1");
  // Answers to asynchronous calls (a proof of life, a subscription check) run their callbacks on
  // the client pool, and a callback may itself send (a proof taken asks the peer to republish).
  // That send can need the pool (a connection to establish, the locator to ask): with one thread,
  // which the callback holds, it waited out its timeout while nothing else was read — a stall of
  // every delivery for 1-2 s. The pool grows instead (docs/scaling.md).
  init.properties->setProperty("Ice.ThreadPool.Client.Size", "1");
  init.properties->setProperty("Ice.ThreadPool.Client.SizeMax", "4");
  init.properties->setProperty("Ice.ACM.Client.Timeout", "0");
  init.properties->setProperty("Ice.MessageSizeMax", "4096");
  return Ice::initialize(init);
}

std::shared_ptr<IceStorm::TopicManagerPrx> topic_manager(const std::shared_ptr<Ice::Communicator>& ic,
                                                         const IceEndpoint& ice, const TlsOptions& tls) {
  // Replicated: the topic manager's well-known object, found through the communicator's locator.
  const std::string manager = instance_name(ice) + "/TopicManager";
  const std::string text =
      ice.locator ? manager
                  : manager + ":" + protocol(tls) + " -h " + ice.host + " -p " + std::to_string(ice.port) + " -t 2000";
  return Ice::uncheckedCast<IceStorm::TopicManagerPrx>(ic->stringToProxy(text));
}

std::shared_ptr<IceStorm::TopicPrx> topic(const std::shared_ptr<IceStorm::TopicManagerPrx>& manager,
                                          const std::string& name) {
  try {
    return manager->retrieve(name);
  } catch (const IceStorm::NoSuchTopic&) {
    try {
      return manager->create(name);
    } catch (const IceStorm::TopicExists&) {
      return manager->retrieve(name);
    }
  }
}

std::shared_ptr<Ice::ObjectPrx> add_subscriber(const std::shared_ptr<Ice::ObjectAdapter>& adapter,
                                               std::shared_ptr<Ice::Object> servant, const std::string& category) {
  adapter->addDefaultServant(std::move(servant), category);
  return adapter->createProxy(Ice::Identity{Ice::generateUUID(), category});
}

bool subscribe(const std::shared_ptr<IceStorm::TopicPrx>& topic, const std::shared_ptr<Ice::ObjectPrx>& subscriber) {
  try {
    topic->subscribeAndGetPublisher(IceStorm::QoS{}, subscriber->ice_oneway());
    return true;
  } catch (const IceStorm::AlreadySubscribed&) {
    return false;  // IceStorm kept the subscription (e.g. its database survived a restart)
  }
}

wire::Level to_wire(State s) noexcept {
  switch (s) {
    case State::Normal: return wire::Level::Normal;
    case State::Warning: return wire::Level::Warning;
    case State::Error: break;
  }
  return wire::Level::Error;
}

bool from_wire(wire::Level l, State& out) noexcept {
  switch (l) {
    case wire::Level::Normal: out = State::Normal; return true;
    case wire::Level::Warning: out = State::Warning; return true;
    case wire::Level::Error: out = State::Error; return true;
  }
  return false;
}

std::string_view outcome_text(Outcome o) noexcept { return o == Outcome::None ? std::string_view{} : to_string(o); }

std::int64_t steady_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace safecass::middleware

namespace safecass::middleware {

void link_topic(const std::shared_ptr<IceStorm::TopicPrx>& from, const std::shared_ptr<IceStorm::TopicManagerPrx>& to,
                const std::string& name) {
  const auto ignore = [](std::exception_ptr) {};
  const auto link_to = [from, name, ignore](const std::shared_ptr<IceStorm::TopicPrx>& target) {
    if (target == nullptr) return;
    from->getLinkInfoSeqAsync(
        [from, target, name, ignore](const IceStorm::LinkInfoSeq& links) {
          // A link is kept with the endpoints it was made to: a broker restarted on another port
          // (its topics are kept) has a topic of the same identity elsewhere. (Each broker's
          // topics have identities of their own: its instance name, IceEndpoint::name.)
          std::shared_ptr<IceStorm::TopicPrx> stale;
          for (const IceStorm::LinkInfo& l : links) {
            if (l.theTopic == nullptr || l.name != name) continue;
            if (l.theTopic->ice_toString() == target->ice_toString()) return;
            if (l.theTopic->ice_getIdentity() == target->ice_getIdentity()) stale = l.theTopic;
          }
          const auto link = [from, target, ignore] {
            from->linkAsync(
                target, 0, [] {}, ignore);
          };
          if (stale != nullptr) {
            from->unlinkAsync(stale, link, ignore);
          } else {
            link();
          }
        },
        ignore);
  };
  to->retrieveAsync(name, link_to, [to, name, link_to, ignore](std::exception_ptr e) {
    try {
      std::rethrow_exception(e);
    } catch (const IceStorm::NoSuchTopic&) {
      to->createAsync(name, link_to, ignore);
    } catch (...) {
    }
  });
}

void Link::connect(const std::vector<std::string>& publish_on) {
  // Every attempt on connections of its own: after a partition the old ones may look open while
  // their packets wait out TCP's retransmission backoff (minutes), and Ice would keep using them.
  if (manager_ != nullptr) {
    if (auto old = manager_->ice_getCachedConnection()) old->close(Ice::ConnectionClose::Forcefully);
    for (const auto& [name, p] : publishers_) {
      if (auto old = p->ice_getCachedConnection()) old->close(Ice::ConnectionClose::Forcefully);
    }
    for (const LinkTarget& target : targets_) {
      if (auto old = target.manager->ice_getCachedConnection()) old->close(Ice::ConnectionClose::Forcefully);
    }
  }
  const std::string id = "link-" + std::to_string(++generation_);
  manager_ = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(topic_manager(ic_, ice_, tls_)->ice_connectionId(id));
  manager_->ice_ping();
  for (Subscription& s : subscriptions_) {
    s.check = {};  // a check of the old connection
    s.proxy = Ice::uncheckedCast<IceStorm::TopicPrx>(topic(manager_, s.topic)->ice_connectionId(id));
    renew(s, false);
  }
  publishers_.clear();
  linked_.clear();
  targets_.clear();
  // A tool's link (at the tools' broker already) links nothing. A member's links: to its own
  // tools' broker, and with one broker per host to each other host's members' and tools' brokers.
  if (!ice_.tools) {
    const auto target = [&](const IceEndpoint& broker, bool tools_only) {
      targets_.push_back(LinkTarget{
          Ice::uncheckedCast<IceStorm::TopicManagerPrx>(topic_manager(ic_, broker, tls_)->ice_connectionId(id)),
          tools_only});
    };
    target(tools_broker(ice_), true);
    for (const IceEndpoint& peer : ice_.peers) {
      target(peer, false);
      target(tools_broker(peer), true);
    }
  }
  for (const std::string& name : publish_on) {
    auto t = Ice::uncheckedCast<IceStorm::TopicPrx>(topic(manager_, name)->ice_connectionId(id));
    publishers_.emplace_back(name, t->getPublisher()->ice_oneway()->ice_connectionId(id));
    linked_.emplace_back(name, t);
  }
  make_links();
}

void Link::make_links() {
  for (const auto& [name, t] : linked_) {
    for (const LinkTarget& target : targets_) {
      if (!target.tools_only || tools_hear(name)) link_topic(t, target.manager, name);
    }
  }
}

void Link::unsubscribe() noexcept {
  for (Subscription& s : subscriptions_) {
    if (s.proxy == nullptr || s.subscriber == nullptr) continue;
    try {
      s.proxy->unsubscribe(s.subscriber->ice_oneway());
    } catch (const Ice::Exception&) {
      // IceStorm is gone, or does not answer: it drops the subscriber by itself.
    }
  }
}

std::shared_ptr<Ice::ObjectPrx> Link::publisher(const std::string& name) const {
  for (const auto& [n, p] : publishers_) {
    if (n == name) return p;
  }
  return nullptr;
}

void Link::ping() const {
  if (manager_ == nullptr) throw Ice::ConnectionRefusedException(__FILE__, __LINE__);
  manager_->ice_ping();
}

std::string resubscribed_line(const std::vector<std::string>& topics) {
  std::string names;
  for (const std::string& t : topics) names += (names.empty() ? "" : ", ") + t;
  return "IceStorm no longer held the subscription to " + names +
         " (dropped as undeliverable, or removed), or it no longer delivered here (a stream lost); subscribed again "
         "under a new identity, resynchronising";
}

void Link::renew(Subscription& s, bool async) {
  const std::shared_ptr<Ice::ObjectPrx> old = s.subscriber;
  s.subscriber = s.servant->ice_identity(Ice::Identity{Ice::generateUUID(), s.servant->ice_getIdentity().category});
  if (async) {
    s.check = s.proxy->subscribeAndGetPublisherAsync(IceStorm::QoS{}, s.subscriber->ice_oneway());
  } else {
    (void)subscribe(s.proxy, s.subscriber);
  }
  // The old identity delivers to someone else's endpoint, or to nobody, or (IceStorm kept it
  // across a restart of its own) to us, twice: not ours any more either way.
  if (old != nullptr)
    s.proxy->unsubscribeAsync(
        old->ice_oneway(), [] {}, [](std::exception_ptr) {});
}

void Link::renew(const std::string& topic) {
  for (Subscription& s : subscriptions_) {
    if (s.topic == topic && s.proxy != nullptr) renew(s, true);
  }
}

std::vector<std::string> Link::check(bool ping_broker) {
  if (ping_broker) ping();
  std::vector<std::string> made;
  bool pending = false;
  for (Subscription& s : subscriptions_) {
    if (!s.check.valid()) continue;
    if (s.check.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      pending = true;
      continue;
    }
    try {
      s.check.get();
      made.push_back(s.topic);  // IceStorm did not hold it: made again now
    } catch (const IceStorm::AlreadySubscribed&) {
      // The identity is held: by this process, or (IceStorm cannot say: it lists identities, not
      // where they deliver) by another endpoint that took it. The stream rules tell: a stream
      // behind is lost within the bound, and its owner asks for a new identity (renew()).
    } catch (const Ice::TimeoutException&) {
      // No answer in time: a replicated IceStorm electing a master answers no subscription until
      // it has one. The ping above answered; the next round asks again.
    }
  }
  if (!pending && ++checks_ % kResubscribeCheckEvery == 0) {
    for (Subscription& s : subscriptions_) {
      if (s.proxy == nullptr)
        s.proxy = Ice::uncheckedCast<IceStorm::TopicPrx>(
            topic(manager_, s.topic)->ice_connectionId(manager_->ice_getConnectionId()));
      s.check = s.proxy->subscribeAndGetPublisherAsync(IceStorm::QoS{}, s.subscriber->ice_oneway());
    }
    make_links();
  }
  return made;
}

}  // namespace safecass::middleware
