// RemoteClient: the console's commands as requests to a coordinator's Control object.

#include "safecass/middleware/client.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>

#include "auth.hpp"
#include "control.hpp"
#include "ice_util.hpp"
#include "read_model_wire.hpp"
#include "receiver.hpp"
#include "safecass/middleware/keys.hpp"

namespace safecass::middleware {

namespace {

ErrorCode code_of(const std::string& text) {
  if (text == "Denied") return ErrorCode::Denied;
  if (text == "NotFound") return ErrorCode::NotFound;
  if (text == "Parse") return ErrorCode::Parse;
  if (text == "InvalidState") return ErrorCode::InvalidState;
  if (text == "Duplicate") return ErrorCode::Duplicate;
  if (text == "Io") return ErrorCode::Io;
  return ErrorCode::InvalidArgument;
}

/// Waits for authenticated heartbeats of one coordinator and keeps the Control proxies they name:
/// the proxy a write token is sent to comes only from a message signed by that coordinator's key
/// (a spoofed heartbeat naming it is refused here), and is used only once the process there has
/// proved itself alive by signing a nonce of ours (a replayed heartbeat of a dead process names
/// an endpoint anyone may now serve).
class Finder final {
public:
  Finder(std::string coordinator, const Keyring& keys, std::shared_ptr<Ice::Communicator> ic)
      : coordinator_(std::move(coordinator)), keys_(keys), ic_(std::move(ic)) {}
  void on_beat(const wire::Signed& m) {
    if (m.signer != coordinator_) return;  // other coordinators' heartbeats, or forgeries of them
    const OpenedHeartbeat opened = open_heartbeat(keys_, ic_, m);
    const wire::Heartbeat& h = opened.beat;
    std::lock_guard lock(mutex_);
    if (!opened.why.empty()) {
      ++refused_;
      return;
    }
    if (h.control.empty()) return;
    if (std::find(tried_.begin(), tried_.end(), h.control) != tried_.end() || control_ == h.control) return;
    control_ = h.control;
    cv_.notify_all();
  }
  std::uint64_t refused() {
    std::lock_guard lock(mutex_);
    return refused_;
  }
  /// Lets `control` be tried again when a later heartbeat names it: it did not answer (a TLS
  /// handshake or a busy process that outlasted the connect timeout), which says nothing of it.
  void retry(const std::string& control) {
    std::lock_guard lock(mutex_);
    std::erase(tried_, control);
  }
  /// The next endpoint named by an authenticated heartbeat that was not tried yet (empty: none
  /// came until `until`).
  std::string next(std::chrono::steady_clock::time_point until) {
    std::unique_lock lock(mutex_);
    cv_.wait_until(lock, until, [&] { return !control_.empty(); });
    std::string out = std::move(control_);
    control_.clear();
    if (!out.empty() && tried_.size() < 64) tried_.push_back(out);
    return out;
  }

private:
  std::string coordinator_;
  const Keyring& keys_;
  std::shared_ptr<Ice::Communicator> ic_;
  std::uint64_t refused_ = 0;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::string control_;
  std::vector<std::string> tried_;
};

}  // namespace

struct RemoteClient::Impl {
  ClientOptions options;
  std::shared_ptr<Ice::Communicator> ic;
  std::shared_ptr<wire::ControlPrx> control;  ///< bound to the coordinator's own connection (prove_at)
  std::string endpoint;                       ///< where it serves, as its proven heartbeat names it
  std::unique_ptr<Keyring> keys;
  std::atomic<std::uint64_t> refused{0};
  std::atomic<std::uint64_t> gaps{0};
  std::atomic<std::uint64_t> read{0};  ///< records delivered from the history (Follower::deliver_kept)
  wire::Heartbeat proven;              ///< the heartbeat the coordinator's proof of life carried at connect()
  /// Counts the bus messages that do not decode (a client logs nothing of its own).
  std::shared_ptr<DropLog> undecodable = std::make_shared<DropLog>(nullptr);

  ~Impl() {
    if (ic) ic->destroy();
  }

  /// Runs one request, turning every failure into an Error.
  template <class F>
  [[nodiscard]] auto call(const char* what, F&& f) -> Expected<decltype(f())> {
    try {
      if constexpr (std::is_void_v<decltype(f())>) {
        f();
        return {};
      } else {
        return f();
      }
    } catch (const wire::OperationError& e) {
      return fail(code_of(e.code), e.message);
    } catch (const Ice::Exception& e) {
      return fail(ErrorCode::Io, std::string(what) + ": coordinator '" + options.coordinator + "' did not answer (" +
                                     e.ice_id() + ")");
    }
  }
};

Expected<std::unique_ptr<RemoteClient>> RemoteClient::connect(ClientOptions options) {
  auto impl = std::make_unique<Impl>();
  impl->options = std::move(options);
  const ClientOptions& o = impl->options;
  auto dir = bus_keys_dir(o.keys_dir);
  if (!dir) return tl::unexpected(dir.error());
  impl->options.tls = tls_from_keys(*dir, impl->options.tls, kReaderCertificate);
  if (auto r = check_transport("console", o.tls, o.insecure, {o.ice.host}); !r) return tl::unexpected(r.error());
  auto keys = Keyring::load(*dir);
  if (!keys) return tl::unexpected(keys.error());
  if (!keys->knows(o.coordinator)) {
    return fail(ErrorCode::NotFound, "coordinator '" + o.coordinator + "' has no key in " + *dir + "/keyring");
  }
  try {
    impl->ic = make_communicator(o.tls, o.ice);
    if (impl->options.listen_host.empty()) impl->options.listen_host = listen_host_towards(o.ice);
    auto adapter =
        impl->ic->createObjectAdapterWithEndpoints("SafecassClient", protocol(o.tls) + " -h " + o.listen_host);
    auto finder = std::make_shared<Finder>(o.coordinator, *keys, impl->ic);
    auto proxy = adapter->addWithUUID(std::make_shared<TopicSubscriber>(
        impl->ic, "beat", [finder](const wire::Signed& m) { finder->on_beat(m); }, impl->undecodable, "console"));
    adapter->activate();
    std::shared_ptr<IceStorm::TopicPrx> heartbeat;
    try {
      heartbeat = topic(topic_manager(impl->ic, tools_broker(o.ice), o.tls), heartbeat_topic(o.coordinator));
    } catch (const Ice::Exception& e) {
      return fail(ErrorCode::Io, "cannot reach the tools' broker at " + to_string(tools_broker(o.ice)) +
                                     " (scripts/start-icestorm runs it beside the members' broker, on the next "
                                     "port): " +
                                     e.what());
    }
    subscribe(heartbeat, proxy);
    // Each endpoint an authentic heartbeat names is asked for a proof of life before anything
    // else is sent to it; one that cannot give one (a replayed heartbeat of a dead process, an
    // impostor on its port) is passed over for the next.
    const auto until = std::chrono::steady_clock::now() + o.timeout;
    std::shared_ptr<wire::ControlPrx> found;
    std::string unproven;  // why the last endpoint tried was not taken
    for (std::string control = finder->next(until); !control.empty(); control = finder->next(until)) {
      auto prx = impl->ic->stringToProxy(control);
      // Requests and the token go in clear over TCP: only to this host, unless the endpoint is TLS
      // (mutual, with this system's CA) or the user accepts otherwise.
      for (const auto& endpoint : prx->ice_getEndpoints()) {
        auto info = endpoint->getInfo();
        const bool secure = info != nullptr && info->secure();
        while (info != nullptr && std::dynamic_pointer_cast<Ice::IPEndpointInfo>(info) == nullptr)
          info = info->underlying;
        const auto ip = std::dynamic_pointer_cast<Ice::IPEndpointInfo>(info);
        const bool allowed = ip != nullptr && (is_loopback_host(ip->host) || o.insecure || (secure && o.tls.enabled()));
        if (!allowed) {
          return fail(ErrorCode::Denied,
                      "coordinator '" + o.coordinator + "' serves its operations at '" + printable(control) +
                          "', which is not on this host and not TLS: refused "
                          "without --insecure (requests and the token would cross the network unencrypted)");
        }
      }
      // The connection must be the coordinator's own (its certificate names it), and the proof,
      // asked over that connection alone, must be of the process at this endpoint.
      auto proven = prove_at(impl->ic, *keys, o.coordinator, control, o.timeout);
      if (!proven) {
        unproven = proven.error().message;
        if (proven.error().code == ErrorCode::Io) finder->retry(control);  // no answer: ask again, not a bad proof
        continue;
      }
      impl->proven = proven->beat;
      impl->endpoint = control;
      found = Ice::uncheckedCast<wire::ControlPrx>(proven->proxy);
      break;
    }
    try {
      heartbeat->unsubscribe(proxy);
    } catch (const Ice::Exception&) {
    }
    adapter->destroy();
    if (found == nullptr) {
      const std::uint64_t refused = finder->refused();
      return fail(ErrorCode::Io,
                  "no authenticated heartbeat from coordinator '" + o.coordinator + "' on the tools' broker " +
                      to_string(tools_broker(o.ice)) + " within " + std::to_string(o.timeout.count()) + " ms" +
                      (unproven.empty() ? "" : " from a process that proved itself alive (" + unproven + ")") +
                      (refused > 0 ? " (" + std::to_string(refused) + " forged heartbeat(s) naming it refused)" : ""));
    }
    impl->control = found;
    const std::string& credential = o.read_token.empty() ? o.token : o.read_token;
    if (!credential.empty()) impl->control = impl->control->ice_context({{kReadCredentialKey, credential}});
    impl->keys = std::make_unique<Keyring>(std::move(*keys));
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io, "cannot reach coordinator '" + o.coordinator + "': " + e.what());
  }
  return std::unique_ptr<RemoteClient>(new RemoteClient(std::move(impl)));
}

RemoteClient::RemoteClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RemoteClient::~RemoteClient() = default;

Expected<std::string> RemoteClient::coordinator() {
  return impl_->call("coordinator", [&] { return impl_->control->coordinator(); });
}

namespace {

template <class Out, class Seq>
std::vector<Out> rows_from_wire(const Seq& seq) {
  std::vector<Out> out;
  out.reserve(seq.size());
  for (const auto& w : seq) out.push_back(from_wire(w));
  return out;
}

[[nodiscard]] Expected<std::vector<introspect::HistoryEntry>> entries_from_wire(const wire::RecordEntrySeq& seq,
                                                                                const std::string& who) {
  std::vector<introspect::HistoryEntry> out;
  out.reserve(seq.size());
  for (const wire::RecordEntry& w : seq) {
    introspect::HistoryEntry e;
    if (!from_wire(w, e))
      return fail(ErrorCode::Parse,
                  "coordinator '" + who + "' sent a malformed history record (seq " + std::to_string(w.seq) + ")");
    out.push_back(std::move(e));
  }
  return out;
}

/// Follows one coordinator's records on the events topic. A follower holds only the keyring and
/// cannot check a batch's seal, so it believes a batch once a heartbeat of the process proven
/// alive, signed with its key, lists the batch's digest (Heartbeat::sentEvents): records travel
/// once, in the message that carries them, one heartbeat late at most. What no heartbeat vouches
/// for within two of them is dropped (forged, or of another process); what a heartbeat vouches for
/// that does not arrive, and what its heartbeats show sent beyond what was vouched for, are read
/// from the coordinator's history in bounded reads (a gap). Runs on the client communicator's one
/// dispatch thread, so records reach the sink in order.
class Follower final {
public:
  Follower(RemoteClient::Impl& client, introspect::RecordSink sink, std::uint64_t last)
      : client_(client), sink_(std::move(sink)), control_(client.control), last_(last) {
    std::string why;
    (void)fresh_.proven(client.proven, why);  // the process proven at connect(): a first proof is never refused
    take_components(client.proven);
  }

  void on_records(const wire::Signed& batch);
  void on_heartbeat(const wire::Signed& beat);
  /// Subscription::catch_up(): the records after the last delivered, from the history.
  [[nodiscard]] Expected<std::size_t> catch_up();

  void stop() {
    std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  /// True when no heartbeat of the followed process was taken for `at_least` and for three of
  /// its periods as seen between its last two heartbeats (since the start, or since the last time
  /// this said true: the subscriptions made again get as long to bring one).
  bool silent(std::chrono::steady_clock::duration at_least) {
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_beat_ <= std::max(at_least, 3 * beat_interval_)) return false;
    last_beat_ = now;
    return true;
  }

private:
  /// A batch not vouched for yet (`messages`), or a digest vouched for whose batch has not come
  /// (no messages); `beats`: heartbeats since.
  struct Waiting {
    Ice::ByteSeq digest;
    wire::EventMessageSeq messages;
    int beats = 0;
    std::size_t bytes = 0;  ///< the batch's body
  };
  /// How many heartbeats a batch waits for its voucher, and a voucher for its batch.
  static constexpr int kWaitBeats = 2;
  /// The most batches, and bytes of them, held unvouched: a flood of forged ones drops the oldest
  /// (counted as refused), so memory stays bounded; a genuine batch dropped so is read from the
  /// history once its heartbeat lists it (a gap).
  static constexpr std::size_t kMaxWaiting = 1024;
  static constexpr std::size_t kMaxWaitingBytes = std::size_t{8} << 20;
  /// Takes `at` out of unvouched_ (under mutex_).
  Waiting take_unvouched(std::vector<Waiting>::iterator at) {
    Waiting w = std::move(*at);
    unvouched_.erase(at);
    held_bytes_ -= w.bytes;
    return w;
  }

  /// Delivers the records of a vouched batch in order and once (a record after one that never
  /// came: the gap is read from the history first); under mutex_.
  void deliver(const wire::EventMessageSeq& messages);
  /// Delivers the kept records above last_ and below `below` (0: all); under mutex_. Io when the
  /// coordinator does not answer.
  [[nodiscard]] Expected<std::size_t> deliver_kept(std::uint64_t below);

  /// The process whose records are followed, at the coordinator's endpoint, bound to it.
  [[nodiscard]] Expected<wire::Heartbeat> prove_restart();

  RemoteClient::Impl& client_;
  introspect::RecordSink sink_;
  std::shared_ptr<wire::ControlPrx> control_;  ///< the client's, until the coordinator restarts
  std::mutex mutex_;                           // everything below and the sink's calls
  bool stopped_ = false;
  std::uint64_t last_;  ///< the last record delivered (its coordinator-wide seq)
  /// The coordinator process proven alive, whose records are followed, and its heartbeats' numbers
  /// (receiver.hpp, every receiver's freshness rules).
  PeerFreshness fresh_;
  bool joined_ = false;  ///< a heartbeat of that process was taken (its history read once)
  std::chrono::steady_clock::time_point last_beat_ = std::chrono::steady_clock::now();  ///< when
  std::chrono::steady_clock::duration beat_interval_{};  ///< between its last two heartbeats
  /// The followed process's event stream (receiver.hpp, the supervisor's too): a number skipped,
  /// or listed sent by a heartbeat two before and not come, is read from the history at once.
  EventStream stream_;
  std::vector<Waiting> unvouched_;       ///< batches received, no heartbeat has listed yet
  std::size_t held_bytes_ = 0;           ///< of unvouched_
  std::vector<Waiting> unreceived_;      ///< digests listed, batches not received yet
  std::vector<Ice::ByteSeq> delivered_;  ///< digests of the batches delivered lately (listed twice)
  /// The coordinator's own components, as the proof of its process lists them: a read of its
  /// history shows what its stream carries, not the records of its stand-ins for other
  /// processes' components.
  Ice::StringSeq components_;
  void take_components(const wire::Heartbeat& proof) {
    components_ = proof.components;
    std::sort(components_.begin(), components_.end());
  }
};

class RemoteSubscription final : public introspect::Subscription {
public:
  /// Heard nothing of the followed process for this long: the subscriptions are made again.
  static constexpr std::chrono::seconds kSilence{1};
  RemoteSubscription(std::shared_ptr<Follower> follower, std::shared_ptr<Ice::ObjectAdapter> adapter,
                     std::unique_ptr<Link> link, std::vector<std::string> topics)
      : follower_(std::move(follower)),
        adapter_(std::move(adapter)),
        link_(std::move(link)),
        topics_(std::move(topics)) {}
  /// The records the stream did not bring, from the history; and when no heartbeat of the process
  /// followed came for kSilence, the subscriptions made again under new identities (Link::renew,
  /// as every member does): IceStorm lists subscriber identities to whoever may call a topic, so
  /// another tool can take one at the tools' broker (docs/security.md), and a follower would
  /// otherwise show no new record from the stream until it is restarted. Every call also takes
  /// the answers of earlier renewals, and every tenth makes again a subscription IceStorm dropped
  /// (Link::check).
  [[nodiscard]] Expected<std::size_t> catch_up() override {
    auto caught = follower_->catch_up();
    try {
      if (caught && follower_->silent(kSilence)) {
        for (const std::string& t : topics_) link_->renew(t);
      }
      (void)link_->check(false);
    } catch (const Ice::Exception& e) {
      return fail(ErrorCode::Io,
                  std::string("records: IceStorm did not take the subscription again (") + e.ice_id() + ")");
    }
    return caught;
  }
  ~RemoteSubscription() override {
    follower_->stop();
    link_->unsubscribe();
    adapter_->destroy();
  }

private:
  std::shared_ptr<Follower> follower_;
  std::shared_ptr<Ice::ObjectAdapter> adapter_;
  std::unique_ptr<Link> link_;
  std::vector<std::string> topics_;
};

}  // namespace

void Follower::on_records(const wire::Signed& batch) {
  const std::string& coordinator = client_.options.coordinator;
  if (batch.signer != coordinator || batch.kind != kKindEvents) return;  // other coordinators' records
  wire::EventMessageSeq messages;
  if (!decode(client_.ic, batch.body, messages)) {
    ++client_.refused;
    return;
  }
  Ice::ByteSeq digest = Signer::digest_of(batch);
  std::lock_guard lock(mutex_);
  if (stopped_) return;
  const auto listed =
      std::find_if(unreceived_.begin(), unreceived_.end(), [&](const Waiting& w) { return w.digest == digest; });
  if (listed != unreceived_.end()) {  // vouched for already: the heartbeat came first
    unreceived_.erase(listed);
    delivered_.push_back(std::move(digest));
    deliver(messages);
    return;
  }
  const std::size_t bytes = batch.body.size();
  while (!unvouched_.empty() && (unvouched_.size() >= kMaxWaiting || held_bytes_ + bytes > kMaxWaitingBytes)) {
    (void)take_unvouched(unvouched_.begin());
    ++client_.refused;
  }
  if (bytes > kMaxWaitingBytes) {
    ++client_.refused;
    return;
  }
  held_bytes_ += bytes;
  unvouched_.push_back(Waiting{std::move(digest), std::move(messages), 0, bytes});
}

void Follower::on_heartbeat(const wire::Signed& m) {
  if (m.signer != client_.options.coordinator) return;
  const OpenedHeartbeat opened = open_heartbeat(*client_.keys, client_.ic, m);
  std::lock_guard lock(mutex_);
  if (stopped_) return;
  if (!opened.why.empty()) {
    ++client_.refused;
    return;
  }
  const wire::Heartbeat& h = opened.beat;
  std::string why;
  PeerFreshness::Verdict v = fresh_.heartbeat(h, why);
  bool restarted = false;
  if (v == PeerFreshness::Verdict::Unproven) {
    // A process not proven alive: a restart of the coordinator (followed once the endpoint proves
    // it), or a replay of a run that is over (refused).
    auto beat = prove_restart();
    if (!beat || beat->incarnation != h.incarnation || !fresh_.proven(*beat, why)) {
      ++client_.refused;
      return;
    }
    take_components(*beat);
    last_ = 0;  // a restarted coordinator numbers its records from 1 again
    joined_ = false;
    stream_ = EventStream{};
    unreceived_.clear();
    delivered_.clear();
    restarted = true;
    // Sent with or before the proof (Covered): of the process just proven all the same.
    v = fresh_.heartbeat(h, why);
  }
  if (v == PeerFreshness::Verdict::Refuse) {
    ++client_.refused;  // a replay: of an earlier process, or a heartbeat taken already
    return;
  }
  if (v == PeerFreshness::Verdict::Covered && !restarted) return;  // no news: the proof was fresher
  const bool first = !joined_;
  joined_ = true;
  const auto now = std::chrono::steady_clock::now();
  if (!first) beat_interval_ = now - last_beat_;
  last_beat_ = now;
  const std::int64_t sent_now = h.events;
  // The first heartbeat of the process followed: what it sent before this follower listened is
  // read once from its history, and the stream is followed from there (a read that fails leaves
  // the stream behind: a gap, read again at the next heartbeat).
  const bool covered = first && deliver_kept(0).has_value();
  if (covered) stream_.caught_up(sent_now);
  // What it vouches for: delivered now if here, else awaited. After the first heartbeat's read, a
  // batch not here was sent before this follower listened (a heartbeat lists two periods): its
  // records were in that read, so it is not awaited, and listed again it is no gap.
  for (const Ice::ByteSeq& digest : h.sentEvents) {
    if (std::find(delivered_.begin(), delivered_.end(), digest) != delivered_.end()) continue;  // listed twice
    const auto held =
        std::find_if(unvouched_.begin(), unvouched_.end(), [&](const Waiting& w) { return w.digest == digest; });
    if (held != unvouched_.end()) {
      Waiting batch = take_unvouched(held);
      delivered_.push_back(std::move(batch.digest));
      deliver(batch.messages);
    } else if (covered) {
      delivered_.push_back(digest);
    } else if (std::none_of(unreceived_.begin(), unreceived_.end(),
                            [&](const Waiting& w) { return w.digest == digest; })) {
      unreceived_.push_back(Waiting{digest, {}, 0});
    }
  }
  if (delivered_.size() > 4 * SentDigests::kMax)
    delivered_.erase(delivered_.begin(), delivered_.end() - 2 * SentDigests::kMax);
  // Batches no heartbeat vouched for in time are dropped (forged, or of another process);
  // vouchers whose batch did not come, and events listed as sent two heartbeats ago and still
  // not delivered, are a gap, read from the history.
  for (Waiting& w : unvouched_) ++w.beats;
  while (!unvouched_.empty() && unvouched_.front().beats > kWaitBeats) {  // oldest first: they came in order
    (void)take_unvouched(unvouched_.begin());
    ++client_.refused;
  }
  bool gap = false;
  for (Waiting& w : unreceived_) gap = ++w.beats > kWaitBeats || gap;
  std::erase_if(unreceived_, [](const Waiting& w) { return w.beats > kWaitBeats; });
  gap = stream_.heard(sent_now).has_value() || gap;
  if (!gap) return;
  ++client_.gaps;
  if (deliver_kept(0)) stream_.caught_up(sent_now);  // the history held everything this heartbeat listed
}

void Follower::deliver(const wire::EventMessageSeq& messages) {
  introspect::HistoryEntry entry;
  for (const wire::EventMessage& m : messages) {
    if (m.coordinator != client_.options.coordinator || m.incarnation != fresh_.incarnation() ||
        !from_wire(m.record, entry)) {
      ++client_.refused;  // misattributed, of another process, or malformed
      continue;
    }
    const bool skipped = m.seq > stream_.last() + 1;
    std::optional<EventStream::Range> range;
    if (stream_.take(m.seq, 0, range) == EventStream::Took::TooFar) {
      ++client_.refused;
      continue;
    }
    if (skipped) {
      // A message before this one never came: its records are read from the history first (a
      // stand-in's records are not on the stream, so the history may have nothing to add).
      if (entry.seq > last_ + 1) {
        ++client_.gaps;
        (void)deliver_kept(entry.seq);
      }
      stream_.caught_up(m.seq - 1);
    }
    if (entry.seq <= last_) continue;
    sink_(entry);
    last_ = entry.seq;
  }
}

Expected<wire::Heartbeat> Follower::prove_restart() {
  // The connection proven at connect() ends with its process: a restart is reached anew, and
  // checked as the first one was.
  auto proven =
      prove_at(client_.ic, *client_.keys, client_.options.coordinator, client_.endpoint, client_.options.timeout);
  if (!proven) return tl::unexpected(proven.error());
  control_ = Ice::uncheckedCast<wire::ControlPrx>(proven->proxy)->ice_context(client_.control->ice_getContext());
  return proven->beat;
}

Expected<std::size_t> Follower::deliver_kept(std::uint64_t below) {
  try {
    // Bounded reads (the coordinator decodes one answer's worth under its lock), from the last
    // record delivered, until an answer brings nothing new.
    std::size_t n = 0;
    for (;;) {
      auto kept =
          entries_from_wire(control_->recordsSince(static_cast<long long>(last_), 0), client_.options.coordinator);
      if (!kept) return tl::unexpected(kept.error());
      const std::uint64_t from = last_;
      for (const introspect::HistoryEntry& e : *kept) {
        if (below != 0 && e.seq >= below) return n;
        if (e.seq <= last_) continue;
        last_ = e.seq;
        if (!components_.empty() && !std::binary_search(components_.begin(), components_.end(), e.component))
          continue;  // a stand-in's record: its own process publishes that component's records
        ++n;
        ++client_.read;  // counted before it is shown: whoever sees it shown sees it counted
        sink_(e);
      }
      if (last_ == from) return n;
    }
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io,
                "records: coordinator '" + client_.options.coordinator + "' did not answer (" + e.ice_id() + ")");
  }
}

Expected<std::size_t> Follower::catch_up() {
  std::lock_guard lock(mutex_);
  if (stopped_) return std::size_t{0};
  auto n = deliver_kept(0);
  if (n && *n > 0) ++client_.gaps;
  return n;
}

std::string RemoteClient::name() const { return impl_->options.coordinator; }

Expected<introspect::ClockInfo> RemoteClient::clock() {
  return impl_->call("clock", [&] { return from_wire(impl_->control->clockInfo()); });
}

Expected<std::vector<introspect::StateRow>> RemoteClient::state_list(std::string_view component) {
  auto rows = impl_->call("state list", [&] { return impl_->control->stateList(std::string(component)); });
  if (!rows) return tl::unexpected(rows.error());
  std::vector<introspect::StateRow> out;
  for (const wire::StateEntry& w : *rows) {
    introspect::StateRow r;
    if (!from_wire(w, r))
      return fail(ErrorCode::Parse, "coordinator '" + impl_->options.coordinator + "' sent a malformed state row");
    out.push_back(std::move(r));
  }
  return out;
}

Expected<std::vector<introspect::HistoryEntry>> RemoteClient::history(std::string_view scope, std::size_t last,
                                                                      introspect::HistoryFilter filter) {
  const int n = static_cast<int>(std::min<std::size_t>(last, 1u << 30));
  auto seq = impl_->call("history", [&] {
    return filter == introspect::HistoryFilter::Events ? impl_->control->eventHistory(n)
                                                       : impl_->control->stateHistory(std::string(scope), n);
  });
  if (!seq) return tl::unexpected(seq.error());
  return entries_from_wire(*seq, impl_->options.coordinator);
}

Expected<std::vector<introspect::HistoryEntry>> RemoteClient::records_since(std::uint64_t seq, std::size_t max) {
  auto entries = impl_->call("records", [&] {
    return impl_->control->recordsSince(static_cast<long long>(seq),
                                        static_cast<int>(std::min<std::size_t>(max, 1u << 30)));
  });
  if (!entries) return tl::unexpected(entries.error());
  return entries_from_wire(*entries, impl_->options.coordinator);
}

Expected<std::vector<introspect::FilterRow>> RemoteClient::filter_list() {
  return impl_->call("filter list",
                     [&] { return rows_from_wire<introspect::FilterRow>(impl_->control->filterList()); });
}

Expected<introspect::FilterInfo> RemoteClient::filter_info(std::string_view name) {
  return impl_->call("filter info", [&] { return from_wire(impl_->control->filterInfo(std::string(name))); });
}

Expected<std::vector<introspect::EventRow>> RemoteClient::event_list() {
  return impl_->call("event list", [&] { return rows_from_wire<introspect::EventRow>(impl_->control->eventList()); });
}

Expected<std::vector<introspect::ConnectionRow>> RemoteClient::connection_list() {
  return impl_->call("connection list",
                     [&] { return rows_from_wire<introspect::ConnectionRow>(impl_->control->connectionList()); });
}

Expected<std::vector<introspect::ServiceRow>> RemoteClient::service_list() {
  return impl_->call("service list",
                     [&] { return rows_from_wire<introspect::ServiceRow>(impl_->control->serviceList()); });
}

Expected<introspect::ExplainAnswer> RemoteClient::explain(std::string_view address) {
  return impl_->call("explain", [&] { return from_wire(impl_->control->explain(std::string(address))); });
}

Expected<introspect::Names> RemoteClient::names() {
  return impl_->call("names", [&] { return from_wire(impl_->control->names()); });
}

Expected<std::string> RemoteClient::read(std::string_view name, const std::vector<std::string>& args) {
  const std::string what(name);
  return impl_->call(what.c_str(), [&] { return impl_->control->read(what, args); });
}

Expected<std::unique_ptr<introspect::Subscription>> RemoteClient::follow(introspect::RecordSink sink) {
  // Where the stream starts: the last record the coordinator has now; what it sends after that
  // and before this follower listens is read once, at its first heartbeat.
  auto newest = history("SYSTEM", 1);
  if (!newest) return tl::unexpected(newest.error());
  const std::uint64_t last = newest->empty() ? 0 : newest->back().seq;
  try {
    const ClientOptions& o = impl_->options;
    auto adapter = impl_->ic->createObjectAdapterWithEndpoints("SafecassFollow-" + Ice::generateUUID(),
                                                               protocol(o.tls) + " -h " + o.listen_host);
    auto follower = std::make_shared<Follower>(*impl_, std::move(sink), last);
    const auto subscriber = [&](const char* operation, std::function<void(const wire::Signed&)> handler) {
      return std::make_shared<TopicSubscriber>(impl_->ic, operation, std::move(handler), impl_->undecodable, "console");
    };
    // The subscriptions are a Link's, as a member's are: each under an identity of its own, made
    // again under a new one when taken (RemoteSubscription::catch_up).
    const std::string category = std::string(kFollowerCategory) + Ice::generateUUID();
    auto link = std::make_unique<Link>(impl_->ic, tools_broker(o.ice), o.tls);
    const std::vector<std::string> topics{kEventTopic, heartbeat_topic(o.coordinator)};
    link->subscribe_to(
        topics[0],
        add_subscriber(adapter, subscriber("records", [follower](const wire::Signed& m) { follower->on_records(m); }),
                       category + "-records"));
    link->subscribe_to(
        topics[1],
        add_subscriber(adapter, subscriber("beat", [follower](const wire::Signed& m) { follower->on_heartbeat(m); }),
                       category + "-beat"));
    adapter->activate();
    link->connect({});
    return std::unique_ptr<introspect::Subscription>(
        std::make_unique<RemoteSubscription>(follower, adapter, std::move(link), topics));
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io,
                "cannot follow coordinator '" + impl_->options.coordinator + "' on IceStorm: " + e.what());
  }
}

Expected<void> RemoteClient::apply(const introspect::Action& action) {
  const std::string& token = impl_->options.token;
  const std::shared_ptr<wire::ControlPrx>& control = impl_->control;
  return std::visit(
      [&](const auto& a) -> Expected<void> {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, introspect::PushSample>) {
          return fail(ErrorCode::InvalidArgument, "a sample of " + a.signal +
                                                      " cannot be pushed over the bus: a coordinator's samples "
                                                      "come from its own framework");
        } else if constexpr (std::is_same_v<A, introspect::GenerateEvent>) {
          return impl_->call("event generate", [&] { control->eventGenerate(token, a.event, a.target); });
        } else if constexpr (std::is_same_v<A, introspect::BroadcastEvent>) {
          return impl_->call("event broadcast", [&] { control->eventBroadcast(token, a.event); });
        } else if constexpr (std::is_same_v<A, introspect::ResetState>) {
          return impl_->call("reset", [&] { control->reset(token, a.target, a.who, a.why); });
        } else if constexpr (std::is_same_v<A, introspect::InjectShallow>) {
          return impl_->call("filter inject", [&] {
            control->filterInject(token, a.filter, wire::SampleSeq(a.samples.begin(), a.samples.end()));
          });
        } else {
          static_assert(std::is_same_v<A, introspect::InjectDeep>, "an Action alternative the client does not send");
          return impl_->call("filter dinject", [&] {
            control->filterDinject(token, a.signal, wire::SampleSeq(a.samples.begin(), a.samples.end()));
          });
        }
      },
      action);
}

std::uint64_t RemoteClient::records_refused() const { return impl_->refused.load() + impl_->undecodable->count(); }
std::uint64_t RemoteClient::gaps_filled() const { return impl_->gaps.load(); }
std::uint64_t RemoteClient::records_read() const { return impl_->read.load(); }

}  // namespace safecass::middleware
