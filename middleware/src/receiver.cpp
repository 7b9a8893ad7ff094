// The receiver's checks (receiver.hpp, DESIGN §7 "The bus, precisely").

#include "receiver.hpp"

#include <sodium.h>

#include <algorithm>
#include <limits>
#include <list>

#include <IceSSL/IceSSL.h>

#include "ice_util.hpp"

namespace safecass::middleware {

std::string incarnation_out_of_bounds(std::string_view what, std::string_view who, std::int64_t incarnation) {
  const std::int64_t limit = new_incarnation() + std::chrono::nanoseconds(kIncarnationMargin).count();
  if (incarnation > 0 && incarnation <= limit) return {};
  return std::string(what) + " of '" + printable(who) + "': incarnation " + std::to_string(incarnation) +
         (incarnation <= 0 ? " is not a start time" : " is more than 60 s ahead of this host's clock");
}

OpenedHeartbeat open_heartbeat(const Keyring& keys, const std::shared_ptr<Ice::Communicator>& ic,
                               const wire::Signed& m) {
  OpenedHeartbeat h;
  h.source = m.signer;
  if (const std::string why = open_signed(keys, ic, m, kKindHeartbeat, h.beat); !why.empty()) {
    h.why = "a heartbeat signed '" + printable(m.signer) + "': " + why;
  } else if (h.beat.coordinator != m.signer) {
    h.why = "a heartbeat naming '" + printable(h.beat.coordinator) + "' signed by '" + printable(m.signer) + "'";
  } else if (std::string bounds = incarnation_out_of_bounds("a heartbeat", m.signer, h.beat.incarnation);
             !bounds.empty()) {
    h.why = std::move(bounds);
    h.source = m.signer + "/incarnation";
  }
  return h;
}

std::string older_incarnation(std::int64_t seen, std::int64_t newest) {
  return "incarnation " + std::to_string(seen) + " is older than " + std::to_string(newest) +
         " (a replay, or two processes with one name)";
}

// ---- Members ------------------------------------------------------------------------------------

Members::Members(const spec::SystemSpec& system) {
  for (const auto& [coordinator, components] : system.coordinators) {
    for (const std::string& c : components) owner_.emplace(c, coordinator);
  }
  for (const spec::ComponentSpec& c : system.components) {
    const auto owner = owner_.find(c.name);
    if (owner == owner_.end()) continue;
    auto& ifaces = provided_[owner->second];
    for (const std::string& p : c.provided) ifaces.push_back(c.name + "." + p);
  }
}

StateStreams Members::state_streams(std::string_view coordinator) const {
  const auto it = provided_.find(coordinator);
  return StateStreams::of(it == provided_.end() ? std::vector<std::string>{} : it->second);
}

StateStreams StateStreams::of(std::vector<std::string> ifaces) {
  std::sort(ifaces.begin(), ifaces.end());
  crypto_generichash_state state;
  ::crypto_generichash_init(&state, nullptr, 0, crypto_generichash_BYTES);
  for (const std::string& iface : ifaces) {
    ::crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(iface.data()), iface.size());
    ::crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>("\n"), 1);
  }
  unsigned char digest[crypto_generichash_BYTES];
  ::crypto_generichash_final(&state, digest, sizeof digest);
  std::uint64_t id = 0;
  for (int k = 0; k < 8; ++k) id = (id << 8) | digest[k];
  return StateStreams{std::move(ifaces), static_cast<std::int64_t>(id)};
}

std::string_view Members::coordinator_of(std::string_view component) const {
  const auto it = owner_.find(component);
  return it == owner_.end() ? std::string_view() : std::string_view(it->second);
}

bool Members::runs(std::string_view coordinator, std::string_view component) const {
  const auto it = owner_.find(component);
  return it != owner_.end() && it->second == coordinator;
}

std::string_view Members::component_of(std::string_view address) { return address.substr(0, address.find('.')); }

// ---- Liveness -----------------------------------------------------------------------------------

bool Liveness::believed(std::int64_t now, std::int64_t sent, std::string_view behind, std::chrono::milliseconds bound,
                        bool settling) {
  const std::int64_t before = last_beat_;
  if (sent > last_beat_) last_beat_ = sent;
  if (behind.empty()) {
    behind_since_ = 0;
  } else if (behind_since_ == 0) {
    behind_since_ = before != 0 ? before : last_beat_;
    behind_.assign(behind);
  }
  if (!lost_ || behind_since_ != 0 || now - last_beat_ > std::chrono::nanoseconds(bound).count()) return false;
  if (settling) {
    if (settling_since_ == 0) settling_since_ = now;
    if (now - settling_since_ <= std::chrono::nanoseconds(settle_limit_).count()) return false;
  }
  lost_ = false;
  settling_since_ = 0;
  return true;
}

std::string Liveness::check(std::int64_t now, std::int64_t watched_since, std::chrono::milliseconds bound,
                            std::string_view since) {
  if (lost_) return {};
  const std::int64_t bound_ns = std::chrono::nanoseconds(bound).count();
  const auto bound_text = [&] { return std::to_string(bound.count()) + " ms"; };  // only for a loss said
  const std::int64_t last = last_beat_ != 0 ? last_beat_ : watched_since;
  if (last != 0 && now - last > bound_ns) {
    lost_ = true;
    renewed_at_ = now;
    renewals_ = 0;
    return "no heartbeat for " + bound_text() +
           (last_beat_ != 0 ? std::string() : " (never proven alive since " + std::string(since) + ")");
  }
  if (behind_since_ != 0 && now - behind_since_ > bound_ns) {
    lost_ = true;
    renewed_at_ = now;
    renewals_ = 0;
    const std::string_view stream = behind_;
    const std::string what = stream.starts_with(kStateStreamPrefix)
                                 ? "state of " + printable(stream.substr(kStateStreamPrefix.size()))
                                 : "the stream '" + printable(stream) + "'";
    return "its heartbeats list " + what + " not received for " + bound_text();
  }
  return {};
}

std::uint32_t Liveness::renew_due(std::int64_t now, std::chrono::nanoseconds round) noexcept {
  if (!lost_ || now - renewed_at_ < round.count()) return 0;
  renewed_at_ = now;
  return ++renewals_;
}

std::int64_t Liveness::due(std::int64_t watched_since, std::chrono::milliseconds bound,
                           std::chrono::nanoseconds round) const noexcept {
  constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  if (lost_) return renewed_at_ + round.count();
  // check() finds a loss once more than the bound has passed: one nanosecond after it.
  const std::int64_t after = std::chrono::nanoseconds(bound).count() + 1;
  const std::int64_t last = last_beat_ != 0 ? last_beat_ : watched_since;
  std::int64_t due = last != 0 ? last + after : kNever;
  if (behind_since_ != 0) due = std::min(due, behind_since_ + after);
  return due;
}

// ---- EventStream --------------------------------------------------------------------------------

namespace {
/// Takes `seq` out of the range of `gaps` that holds it (splitting it); that gap as it was, or
/// nothing when no range holds it.
template <class Gap>
std::optional<Gap> take_out(std::vector<Gap>& gaps, std::int64_t seq) {
  for (auto it = gaps.begin(); it != gaps.end(); ++it) {
    if (seq < it->range.first || seq > it->range.last) continue;
    const Gap was = *it;
    if (it->range.first == it->range.last) {
      gaps.erase(it);
    } else if (seq == it->range.first) {
      ++it->range.first;
    } else if (seq == it->range.last) {
      --it->range.last;
    } else {
      Gap upper = *it;
      upper.range.first = seq + 1;
      it->range.last = seq - 1;
      gaps.insert(std::next(it), upper);
    }
    return was;
  }
  return std::nullopt;
}
}  // namespace

void EventStream::join(std::int64_t sent) {
  joined_ = last_ = listed_ = listed_before_ = sent;
  gaps_.clear();
  missed_.clear();
}

EventStream::Took EventStream::take(std::int64_t seq, std::int64_t now, std::optional<Range>& range) {
  range.reset();
  if (seq - last_ > kMaxSeqJump) return Took::TooFar;
  if (seq <= joined_) return Took::Early;
  if (seq <= last_) {
    if (take_out(gaps_, seq)) return Took::Filled;
    const auto missed = take_out(missed_, seq);
    if (!missed) return Took::Again;
    if (missed->late_said) return Took::LateAgain;
    for (Gap& g : missed_) {  // the pieces of its range left
      if (g.range.first >= missed->range.first && g.range.last <= missed->range.last) g.late_said = true;
    }
    range = missed->range;
    return Took::Late;
  }
  if (seq != last_ + 1) {
    if (gaps_.size() >= kMaxGaps) {
      range = miss(gaps_.front());
      gaps_.erase(gaps_.begin());
    }
    gaps_.push_back(Gap{Range{last_ + 1, seq - 1}, now, false});
  }
  last_ = seq;
  return Took::Next;
}

std::optional<EventStream::Range> EventStream::heard(std::int64_t sent) {
  std::optional<Range> out;
  if (listed_before_ > last_) {
    out = miss(Gap{Range{last_ + 1, listed_before_}, 0, false});
    last_ = listed_before_;
  }
  listed_before_ = listed_;
  listed_ = sent;
  return out;
}

std::optional<EventStream::Range> EventStream::overdue(std::int64_t now, std::int64_t grace) {
  if (gaps_.empty() || now - gaps_.front().opened < grace) return std::nullopt;
  const Range r = miss(gaps_.front());
  gaps_.erase(gaps_.begin());
  return r;
}

void EventStream::caught_up(std::int64_t seq) {
  for (std::vector<Gap>* list : {&gaps_, &missed_}) {
    std::erase_if(*list, [&](const Gap& g) { return g.range.last <= seq; });
    for (Gap& g : *list) g.range.first = std::max(g.range.first, seq + 1);
  }
  last_ = std::max(last_, seq);
}

EventStream::Range EventStream::miss(const Gap& g) {
  if (missed_.size() >= kMaxGaps) missed_.erase(missed_.begin());
  missed_.push_back(Gap{g.range, g.opened, false});
  return g.range;
}

std::string EventStream::text(const Range& r) {
  return std::to_string(r.first) + (r.first == r.last ? std::string() : ".." + std::to_string(r.last));
}

// ---- MissedRecords ------------------------------------------------------------------------------

void MissedRecords::add(const EventStream::Range& r) {
  count_ += r.last - r.first + 1;
  if (!shown_.empty() && more_ == 0 && shown_.back().last + 1 == r.first) {
    shown_.back().last = r.last;  // adjoins the range before it (a heartbeat's, then a gap's)
  } else if (shown_.size() < kShown) {
    shown_.push_back(r);
  } else {
    ++more_;
  }
}

std::int64_t MissedRecords::due_at() const noexcept {
  if (count_ == 0) return std::numeric_limits<std::int64_t>::max();
  return said_at_ ? *said_at_ + kInterval : std::numeric_limits<std::int64_t>::min();
}

std::optional<std::string> MissedRecords::take(std::int64_t now, std::string_view who, bool now_anyway) {
  if (count_ == 0 || (!now_anyway && now < due_at())) return std::nullopt;
  std::string line = std::to_string(count_) + " event record(s) of '" + printable(who) + "' missed (seq ";
  for (std::size_t i = 0; i < shown_.size(); ++i) line += (i == 0 ? "" : ", ") + EventStream::text(shown_[i]);
  if (more_ > 0) line += " and " + std::to_string(more_) + " more range(s)";
  line += ")";
  count_ = 0;
  shown_.clear();
  more_ = 0;
  said_at_ = now;
  return line;
}

// ---- PeerFreshness ------------------------------------------------------------------------------

PeerFreshness::Verdict PeerFreshness::process(std::int64_t incarnation, std::string& why) const {
  // No process proven yet (a proof's incarnation is always positive): nothing is taken, whatever
  // incarnation a message names, zero included.
  if (incarnation_ == 0) return Verdict::Unproven;
  if (incarnation < incarnation_) {
    why = older_incarnation(incarnation, incarnation_);
    return Verdict::Refuse;
  }
  return incarnation == incarnation_ ? Verdict::Accept : Verdict::Unproven;
}

PeerFreshness::Verdict PeerFreshness::heartbeat(const wire::Heartbeat& beat, std::string& why) {
  if (why = other_streams(beat); !why.empty()) return Verdict::Refuse;
  if (const Verdict v = process(beat.incarnation, why); v != Verdict::Accept) return v;
  const std::int64_t seq = beat.seq;
  if (doubt_) return Verdict::Unproven;
  if (seq <= heartbeat_seq_) {
    // The proof carried the heartbeat it was sent with: that one (and older ones still on their
    // way) arrive after it, and are no replay.
    if (heartbeat_from_proof_) return Verdict::Covered;
    why = "seq " + std::to_string(seq) + " not above " + std::to_string(heartbeat_seq_) + " (replayed)";
    return Verdict::Refuse;
  }
  heartbeat_seq_ = seq;
  heartbeat_from_proof_ = false;
  return Verdict::Accept;
}

void PeerFreshness::follow(StateStreams streams) {
  streams_ = std::move(streams);
  following_ = true;
  tracked_.assign(streams_.ifaces.size(), Stream{});
  index_.clear();
  for (std::size_t i = 0; i < streams_.ifaces.size(); ++i) index_.emplace(streams_.ifaces[i], i);
}

std::optional<PeerFreshness::Slot> PeerFreshness::slot(std::string_view iface) const {
  const auto it = index_.find(iface);
  if (it == index_.end()) return std::nullopt;
  return Slot{it->second};
}

std::string PeerFreshness::other_streams(std::int64_t states_id) const {
  if (following_ && states_id == streams_.id) return {};
  return "its updates number the state streams of a list of id " + std::to_string(states_id) +
         ", where the system file gives its coordinator " + std::to_string(tracked_.size()) + " of id " +
         std::to_string(streams_.id) + " (its components' provided interfaces differ: another system file?)";
}

std::string PeerFreshness::other_streams(const wire::Heartbeat& beat) const {
  if (!following_) return {};  // follows none (a tool)
  if (beat.statesId == streams_.id && beat.states.size() == tracked_.size()) return {};
  return "it lists " + std::to_string(beat.states.size()) + " state stream(s) of id " + std::to_string(beat.statesId) +
         ", where the system file gives its coordinator " + std::to_string(tracked_.size()) + " of id " +
         std::to_string(streams_.id) + " (its components' provided interfaces differ: another system file?)";
}

PeerFreshness::Verdict PeerFreshness::stream(Slot slot, std::int64_t incarnation, std::int64_t seq,
                                             std::int64_t& missed, std::string& why) {
  missed = 0;
  if (const Verdict v = process(incarnation, why); v != Verdict::Accept) return v;
  if (doubt_) return Verdict::Unproven;
  return take(tracked_.at(slot.index), seq, missed, why);
}

PeerFreshness::Verdict PeerFreshness::take(Stream& s, std::int64_t seq, std::int64_t& missed, std::string& why) {
  if (seq <= s.last) {
    // At or below what the proof listed: sent before the process proved itself alive (still on
    // its way) or a replay; either way not taken, and what it held comes again in the republish
    // asked for at the proof.
    if (s.from_proof) return Verdict::Unproven;
    why = "seq " + std::to_string(seq) + " not above " + std::to_string(s.last) + " (stale or replayed)";
    return Verdict::Refuse;
  }
  if (seq - s.last > kMaxSeqJump) {
    why = "seq " + std::to_string(seq) + " jumps more than " + std::to_string(kMaxSeqJump) + " ahead of " +
          std::to_string(s.last);
    return Verdict::Refuse;
  }
  missed = seq - s.last - 1;
  s.last = seq;
  s.from_proof = false;
  s.taken = seq;
  return Verdict::Accept;
}

bool PeerFreshness::proven(const wire::Heartbeat& beat, std::string& why, std::int64_t asked) {
  if (beat.incarnation < incarnation_) {
    why = "a proof of incarnation " + std::to_string(beat.incarnation) + ", older than " + std::to_string(incarnation_);
    return false;
  }
  if (why = other_streams(beat); !why.empty()) return false;
  if (beat.incarnation == incarnation_) {
    if (beat.seq >= heartbeat_seq_) {
      heartbeat_seq_ = beat.seq;
      heartbeat_from_proof_ = true;
    }
  } else {
    incarnation_ = beat.incarnation;
    heartbeat_seq_ = beat.seq;
    heartbeat_from_proof_ = true;
    std::fill(tracked_.begin(), tracked_.end(), Stream{});
  }
  // What the process had sent when it answered: anything at or below it that arrives later is
  // old; what it sends next is above it.
  for (std::size_t i = 0; i < tracked_.size(); ++i) {
    Stream& have = tracked_[i];
    if (beat.states[i] > have.last) {
      have.last = beat.states[i];
      have.from_proof = true;
    }
  }
  doubt_ = false;
  anchor_local_ = asked;
  anchor_remote_ = beat.time;
  return true;
}

// ---- Prover -------------------------------------------------------------------------------------

Prover::Prover(std::shared_ptr<Ice::Communicator> ic, const Keyring& keys,
               std::function<void(const std::string&, const wire::Heartbeat&, std::int64_t)> on_proven,
               std::function<void(const std::string&, const std::string&)> on_refused, std::chrono::milliseconds retry)
    : ic_(std::move(ic)),
      keys_(keys),
      on_proven_(std::move(on_proven)),
      on_refused_(std::move(on_refused)),
      retry_ns_(std::chrono::nanoseconds(retry).count()) {}

namespace {
std::string fresh_nonce() {
  std::string nonce(kNonceBytes, '\0');
  ::randombytes_buf(nonce.data(), nonce.size());
  return nonce;
}
Ice::ByteSeq bytes_of(const std::string& s) { return Ice::ByteSeq(s.begin(), s.end()); }

/// Why `answer` is not `signer`'s proof of `nonce` given at `endpoint` (empty: it is, and `beat` is
/// what it proves).
std::string check_proof(const std::shared_ptr<Ice::Communicator>& ic, const Keyring& keys, const std::string& signer,
                        const std::string& endpoint, const std::string& nonce, const wire::Signed& answer,
                        wire::Heartbeat& beat) {
  if (answer.signer != signer) return "an answer signed '" + printable(answer.signer) + "', not by '" + signer + "'";
  wire::Proof proof;
  if (std::string why = open_signed(keys, ic, answer, kKindProof, proof); !why.empty()) return why;
  if (proof.nonce != bytes_of(nonce)) return "an answer to another nonce (a recorded proof)";
  if (proof.beat.coordinator != signer) return "a proof naming '" + printable(proof.beat.coordinator) + "'";
  if (std::string why = incarnation_out_of_bounds("a proof", signer, proof.beat.incarnation); !why.empty()) return why;
  // The process that signed serves the endpoint its heartbeat names; an answer asked at another
  // one was relayed from it by whoever serves that one.
  if (proof.beat.control != endpoint) {
    return "a proof of the process at '" + printable(proof.beat.control) + "' given at '" + printable(endpoint) +
           "' (relayed)";
  }
  beat = std::move(proof.beat);
  return {};
}
}  // namespace

void Prover::done(const std::string& signer, const std::string& endpoint, const std::string& nonce,
                  const wire::Signed* answer, const std::string& error, std::int64_t sent) {
  {
    std::lock_guard lock(mutex_);
    const auto it = questions_.find(signer);
    if (it == questions_.end() || it->second.nonce != nonce) return;  // superseded
    it->second.open = false;
  }
  wire::Heartbeat beat;
  std::string why = answer != nullptr ? check_proof(ic_, keys_, signer, endpoint, nonce, *answer, beat) : error;
  if (const std::int64_t took = steady_ns() - sent; why.empty() && took > retry_ns_) {
    why = "its answer came " + std::to_string(took / 1'000'000) + " ms after the question, too late to date its " +
          "heartbeats by; asked again";
  }
  if (why.empty()) {
    on_proven_(signer, beat, sent);
  } else if (on_refused_) {
    on_refused_(signer, why);
  }
}

namespace {
/// What an Ice failure says, for a log line.
std::string failure_text(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const Ice::Exception& ex) {
    return ex.ice_id();
  } catch (const std::exception& ex) {
    return ex.what();
  } catch (...) {
  }
  return "unknown";
}
}  // namespace

void Prover::ask(const std::string& signer, const std::string& endpoint) {
  if (endpoint.empty()) return;
  std::shared_ptr<wire::AlivePrx> alive;
  std::string nonce;
  {
    std::lock_guard lock(mutex_);
    Question& q = questions_[signer];  // signers are keyring names: bounded
    const std::int64_t now = steady_ns();
    if (q.open || (q.asked != 0 && now - q.asked < retry_ns_)) return;
    try {
      alive = Ice::uncheckedCast<wire::AlivePrx>(ic_->stringToProxy(endpoint))->ice_invocationTimeout(1000);
    } catch (const Ice::Exception&) {
      q.asked = now;  // a heartbeat naming no endpoint we can use: not proven, asked again later
      return;
    }
    q.nonce = fresh_nonce();
    q.asked = now;
    q.open = true;
    nonce = q.nonce;
  }
  const auto failed = [this, signer, endpoint, nonce](const std::string& what) {
    done(signer, endpoint, nonce, nullptr, what, 0);
  };
  // First the connection, checked to be the signer's own (not_served_by); then the question, on
  // that connection only.
  const auto connected = [this, alive, signer, endpoint, nonce, failed](const std::shared_ptr<Ice::Connection>& con) {
    if (std::string why = not_served_by(ic_, con, signer); !why.empty()) return failed(why);
    try {
      // The question's time: the nonce leaves now, on a connection already made, so the round trip
      // is one request (the answer is refused if it is later than a period).
      const std::int64_t sent = steady_ns();
      alive->ice_fixed(con)->proveAsync(
          bytes_of(nonce),
          [this, signer, endpoint, nonce, sent](const wire::Signed& answer) {
            done(signer, endpoint, nonce, &answer, {}, sent);
          },
          [failed](const std::exception_ptr& e) { failed("its endpoint did not answer (" + failure_text(e) + ")"); });
    } catch (const Ice::Exception& e) {
      failed(std::string("cannot ask it (") + e.ice_id() + ")");
    }
  };
  try {
    alive->ice_getConnectionAsync(connected, [failed](const std::exception_ptr& e) {
      failed("its endpoint did not answer (" + failure_text(e) + ")");
    });
  } catch (const Ice::Exception& e) {
    failed(std::string("cannot ask it (") + e.ice_id() + ")");
  }
}

std::string not_served_by(const std::shared_ptr<Ice::Communicator>& ic,
                          const std::shared_ptr<Ice::Connection>& connection, std::string_view member) {
  if (connection == nullptr) return "no connection";
  const bool tls = !ic->getProperties()->getProperty("IceSSL.CertFile").empty();
  if (!tls) return {};
  std::shared_ptr<Ice::ConnectionInfo> info;
  try {
    info = connection->getInfo();
  } catch (const Ice::Exception& e) {
    return std::string("its connection closed (") + e.ice_id() + ")";
  }
  const auto ssl = std::dynamic_pointer_cast<IceSSL::ConnectionInfo>(info);
  if (ssl == nullptr) return "its endpoint is not TLS, and this system's bus is";
  if (!ssl->verified || ssl->certs.empty()) return "its endpoint showed no verified certificate";
  const IceSSL::DistinguishedName subject = ssl->certs.front()->getSubjectDN();
  if (!subject.match(
          IceSSL::DistinguishedName(std::list<std::pair<std::string, std::string>>{{"CN", std::string(member)}}))) {
    return "its endpoint is served by the certificate of '" + printable(std::string(subject)) + "', not of '" +
           printable(member) + "'";
  }
  return {};
}

[[nodiscard]] Expected<ProvenEndpoint> prove_at(const std::shared_ptr<Ice::Communicator>& ic, const Keyring& keys,
                                                const std::string& member, const std::string& endpoint,
                                                std::chrono::milliseconds timeout) {
  const std::string who = printable(member);
  ProvenEndpoint proven;
  try {
    auto prx = ic->stringToProxy(endpoint)->ice_invocationTimeout(static_cast<int>(timeout.count()));
    auto con = prx->ice_getConnection();
    if (std::string why = not_served_by(ic, con, member); !why.empty()) {
      return fail(ErrorCode::Denied, "'" + who + "' not reached at '" + printable(endpoint) + "': " + why);
    }
    // The connection is the binding: it must outlive idle times (the other side's idle timer sees
    // the heartbeats), and when it ends every request fails rather than reaching a newcomer.
    con->setACM(Ice::nullopt, Ice::ACMClose::CloseOff, Ice::ACMHeartbeat::HeartbeatAlways);
    proven.proxy = prx->ice_fixed(con);
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io, "'" + who + "' not reached at '" + printable(endpoint) + "' (" + e.ice_id() + ")");
  }
  const std::string nonce = fresh_nonce();
  wire::Signed answer;
  try {
    answer = Ice::uncheckedCast<wire::AlivePrx>(proven.proxy)->prove(bytes_of(nonce));
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io, "'" + who + "' did not answer a proof of life (" + e.ice_id() + ")");
  }
  if (std::string why = check_proof(ic, keys, member, endpoint, nonce, answer, proven.beat); !why.empty()) {
    return fail(ErrorCode::Denied, "'" + who + "' gave no valid proof of life: " + why);
  }
  return proven;
}

wire::Signed make_proof(const Signer& signer, const std::shared_ptr<Ice::Communicator>& ic, const Ice::ByteSeq& nonce,
                        wire::Heartbeat beat) {
  if (nonce.size() != kNonceBytes) return {};
  return signer.sign(kKindProof, encode(ic, wire::Proof{nonce, std::move(beat)}));
}

// ---- TopicSubscriber ----------------------------------------------------------------------------

TopicSubscriber::TopicSubscriber(std::shared_ptr<Ice::Communicator> ic, std::string operation,
                                 std::function<void(const wire::Signed&)> handler, std::shared_ptr<DropLog> log,
                                 std::string who)
    : ic_(std::move(ic)),
      operation_(std::move(operation)),
      handler_(std::move(handler)),
      log_(std::move(log)),
      who_(std::move(who)) {}

bool TopicSubscriber::ice_invoke(std::pair<const Ice::Byte*, const Ice::Byte*> in, std::vector<Ice::Byte>& out,
                                 const Ice::Current& current) {
  if (current.requestId != 0) {  // a twoway request (IceStorm sends oneway): an empty answer
    Ice::OutputStream answer(ic_);
    answer.writeEmptyEncapsulation(current.encoding);
    answer.finished(out);
  }
  if (current.operation != operation_) {
    log_->drop("(unknown operation)",
               who_ + ": refused a message for an unknown operation (" + printable(current.operation) + ")");
    return true;
  }
  wire::Signed m;
  bool whole = false;
  try {
    Ice::InputStream encaps(ic_, in);
    encaps.startEncapsulation();
    encaps.read(m);
    encaps.endEncapsulation();
    whole = encaps.pos() == static_cast<std::size_t>(in.second - in.first);
  } catch (...) {
    whole = false;
  }
  if (!whole) {
    log_->drop("(undecodable)", who_ + ": refused a message that does not decode (" + operation_ + ")");
    return true;
  }
  handler_(m);
  return true;
}

// ---- Guard --------------------------------------------------------------------------------------

bool Guard::dispatch(Ice::Request& request) {
  try {
    return servant_->ice_dispatch(request);
  } catch (const Ice::MarshalException&) {
    log_->drop("(undecodable)",
               what_ + ": refused a message that does not decode (" + printable(request.getCurrent().operation) + ")");
    throw;
  } catch (const Ice::RequestFailedException&) {
    log_->drop("(unknown operation)", what_ + ": refused a request for an unknown object or operation (" +
                                          printable(request.getCurrent().operation) + ")");
    throw;
  } catch (const Ice::UserException&) {
    throw;  // an answer (OperationError), not a failure
  } catch (const std::exception& e) {
    log_->drop("(dispatch)", what_ + ": a request failed: " + printable(e.what()));
    throw;
  }
}

void SentDigests::add(Ice::ByteSeq digest) {
  std::lock_guard lock(mutex_);
  now_.push_back(std::move(digest));
  if (now_.size() > kMax) now_.erase(now_.begin());
}

wire::DigestSeq SentDigests::take() {
  std::lock_guard lock(mutex_);
  const std::size_t kept = std::min(before_.size(), kMax - now_.size());
  wire::DigestSeq out(before_.end() - static_cast<std::ptrdiff_t>(kept), before_.end());
  out.insert(out.end(), now_.begin(), now_.end());
  before_ = std::move(now_);
  now_.clear();
  return out;
}

}  // namespace safecass::middleware
