#pragma once
// Internal: the checks every receiver of the bus makes (DESIGN §7 "The bus, precisely"), once,
// for coordinators, the supervisor and every follower (watch, viewer, timeline):
// - TopicSubscriber: every topic subscriber decodes its messages itself; what does not decode is
//   counted and logged at most once per second, never by Ice line by line (Guard does the same
//   for the Control and Alive objects);
// - Members: a member speaks only for the components the system file assigns to it;
// - Freshness: an incarnation is believed only once proven by a signed answer to a nonce of
//   this receiver (Prover), is bounded by the receiver's clock, and an older one is dropped;
//   each stream's numbers only rise, and never jump more than kMaxSeqJump in one message.

#include <Ice/Ice.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "auth.hpp"
#include "ice_sequences.hpp"  // before the generated header: its sequences' reader
#include "safecass.h"
#include "safecass/core/text_map.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

inline constexpr std::string_view kKindProof = "proof";
/// Bytes of a receiver's nonce (wire::Alive::prove).
inline constexpr std::size_t kNonceBytes = 16;
/// How far ahead of the receiver's clock an incarnation (the sender's start time) may be: the
/// clocks of the hosts of one system differ by less. A larger one is refused, so that no member
/// can lock itself out of its own later runs with an incarnation near 2^63.
inline constexpr std::chrono::seconds kIncarnationMargin{60};
/// The furthest a stream may jump ahead in one message, even a signed one: a sequence number
/// cannot push a stream into the future and freeze it.
inline constexpr std::int64_t kMaxSeqJump = std::int64_t{1} << 20;

/// Why a message of incarnation `seen` is refused when `newest` is the one believed: a replay, or a
/// second process with the same name.
std::string older_incarnation(std::int64_t seen, std::int64_t newest);

/// Why `incarnation` (of `who`, in `what`) is refused: it is not positive, or it lies further in
/// the future than kIncarnationMargin. Empty when it is acceptable.
std::string incarnation_out_of_bounds(std::string_view what, std::string_view who, std::int64_t incarnation);

/// A heartbeat opened as every receiver must before anything in it is believed (DESIGN §7): signed
/// by a key of the keyring, of kind "heartbeat", naming its signer as its coordinator, and of an
/// incarnation within bounds. Whether its process is the one proven alive is the receiver's
/// PeerFreshness to say.
struct OpenedHeartbeat {
  wire::Heartbeat beat;
  std::string why;     ///< empty: opened; else why it is refused
  std::string source;  ///< the DropLog source to count a refusal under (an incarnation out of
                       ///< bounds has its own, so that no other refusal of that signer hides it)
};
OpenedHeartbeat open_heartbeat(const Keyring& keys, const std::shared_ptr<Ice::Communicator>& ic,
                               const wire::Signed& m);

/// The seal digests of the event batches a coordinator sent in its last two heartbeat periods
/// (Heartbeat::sentEvents): its publisher adds each batch once sent, its heartbeat takes the list.
/// A reader that holds only the keyring believes a batch once a signed heartbeat lists it; two
/// periods, so that one heartbeat lost costs no reader a read of the history. Thread-safe.
class SentDigests {
public:
  /// At most this many digests per heartbeat (the newest): the batches of a burst beyond it are
  /// read from the history by those readers, in bounded reads.
  static constexpr std::size_t kMax = 256;
  void add(Ice::ByteSeq digest);
  /// The digests of the last two periods, oldest first, at most kMax; starts a new period.
  wire::DigestSeq take();

private:
  std::mutex mutex_;
  wire::DigestSeq before_, now_;
};

/// A coordinator's state streams as its heartbeats list their numbers (wire::Heartbeat::states):
/// one per interface "C.p" its components provide, sorted bytewise, and the id of that list
/// (wire::Heartbeat::statesId: the first 8 bytes of the BLAKE2b digest of the names, each ended by
/// a newline). The publisher and every receiver derive the list from the system file, so a
/// heartbeat carries numbers alone; a receiver with another list refuses the heartbeat.
struct StateStreams {
  std::vector<std::string> ifaces;
  std::int64_t id = 0;
  /// The list of `ifaces`, sorted, and its id.
  static StateStreams of(std::vector<std::string> ifaces);
};

/// The name of the state stream of interface `iface`, as a receiver says which stream it misses.
inline constexpr std::string_view kStateStreamPrefix = "state:";
inline std::string state_stream(std::string_view iface) { return std::string(kStateStreamPrefix).append(iface); }

/// The coordinator each component runs in, as the system file assigns them.
class Members {
public:
  explicit Members(const spec::SystemSpec& system);
  /// True when the system file assigns `component` to `coordinator`.
  bool runs(std::string_view coordinator, std::string_view component) const;
  /// The coordinator the system file assigns `component` to; empty when none.
  std::string_view coordinator_of(std::string_view component) const;
  /// The component of an interface or address "Component.rest".
  static std::string_view component_of(std::string_view address);
  /// The state streams of `coordinator`'s heartbeats: the interfaces its components provide
  /// (none for a name the system file does not give a component).
  StateStreams state_streams(std::string_view coordinator) const;

private:
  TextMap<std::string> owner_;                  // component -> coordinator
  TextMap<std::vector<std::string>> provided_;  // coordinator -> "C.p" of its components
};

/// What one receiver believes of one peer's process: the proven incarnation, its heartbeats' and
/// streams' last numbers. Not thread-safe: the owner holds its own lock.
class PeerFreshness {
public:
  enum class Verdict {
    Accept,    ///< believed: the caller applies it
    Refuse,    ///< a replay, an older process, a jump: `why` says which
    Unproven,  ///< a process this receiver has not proven alive yet (ask it: Prover), or a
               ///< message it sent before it proved itself alive: dropped, without blame
    Covered,   ///< a heartbeat numbered at or below the proof just taken, before any newer one:
               ///< sent before or with the proof and still on its way; dropped, without blame
               ///< and without asking again (its number is no news: the proof was fresher)
  };
  /// The incarnation rule alone, for a message of `incarnation`: older than the believed one
  /// refused, another one not proven, the believed one accepted.
  Verdict process(std::int64_t incarnation, std::string& why) const;
  /// A heartbeat: its incarnation, its number `beat.seq`, and its list of state streams, which
  /// must be the one follow() was given (a heartbeat of another list is refused).
  Verdict heartbeat(const wire::Heartbeat& beat, std::string& why);
  /// A peer's state stream, by its position in the peer's StateStreams.
  struct Slot {
    std::size_t index = 0;
  };
  /// Follows the peer's state streams from now on (the receiver's system file's list): their
  /// numbers start at 0 and are reset when another process is proven. A receiver that follows
  /// none (a tool) checks no heartbeat's list.
  void follow(StateStreams streams);
  /// The slot of interface `iface`'s stream; none when the peer has no such stream.
  std::optional<Slot> slot(std::string_view iface) const;
  /// Why a state batch that numbers the streams of the list of id `states_id`
  /// (wire::StateBatch::statesId) is refused: another list than the one followed. Empty: its
  /// updates' positions are slots of the followed list (slot(std::int64_t)).
  std::string other_streams(std::int64_t states_id) const;
  /// The slot an update of a batch of the followed list names by its position `stream`
  /// (wire::StateUpdate::stream); none when the list has no such position.
  std::optional<Slot> slot(std::int64_t stream) const noexcept {
    if (stream < 0 || static_cast<std::uint64_t>(stream) >= tracked_.size()) return std::nullopt;
    return Slot{static_cast<std::size_t>(stream)};
  }
  /// The number of state streams followed (slots 0 to size() - 1).
  std::size_t size() const noexcept { return tracked_.size(); }
  /// The interface of a slot.
  const std::string& iface(Slot slot) const { return streams_.ifaces.at(slot.index); }
  /// An update numbered `seq` of the stream in `slot`: on Accept `missed` is the number of updates
  /// of the stream skipped since the last one accepted, or since the number the proof listed.
  Verdict stream(Slot slot, std::int64_t incarnation, std::int64_t seq, std::int64_t& missed, std::string& why);
  /// Calls `behind(slot, listed)` for each stream that `beat` (a heartbeat of the process
  /// believed, of the list followed) lists ahead of what was taken from the stream's messages.
  template <class F>
  void ahead(const wire::Heartbeat& beat, F&& behind) const {
    const std::size_t n = std::min(beat.states.size(), tracked_.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (beat.states[i] > tracked_[i].taken) behind(Slot{i}, beat.states[i]);
    }
  }
  /// A proof of `beat` (checked by the Prover): its incarnation becomes the believed one, and its
  /// heartbeat and stream numbers the floor below which everything is a replay. `asked` is when
  /// the nonce it answers was sent (steady ns; 0: not known): the process's heartbeats are dated
  /// against it from now on (sent_at). Returns false, with `why`, when it is older than the
  /// believed one or lists other state streams than those followed.
  bool proven(const wire::Heartbeat& beat, std::string& why, std::int64_t asked = 0);
  /// The process believed is gone (its peer was declared lost): the next one proven is believed,
  /// whatever its incarnation. Only a proof of a fresh nonce is: a replay of any process stays
  /// refused, since it cannot answer one.
  void forget() noexcept {
    incarnation_ = 0;
    doubt_ = false;
  }
  /// Its peer was declared lost: the process believed is believed again only on a new proof (its
  /// heartbeats and state streams are Unproven until then), so that no recording of it (a
  /// member's replay of heartbeats the receiver never got) ends a loss (verify --bus, P2). Its
  /// event records are still taken (process()): they end no loss, and none is taken twice. An
  /// older process stays refused.
  void doubt() noexcept { doubt_ = true; }
  /// When the believed process sent what it stamped `remote_time` (Heartbeat::time, its steady
  /// clock), on this receiver's steady clock: dated against the last proof's question, so at the
  /// latest by the proof's round trip (never later than `now`). Without a dated proof: `now`.
  std::int64_t sent_at(std::int64_t remote_time, std::int64_t now) const noexcept {
    if (anchor_local_ == 0) return now;
    const std::int64_t sent = anchor_local_ + (remote_time - anchor_remote_);
    return sent < now ? sent : now;
  }
  /// The believed incarnation (0: none proven yet).
  std::int64_t incarnation() const noexcept { return incarnation_; }
  /// The last number accepted on the stream in `slot`, or listed by the proof (0: none).
  std::int64_t last(Slot slot) const { return tracked_.at(slot.index).last; }
  /// The last number of the stream in `slot` taken from a message of the process believed (0:
  /// none): what the receiver holds of it, whatever a proof listed.
  std::int64_t taken(Slot slot) const { return tracked_.at(slot.index).taken; }

private:
  struct Stream {
    std::int64_t last = 0;    ///< the last number accepted, or listed by the proof
    bool from_proof = false;  ///< `last` is the proof's: nothing accepted since
    std::int64_t taken = 0;   ///< the last number accepted from a message
  };
  Verdict take(Stream& s, std::int64_t seq, std::int64_t& missed, std::string& why);
  /// Why `beat` lists other state streams than those followed (empty: the same, or none followed).
  std::string other_streams(const wire::Heartbeat& beat) const;
  std::int64_t incarnation_ = 0;
  bool doubt_ = false;              ///< lost since proven: a new proof is needed
  std::int64_t anchor_local_ = 0;   ///< when the last proof's question was sent (steady ns here)
  std::int64_t anchor_remote_ = 0;  ///< the time its heartbeat carried (the sender's steady ns)
  std::int64_t heartbeat_seq_ = 0;
  bool heartbeat_from_proof_ = false;  ///< heartbeat_seq_ is a proof's, no heartbeat taken since
  bool following_ = false;             ///< follow() was called: heartbeats' lists are checked
  StateStreams streams_;               ///< followed (follow())
  std::vector<Stream> tracked_;        ///< by Slot::index, one per streams_.ifaces
  TextMap<std::size_t> index_;         ///< by interface: the slot
};

/// Whether one peer a receiver follows is lost: the loss rule of DESIGN §4 and §7, the same for
/// every receiver. Watched from a start (a peer never heard of is as bad as a gone one), a peer is
/// lost when no heartbeat of it was believed for longer than the loss bound, or when a stream its
/// heartbeats show ahead of what the receiver holds has not caught up within the bound (a lost
/// subscription, updates dropped on the way). It is back once a heartbeat is believed with every
/// stream caught up, and the peer has settled losses of its own (at most kSettleLimit is waited
/// for that). Not thread-safe: the owner holds its own lock.
class Liveness {
public:
  Liveness() = default;
  /// With another limit on the wait for a settling peer (the conformance test, at the model's scale).
  explicit Liveness(std::chrono::milliseconds settle_limit) noexcept : settle_limit_(settle_limit) {}
  /// A heartbeat of the peer, sent at `sent` (PeerFreshness::sent_at) and believed at `now`
  /// (steady ns); `behind` names a stream it lists ahead of what is held (empty: none). What
  /// counts is when it was sent: a heartbeat held back (a member relaying it late) buys no time.
  /// A stream shown ahead for the first time was sent after the heartbeat believed before this
  /// one: it is behind since then. True when this ends a loss (every stream caught up, and the
  /// heartbeat younger than `bound`): the owner clears its loss event.
  ///
  /// `settling`: the peer's heartbeat lists losses of its own that it is still clearing
  /// (Heartbeat::settling) and the owner shows its state. A loss is then kept, for at most
  /// kSettleLimit (or the limit it was made with) from the first heartbeat that would have ended it: the peer's state
  /// is about to change as it hears its own peers again, and the owner's view goes from the loss straight to that
  /// state, changing once (verify --bus, P5) instead of showing the way between. The limit ends a wait that could be
  /// mutual (two coordinators that feed each other).
  bool believed(std::int64_t now, std::int64_t sent, std::string_view behind, std::chrono::milliseconds bound,
                bool settling = false);
  /// How long a loss is kept at most for a peer that is settling: after a partition heals, the
  /// links between brokers come back each on its own (a connection attempt begun during the cut
  /// gives up after 2 s, the next comes a second later), then the peer proves its own peers
  /// alive; 3-4 s in all on the three hosts of the tests (docs/deployment.md), one side's more
  /// than the other's. 5 s covers that with a margin for a loaded machine.
  static constexpr std::chrono::milliseconds kSettleLimit{5000};
  /// Every stream the last heartbeat showed ahead has caught up (until the next heartbeat says
  /// otherwise). The owner calls it only when none is behind any more: one stream caught up
  /// while another is not must not restart the other's clock (verify --bus, two streams).
  void caught_up() noexcept { behind_since_ = 0; }
  /// Called by the owner's watch at `now`: why the peer is lost from now on (the owner raises its
  /// loss event), or empty. `watched_since` is when the owner started watching it (0: not yet),
  /// `bound` the loss bound; `since` says what started the watch ("the supervisor connected").
  std::string check(std::int64_t now, std::int64_t watched_since, std::chrono::milliseconds bound,
                    std::string_view since);
  /// Called by the owner's watch at `now` after check(): nonzero when the peer has been lost for a
  /// subscription round (`round`) since its loss began, or since this last said so (which renewal
  /// of this loss it is: 1 for the first, which the owner says in its log); the owner
  /// then subscribes to the peer's topics again under new identities (Link::renew). A loss renews
  /// them as it begins; a peer still lost a round later may be one whose subscriptions a member
  /// took before the loss began (a newcomer has no loss to begin: start_lost()) or after, and
  /// IceStorm's subscription round cannot tell: it holds them, for the member (verify --bus,
  /// class `unsubscribed`).
  std::uint32_t renew_due(std::int64_t now, std::chrono::nanoseconds round) noexcept;
  /// The earliest time (steady ns) at which check() can find the peer lost, or, while it is lost,
  /// renew_due() says so, if nothing comes meanwhile; INT64_MAX when neither can (not watched
  /// yet). What comes only moves it later, and what starts a new duty (a first heartbeat, a stream
  /// behind, the watch's start) makes one at least `bound` after it: the owner's watch sleeps until
  /// the earliest due of its peers, `bound` at most, instead of polling.
  std::int64_t due(std::int64_t watched_since, std::chrono::milliseconds bound,
                   std::chrono::nanoseconds round) const noexcept;
  bool lost() const noexcept { return lost_; }
  /// Starts the peer lost at `now` (a newcomer starts toward safe): back once a heartbeat is
  /// believed with every stream caught up, as after a loss.
  void start_lost(std::int64_t now) noexcept {
    lost_ = true;
    renewed_at_ = now;
    renewals_ = 0;
  }
  /// When the newest heartbeat believed was sent (0: never).
  std::int64_t last_beat() const noexcept { return last_beat_; }

private:
  std::int64_t last_beat_ = 0;
  std::int64_t behind_since_ = 0;    ///< since when its heartbeats show `behind_` ahead (0: caught up)
  std::int64_t settling_since_ = 0;  ///< lost, and kept lost since then because it was settling (0: not)
  std::int64_t renewed_at_ = 0;      ///< lost: when the loss began, or renew_due() last said so
  std::uint32_t renewals_ = 0;       ///< lost: how often renew_due() said so since the loss began
  std::chrono::milliseconds settle_limit_ = kSettleLimit;
  std::string behind_;
  bool lost_ = false;
};

/// One proven process's stream of event records as a receiver follows it, the same for every
/// receiver (DESIGN §7 "One follower"): the numbers taken, the ranges that did not come (gaps:
/// IceStorm may deliver a batch after the next one, so a gap is missed only after a grace), and
/// what the process's heartbeats list as sent that never came. What a receiver does with a missed
/// range is its own: the supervisor reports it and reads the view again, a tool reads the range
/// from the coordinator's history. Not thread-safe: the owner holds its own lock.
class EventStream {
public:
  struct Range {
    std::int64_t first = 0;  ///< first missing number
    std::int64_t last = 0;   ///< last missing number
  };
  enum class Took {
    Next,       ///< above every number taken: deliver (a skipped range opens a gap)
    Filled,     ///< fills an open gap (it came after a later one): deliver
    Late,       ///< comes after its range was missed, the first of that range to: deliver, say so
    LateAgain,  ///< as Late, said already for its range: deliver
    Early,      ///< at or below the number the receiver joined at: sent before the process proved
                ///< itself alive, and indistinguishable from a replay: not taken, without blame
    Again,      ///< received already: a duplicate or a replay
    TooFar,     ///< more than kMaxSeqJump above the last number taken: refused
  };
  /// More open gaps than this: the oldest is missed at once (take()'s `range`).
  static constexpr std::size_t kMaxGaps = 64;

  /// A process proven alive whose proof lists `sent` records sent: the stream starts after them.
  void join(std::int64_t sent);
  /// Record number `seq`, arrived at `now` (steady ns). `range` is set, for Next, to a gap missed
  /// at once because more than kMaxGaps are open; for Late, to the missed range it belongs to.
  Took take(std::int64_t seq, std::int64_t now, std::optional<Range>& range);
  /// A believed heartbeat listing `sent` records sent: what the heartbeat two before it listed and
  /// has not come since is missed, once, and the stream goes on after it. Two heartbeats of slack:
  /// a batch and the heartbeat that lists it travel on different topics, and a reader that waits
  /// for a heartbeat to vouch for a batch takes it one heartbeat late.
  std::optional<Range> heard(std::int64_t sent);
  /// The oldest gap open since at least `grace` ns before `now`, missed now; none when none.
  std::optional<Range> overdue(std::int64_t now, std::int64_t grace);
  /// Every record up to `seq` is held (read from the process's history): gaps below it close.
  void caught_up(std::int64_t seq);
  /// The highest number taken (or joined at).
  std::int64_t last() const noexcept { return last_; }
  /// True while a range below last() has not come.
  bool has_gaps() const noexcept { return !gaps_.empty(); }
  /// When overdue() will miss the oldest open gap (steady ns); INT64_MAX when none is open.
  std::int64_t overdue_at(std::int64_t grace) const noexcept {
    return gaps_.empty() ? std::numeric_limits<std::int64_t>::max() : gaps_.front().opened + grace;
  }
  /// "first" or "first..last".
  static std::string text(const Range& r);

private:
  struct Gap {
    Range range;
    std::int64_t opened = 0;  ///< steady ns
    bool late_said = false;   ///< missed ranges: a late record of it was said
  };
  /// Moves `g` to the missed ranges (the newest kMaxGaps kept) and returns its range.
  Range miss(const Gap& g);
  std::int64_t joined_ = 0;
  std::int64_t last_ = 0;
  std::int64_t listed_ = 0;         ///< what the last heartbeat listed as sent
  std::int64_t listed_before_ = 0;  ///< what the heartbeat before it listed
  std::vector<Gap> gaps_;           ///< open, oldest first
  std::vector<Gap> missed_;         ///< missed, oldest first: a record of one that still comes is late
};

/// What a receiver says of the records it missed (EventStream's ranges): all of them, in at most
/// one line a second per sender. The first range is said at once; ranges found within a second of
/// the last line wait for the next one, which sums them exactly and lists them (the first kShown,
/// then how many more). A rate limit that dropped lines would leave records lost unreported.
class MissedRecords {
public:
  static constexpr std::size_t kShown = 8;
  static constexpr std::int64_t kInterval = 1'000'000'000;  ///< steady ns between two lines

  void add(const EventStream::Range& r);
  /// The line due at `now` ("N event record(s) of 'who' missed (seq a..b, c)"), if one is: records
  /// wait and a second has passed since the last line, or `now_anyway` (the receiver stops).
  std::optional<std::string> take(std::int64_t now, std::string_view who, bool now_anyway = false);
  /// When take() has a line (steady ns); INT64_MAX when no record waits.
  std::int64_t due_at() const noexcept;

private:
  std::int64_t count_ = 0;                 ///< records waiting to be said
  std::vector<EventStream::Range> shown_;  ///< their first kShown ranges
  std::int64_t more_ = 0;                  ///< ranges beyond those
  std::optional<std::int64_t> said_at_;    ///< the last line's time
};

/// Asks a peer's Alive endpoint (named in its heartbeat) to sign a fresh nonce, and checks the
/// answer: asked over a connection to the peer's own process (not_served_by), kind "proof", signed
/// by the peer's key, the nonce ours, the endpoint the one asked. At most one question per peer
/// at a time, and one per `retry` after a failure. Answers are delivered to `on_proven` on an Ice
/// thread, outside any lock of the caller.
class Prover {
public:
  /// `on_proven` gets the proof's heartbeat and when its question was sent (steady ns); an answer
  /// that comes more than `retry` after its question is refused: it proves the process alive too
  /// long ago to date its heartbeats by (PeerFreshness::sent_at), and the question is asked again.
  Prover(std::shared_ptr<Ice::Communicator> ic, const Keyring& keys,
         std::function<void(const std::string& signer, const wire::Heartbeat& beat, std::int64_t asked)> on_proven,
         std::function<void(const std::string& signer, const std::string& why)> on_refused,
         std::chrono::milliseconds retry);
  /// Asks `signer`, whose heartbeat names `endpoint`, unless a question is on its way.
  void ask(const std::string& signer, const std::string& endpoint);

private:
  struct Question {
    std::string nonce;
    std::int64_t asked = 0;  ///< steady ns
    bool open = false;
  };
  void done(const std::string& signer, const std::string& endpoint, const std::string& nonce,
            const wire::Signed* answer, const std::string& error, std::int64_t sent);

  std::shared_ptr<Ice::Communicator> ic_;
  const Keyring& keys_;
  std::function<void(const std::string&, const wire::Heartbeat&, std::int64_t)> on_proven_;
  std::function<void(const std::string&, const std::string&)> on_refused_;
  std::int64_t retry_ns_;
  std::mutex mutex_;
  std::map<std::string, Question, std::less<>> questions_;
};

/// Why `connection` is not one to `member`'s own process (empty: it is). A proof names what it
/// proves (DESIGN §7): with TLS (the communicator holds a certificate of the system), the peer's
/// verified certificate must carry `member` as its common name, since any certificate of the
/// system's CA could serve any endpoint. Without TLS (keys of an earlier version, run with a
/// warning) a connection names nobody and only the proof's endpoint binds it (check_proof).
std::string not_served_by(const std::shared_ptr<Ice::Communicator>& ic,
                          const std::shared_ptr<Ice::Connection>& connection, std::string_view member);

/// A process proven alive at an endpoint, and the proxy that reaches it.
struct ProvenEndpoint {
  std::shared_ptr<Ice::ObjectPrx> proxy;  ///< fixed to the connection checked
  wire::Heartbeat beat;                   ///< what its proof says of it
};

/// Reaches `member` at `endpoint` (a stringified proxy a heartbeat of `member` names) and proves
/// it alive there, waiting for the answer: connected, the connection checked by not_served_by,
/// the proxy fixed to that connection (every later request goes to the process checked or fails,
/// never to whoever serves the endpoint next), then a fresh nonce signed by `member`'s key and
/// answered with a proof of the process at `endpoint`.
/// Errors: Io (no connection or no answer within `timeout`), Denied (another process serves the
/// endpoint, no valid proof, or a proof of a process at another endpoint: a relayed answer).
[[nodiscard]] Expected<ProvenEndpoint> prove_at(const std::shared_ptr<Ice::Communicator>& ic, const Keyring& keys,
                                                const std::string& member, const std::string& endpoint,
                                                std::chrono::milliseconds timeout);

/// The signed answer to `nonce` of a process whose current heartbeat is `beat` (Alive::prove).
wire::Signed make_proof(const Signer& signer, const std::shared_ptr<Ice::Communicator>& ic, const Ice::ByteSeq& nonce,
                        wire::Heartbeat beat);

/// The subscriber of one bus topic: it receives each message as raw bytes and decodes the
/// envelope itself, so that a message that does not decode costs one exception caught where it is
/// thrown (not an unwinding through Ice's dispatch, which made such a flood cost several times
/// more), is counted and logged at most once a second, and never reaches `handler`. Ice's warning
/// for each one is off (Ice.Warn.Dispatch).
class TopicSubscriber final : public Ice::BlobjectArray {
public:
  /// `operation`: the topic interface's one operation (e.g. "updates" for wire::StateTopic).
  TopicSubscriber(std::shared_ptr<Ice::Communicator> ic, std::string operation,
                  std::function<void(const wire::Signed&)> handler, std::shared_ptr<DropLog> log, std::string who);
  bool ice_invoke(std::pair<const Ice::Byte*, const Ice::Byte*> in, std::vector<Ice::Byte>& out,
                  const Ice::Current& current) override;

private:
  std::shared_ptr<Ice::Communicator> ic_;
  std::string operation_;
  std::function<void(const wire::Signed&)> handler_;
  std::shared_ptr<DropLog> log_;
  std::string who_;
};

/// Dispatches a servant that is not a topic subscriber (the Control and Alive objects): anything
/// that fails to dispatch (an undecodable request, an unknown operation) is counted and logged at
/// most once per second with the number since, instead of Ice's warning for each one
/// (Ice.Warn.Dispatch is off).
class Guard final : public Ice::DispatchInterceptor {
public:
  Guard(std::shared_ptr<Ice::Object> servant, std::shared_ptr<DropLog> log, std::string what)
      : servant_(std::move(servant)), log_(std::move(log)), what_(std::move(what)) {}
  bool dispatch(Ice::Request& request) override;

private:
  std::shared_ptr<Ice::Object> servant_;
  std::shared_ptr<DropLog> log_;
  std::string what_;
};

}  // namespace safecass::middleware
