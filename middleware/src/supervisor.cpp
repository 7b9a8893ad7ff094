// The supervisor: the system-wide view and lost-coordinator detection (see supervisor.hpp).

#include "safecass/middleware/supervisor.hpp"
#include "safecass/core/address.hpp"
#include "safecass/core/named.hpp"
#include "safecass/core/text_map.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <unordered_map>

#include "auth.hpp"
#include "bus_link.hpp"
#include "ice_util.hpp"
#include "read_model_wire.hpp"
#include "receiver.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/model.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/spec/instance.hpp"
#include "sleeper.hpp"

namespace safecass::middleware {

struct Supervisor::Impl {
  const spec::SystemSpec& system;
  SupervisorOptions options;
  FilterRegistry builtin;                    ///< the built-in filter types, when the options give no registry
  std::unique_ptr<spec::Instance> instance;  ///< the view: every component of the system, named "supervisor"
  Coordinator& model() noexcept { return instance->coordinator(); }

  /// Event records not received between two that were wait kReorderGrace before they are
  /// reported missed: IceStorm forwards a topic's messages without the "ordered" QoS, so a batch
  /// can arrive after the next one (EventStream).
  static constexpr std::chrono::milliseconds kReorderGrace{250};
  /// Between two of the supervisor's heartbeats (coordinators lose it after their loss bound, 3
  /// heartbeat periods by default: 300 ms).
  static constexpr std::chrono::milliseconds kHeartbeatPeriod{100};

  /// A provided interface of one of a coordinator's components: what an update of it reaches,
  /// found once, so that an update costs no lookup (its stream's position indexes Peer::services).
  struct Service {
    std::string address;     ///< "C.s_S.p", its row in the view
    ViewRow* row = nullptr;  ///< its row once it has one (view's nodes stay put until erased)
  };
  struct Peer {
    std::vector<std::string> components;
    std::vector<Service> services;  ///< by PeerFreshness::Slot::index: one per state stream
    PeerFreshness fresh;            ///< its proven process, heartbeats and state streams
    /// The newest incarnation heard from but not proven yet, and the lowest number of its records
    /// it was heard to have sent (its first heartbeat's list, or its first record's number - 1):
    /// what it sent above that before its proof was not taken, and is reported missed.
    std::int64_t unproven_incarnation = 0;
    std::int64_t unproven_floor = 0;
    /// The proven process's records: joined at its proof of life (which lists the last record
    /// sent, so a record lost after it is a gap, even the first ones). Records up to the join were
    /// sent before: any still on their way are not taken (they cannot be told from replays);
    /// those sent since the supervisor first heard of the process were reported missed at the proof.
    EventStream records;
    MissedRecords missed;        ///< its records missed and not said yet (said by the watch loop)
    std::string control;         ///< its Control proxy, from its last authenticated heartbeat
    bool refresh = false;        ///< records were missed: fetch its state list again
    bool states_behind = false;  ///< the last heartbeat listed state updates not received
    /// The records the last heartbeat believed listed sent (0 when not followed); none since a loss.
    std::optional<std::int64_t> records_listed;
    /// The state streams (PeerFreshness::Slot::index) the last heartbeat listed ahead of what
    /// the view holds, with the numbers it listed: caught up once every one of them has come.
    std::vector<std::pair<std::size_t, std::int64_t>> behind;
    Liveness live;  ///< lost or not, and since when it was heard
  };
  mutable std::mutex mutex;
  std::map<std::string, Peer, std::less<>> peers;
  TextMap<ViewRow> view;  ///< by address: one hash per record or update (view() sorts)

  std::shared_ptr<Ice::Communicator> ic;
  /// The topics the supervisor publishes on, in BusLink's order.
  enum Topic : std::size_t { PublishResync, PublishHeartbeat };
  std::unique_ptr<BusLink> link;
  std::optional<Signer> signer;
  std::optional<Keyring> keyring;
  std::shared_ptr<DropLog> drops;
  std::unique_ptr<Prover> prover;  ///< proves coordinators alive (destroyed after the communicator)
  std::unique_ptr<Members> members;
  std::string alive;  ///< the proxy of its Alive object, named in its heartbeats
  std::int64_t incarnation = new_incarnation();
  std::atomic<std::int64_t> heartbeat_seq{0};
  std::atomic<std::int64_t> resync_seq{0};
  std::atomic<bool> running{false};
  std::atomic<std::int64_t> watching_since{0};  ///< steady_ns() of the first connection to IceStorm
  std::thread watch_thread;
  Sleeper watch_sleeper;  ///< the watch thread's waits: ended by stop(), cut short when a view must be read again
  // Scratch storage of the dispatch thread (Ice's one server thread): reused for every message,
  // so that a steady stream of records and updates does not allocate per record.
  introspect::HistoryEntry record_scratch;
  wire::StateBatch updates_scratch;
  wire::EventMessageSeq events_scratch;
  std::string record_note;  ///< dispatch thread: the note printed with a record (late, taken while lost)
  std::string note_scratch;

  Impl(const spec::SystemSpec& s, SupervisorOptions o) : system(s), options(std::move(o)) {}

  void write_text(const std::string& line) const {
    if (options.print) {
      options.print(line);
    } else {
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    }
  }
  /// One output line; its text is made only if the consumer asks for it.
  void emit(const SupervisorLine& line) const {
    if (options.output) {
      options.output(line);
    } else {
      write_text(line.text());
    }
  }
  /// A notice of the supervisor's own.
  void print(const std::string& line) const {
    if (options.output) {
      options.output(SupervisorLine::notice(line));
    } else {
      write_text(line);
    }
  }

  void refuse(const std::string& source, const std::string& what) {
    drops->drop(source, "supervisor: refused " + what);
  }

  /// Checks a sealed message (state updates, event records) and decodes it; heartbeats, which are
  /// signed, are opened by open_heartbeat().
  template <class Seq>
  bool open(const wire::Signed& m, std::string_view kind, Seq& out) {
    const std::string why = open_sealed(*signer, ic, m, kind, out);
    if (!why.empty()) {
      refuse(m.signer, "a " + std::string(kind) + " message signed '" + printable(m.signer) + "': " + why);
      return false;
    }
    return true;
  }

  /// A process not proven yet, of `incarnation`, was heard to have sent `sent` records (under
  /// `mutex`): see Peer::unproven_floor.
  static void heard_unproven(Peer& peer, std::int64_t incarnation, std::int64_t sent) {
    if (incarnation < peer.unproven_incarnation) return;
    if (incarnation > peer.unproven_incarnation) {
      peer.unproven_incarnation = incarnation;
      peer.unproven_floor = sent;
    } else {
      peer.unproven_floor = std::min(peer.unproven_floor, sent);
    }
  }

  /// A stream message of incarnation `seen` of `who` (under `mutex`): true when it is of the process
  /// proven alive. An older one is a replay (refused); a newer one is a process not proven alive
  /// yet, dropped until its heartbeat is proven (receiver.hpp).
  bool current(Peer& peer, const std::string& who, std::int64_t seen, std::string_view what) {
    std::string why;
    const PeerFreshness::Verdict v = peer.fresh.process(seen, why);
    if (v == PeerFreshness::Verdict::Refuse) refuse(who, std::string(what) + " of '" + printable(who) + "': " + why);
    return v == PeerFreshness::Verdict::Accept;
  }

  /// `beat` of `who` was proven by an answer to our nonce sent at `asked` (Prover, on an Ice thread).
  void on_proven(const std::string& who, const wire::Heartbeat& beat, std::int64_t asked) {
    bool resync = false;
    std::vector<std::string> recovered;
    {
      std::lock_guard lock(mutex);
      const auto p = peers.find(who);
      if (p == peers.end()) return;
      Peer& peer = p->second;
      const std::int64_t known = peer.fresh.incarnation();
      if (std::string why; !peer.fresh.proven(beat, why, asked)) {
        refuse(who, "a proof of life of '" + printable(who) + "': " + why);
        return;
      }
      // Proven anew (first, restarted, or after a loss): what it sent meanwhile is asked again.
      resync = true;
      if (beat.incarnation != known) {
        // A new process: what the view held of an earlier one goes; its records join at what the
        // proof lists as sent, and those it sent before (dropped, unproven) are reported missed.
        if (known != 0) {
          // A Service that points at one of the rows erased points at none (its next update makes
          // the row again); checked by the row's coordinator, so before the rows go.
          for (auto& [_, other] : peers) {
            for (Service& service : other.services) {
              if (service.row != nullptr && service.row->coordinator == who) service.row = nullptr;
            }
          }
          for (auto it = view.begin(); it != view.end();) {
            it = it->second.coordinator == who ? view.erase(it) : std::next(it);
          }
          print("supervisor: coordinator '" + printable(who) + "' restarted; its view is refreshed");
        }
        const std::int64_t joined = beat.events;
        peer.records.join(joined);
        peer.records_listed = joined;
        peer.states_behind = false;
        const std::int64_t heard =
            peer.unproven_incarnation == beat.incarnation ? std::min(peer.unproven_floor, joined) : joined;
        if (options.records && heard < joined) {
          print("supervisor: " + std::to_string(joined - heard) + " event record(s) of '" + printable(who) +
                "' missed (seq " + EventStream::text({heard + 1, joined}) +
                ", sent before it proved itself alive to the supervisor); its view is read again");
          peer.refresh = true;
          watch_sleeper.wake();
        }
        peer.unproven_incarnation = 0;
      }
      believe(beat, peer, asked, recovered, resync);
    }
    if (resync) request_resync(who);
    announce_recovered(who, recovered);
  }

  void request_resync(const std::string& who) {
    const auto pub = Ice::uncheckedCast<wire::ResyncTopicPrx>(link->publisher(PublishResync));
    if (pub == nullptr) return;
    try {
      pub->resync(signer->seal(kKindResync, encode(ic, wire::ResyncRequest{std::string(kSupervisorSigner), incarnation,
                                                                           ++resync_seq, who})));
    } catch (const Ice::Exception&) {
      // The link thread notices and reconnects.
    }
  }

  /// `gap` of `peer`'s records is missed (under `mutex`): the watch loop says so (report_gaps).
  void report_missed(Peer& peer, const EventStream::Range& gap) {
    peer.missed.add(gap);
    peer.refresh = true;  // the missed records may have changed rows: read them again
    watch_sleeper.wake();
  }

  /// Reports the gaps still open kReorderGrace after they opened, and says the records missed
  /// (at most a line a second per coordinator, none left out; every one at once when `stopping`)
  /// (watch loop).
  void report_gaps(std::int64_t now, bool stopping = false) {
    const std::int64_t grace = std::chrono::nanoseconds(kReorderGrace).count();
    std::vector<std::string> lines;
    {
      std::lock_guard lock(mutex);
      for (auto& [name, peer] : peers) {
        while (const auto gap = peer.records.overdue(now, grace)) report_missed(peer, *gap);
        if (auto line = peer.missed.take(now, name, stopping)) lines.push_back("supervisor: " + *line);
      }
    }
    for (const std::string& line : lines) print(line);
  }

  void on_events(const wire::Signed& signed_batch) {
    wire::EventMessageSeq& batch = events_scratch;
    if (!open(signed_batch, kKindEvents, batch)) return;
    for (const wire::EventMessage& m : batch) on_event(signed_batch.signer, m);
  }

  void on_event(const std::string& sender, const wire::EventMessage& m) {
    // Its refusals are rate-limited apart from the sender's other messages: a failover's flood of
    // repeated state updates must not hide what became of a record.
    const auto refuse_record = [&](const std::string& what) { refuse(sender + "/records", what); };
    if (m.coordinator != sender) {
      refuse_record("an event record naming '" + printable(m.coordinator) + "' signed by '" + printable(sender) + "'");
      return;
    }
    State from = State::Normal, to = State::Normal, level = State::Normal;
    if (!from_wire(m.record.from, from) || !from_wire(m.record.to, to) || !from_wire(m.record.level, level)) {
      refuse_record("an event record of '" + printable(m.coordinator) + "' with an invalid level");
      return;
    }
    const bool transition =
        m.record.kind == wire::RecordKind::Transition || m.record.kind == wire::RecordKind::ComponentTransition;
    const bool shown = transition || m.record.kind == wire::RecordKind::Reset;
    introspect::HistoryEntry& entry = record_scratch;
    if (shown) {
      if (!from_wire(m.record, entry)) {
        refuse_record("an event record of '" + printable(m.coordinator) + "' with an unknown kind or outcome");
        return;
      }
      // The address a transition's row is kept under: its machine, or its component.
      if (m.record.kind == wire::RecordKind::Transition ? m.record.machine.empty() : m.record.component.empty()) {
        refuse_record("an event record of '" + printable(m.coordinator) + "' that names no " +
                      (m.record.kind == wire::RecordKind::Transition ? "machine" : "component"));
        return;
      }
    }
    // A member speaks only for the components the system file assigns to it.
    for (const std::string* named : {&m.record.component, &m.record.machine}) {
      if (named->empty() || members->runs(m.coordinator, Members::component_of(*named))) continue;
      refuse_record("an event record of '" + printable(m.coordinator) + "' about '" + printable(*named) +
                    "', a component it does not run");
      return;
    }
    bool late = false;    // below a record received before it: printed as late
    bool masked = false;  // taken while the coordinator is lost, which its rows are shown as
    {
      std::lock_guard lock(mutex);
      const auto p = peers.find(m.coordinator);
      if (p == peers.end()) {
        refuse_record("an event record of '" + printable(m.coordinator) +
                      "', which is not a coordinator of the system");
        return;
      }
      Peer& peer = p->second;
      if (!current(peer, m.coordinator, m.incarnation, "an event record")) {
        if (m.incarnation > peer.fresh.incarnation()) heard_unproven(peer, m.incarnation, m.seq - 1);
        return;
      }
      std::optional<EventStream::Range> range;
      switch (peer.records.take(m.seq, steady_ns(), range)) {
        case EventStream::Took::Next:
          if (range) report_missed(peer, *range);  // pushed out by more open gaps
          break;
        case EventStream::Took::Filled: late = true; break;  // it fills a gap below a record received before it
        case EventStream::Took::Late:
          drops->note(m.coordinator + "/late", "supervisor: event record(s) of '" + printable(m.coordinator) +
                                                   "' reported missed (seq " + EventStream::text(*range) +
                                                   ") arrive late; accepted");
          late = true;
          break;
        case EventStream::Took::LateAgain: late = true; break;
        case EventStream::Took::Early:
          // Sent before the process proved itself alive to the supervisor, still on its way: it may
          // as well be a replay of an older record, so it is not taken (reported missed at the
          // proof when sent since the supervisor first heard of the process).
          return;
        case EventStream::Took::Again:
          refuse_record("an event record of '" + printable(m.coordinator) + "': seq " + std::to_string(m.seq) +
                        " not above " + std::to_string(peer.records.last()) + " and received already (replayed)");
          return;
        case EventStream::Took::TooFar:
          refuse_record("an event record of '" + printable(m.coordinator) + "': seq " + std::to_string(m.seq) +
                        " jumps more than " + std::to_string(kMaxSeqJump) + " ahead");
          return;
      }
      if (!shown) return;
      masked = peer.live.lost();
      if (transition) {
        const std::string_view address = entry.where();  // checked above: a machine, or a component
        auto row = view.find(address);
        if (row == view.end()) row = view.emplace(std::string(address), ViewRow{}).first;
        ViewRow& r = row->second;
        // A record that arrived late never takes a row back to an older state.
        if (r.record_seq < m.seq || r.coordinator != m.coordinator) {
          r.coordinator = m.coordinator;  // assignments into the row's own storage: no allocation once sized
          r.address = address;
          r.state = to;
          r.record_seq = m.seq;
          if (to == State::Normal || !m.record.hasRoot) {
            r.cause.clear();
          } else {
            r.cause.assign(m.record.root.origin).append(":").append(m.record.root.event);
          }
        }
      }
    }
    record_note.clear();
    if (late) record_note.assign("late: seq ").append(std::to_string(m.seq)).append(" arrived after newer records");
    if (masked) {
      // What it did while out of reach, or while it settles its own losses (Liveness::believed):
      // the view shows it lost until it recovers, and then changes once.
      record_note.append(late ? "; " : "").append("while '").append(m.coordinator).append("' is lost");
    }
    emit(SupervisorLine::of_record(m.coordinator, entry, std::string_view(record_note)));
  }

  void on_updates(const wire::Signed& signed_batch) {
    wire::StateBatch& batch = updates_scratch;
    if (!open(signed_batch, kKindState, batch)) return;
    const std::string& from = signed_batch.signer;
    if (batch.coordinator != from) {
      refuse(from, "state updates naming '" + printable(batch.coordinator) + "' signed by '" + printable(from) + "'");
      return;
    }
    const auto p = peers.find(from);  // (peers never change after create())
    if (p == peers.end()) {
      refuse(from, "state updates of '" + printable(from) + "', which is not a coordinator of the system");
      return;
    }
    {
      std::lock_guard lock(mutex);
      if (const std::string why = p->second.fresh.other_streams(batch.statesId); !why.empty()) {
        refuse(from, "state updates of '" + printable(from) + "': " + why);
        return;
      }
    }
    for (const wire::StateUpdate& u : batch.updates) on_update(p->second, batch, u);
  }

  /// An update of `batch`, a batch of `peer`'s list of state streams.
  void on_update(Peer& peer, const wire::StateBatch& batch, const wire::StateUpdate& u) {
    const std::string& from = batch.coordinator;
    State s = State::Normal;
    if (!from_wire(u.state, s)) {
      refuse(from, "a state update of '" + printable(from) + "' with an invalid level");
      return;
    }
    // The note printed with the state: "roots a:b, c:d"; the view keeps the causes after "roots ".
    constexpr std::string_view kRoots = "roots ";
    std::string& note = note_scratch;
    note.assign(kRoots);
    for (const wire::Root& r : u.roots) {
      if (note.size() > kRoots.size()) note.append(", ");
      note.append(r.origin).append(":").append(r.event);
    }
    const std::string_view causes = std::string_view(note).substr(kRoots.size());
    std::string_view address;  // its row: Service::address (peers never change after create())
    {
      std::lock_guard lock(mutex);
      const std::optional<PeerFreshness::Slot> slot = peer.fresh.slot(u.stream);
      if (!slot) {
        refuse(from, "a state update of '" + printable(from) + "' for stream " + std::to_string(u.stream) +
                         ", not one of its " + std::to_string(peer.fresh.size()) + " state streams");
        return;
      }
      Service& service = peer.services[slot->index];
      address = service.address;
      // Each interface's stream numbers its updates 1, 2, 3...: an update not above the last one
      // applied is a replay (or a duplicate) and must not bring back an older state; a gap needs
      // nothing more: this full state supersedes what was missed.
      std::int64_t missed = 0;
      std::string why;
      switch (peer.fresh.stream(*slot, batch.incarnation, u.seq, missed, why)) {
        case PeerFreshness::Verdict::Accept: break;
        case PeerFreshness::Verdict::Covered:           // (heartbeats only)
        case PeerFreshness::Verdict::Unproven: return;  // taken from its republish once proven
        case PeerFreshness::Verdict::Refuse:
          refuse(from, "a state update of '" + printable(from) + "' for " + peer.fresh.iface(*slot) + ": " + why);
          return;
      }
      if (auto& behind = peer.behind; !behind.empty()) {
        std::erase_if(behind, [&](const auto& b) { return b.first == slot->index && u.seq >= b.second; });
        if (behind.empty()) peer.live.caught_up();  // every stream listed ahead has come
      }
      if (service.row == nullptr) service.row = &view.try_emplace(service.address).first->second;
      ViewRow& r = *service.row;
      if (r.address == address && r.coordinator == from && r.state == s && r.cause == causes) return;
      r.coordinator = from;
      r.address = address;
      r.state = s;
      r.cause.assign(causes);
    }
    emit(SupervisorLine::of_state(from, address, s, causes.empty() ? std::string_view() : note));
  }

  void on_beat(const wire::Signed& m) {
    if (link->heard_own(m)) return;
    const OpenedHeartbeat opened = open_heartbeat(*keyring, ic, m);
    if (!opened.why.empty()) {
      refuse(opened.source, opened.why);
      return;
    }
    const wire::Heartbeat& h = opened.beat;
    if (h.coordinator == kSupervisorSigner) {
      if (h.incarnation == incarnation) {
        link->own_heartbeat_heard();  // one of this run not among those sent last (heard_own): late
      } else {
        drops->drop("supervisor/duplicate", "supervisor: another supervisor runs on this bus (incarnation " +
                                                std::to_string(h.incarnation) + ", ours " +
                                                std::to_string(incarnation) + ")");
      }
      return;
    }
    std::vector<std::string> recovered;
    bool resync = false;
    {
      std::lock_guard lock(mutex);
      const auto p = peers.find(h.coordinator);
      if (p == peers.end()) {
        refuse(m.signer, "a heartbeat of '" + printable(h.coordinator) + "', which is not a coordinator of the system");
        return;
      }
      Peer& peer = p->second;
      const std::int64_t known = peer.fresh.incarnation();
      std::string why;
      switch (peer.fresh.heartbeat(h, why)) {
        case PeerFreshness::Verdict::Accept: break;
        case PeerFreshness::Verdict::Unproven: {
          // Believed only on a signed answer to a nonce of ours: a recorded heartbeat has none.
          heard_unproven(peer, h.incarnation, h.events);
          prover->ask(h.coordinator, h.control);
          return;
        }
        case PeerFreshness::Verdict::Covered: return;  // the proof was fresher
        case PeerFreshness::Verdict::Refuse:
          // An older incarnation still beating while a newer one runs: two processes, one name.
          if (h.incarnation < known &&
              steady_ns() - peer.live.last_beat() <= std::chrono::nanoseconds(options.lost_after).count()) {
            drops->drop(h.coordinator + "/duplicate",
                        "supervisor: two processes run coordinator '" + printable(h.coordinator) + "' (incarnations " +
                            std::to_string(h.incarnation) + " and " + std::to_string(known) + ")");
          } else {
            refuse(m.signer, "a heartbeat of '" + printable(h.coordinator) + "': " + why);
          }
          return;
      }
      believe(h, peer, peer.fresh.sent_at(h.time, steady_ns()), recovered, resync);
    }
    if (resync) request_resync(h.coordinator);
    announce_recovered(h.coordinator, recovered);
  }

  /// An authentic heartbeat of the proven process of `h.coordinator`, sent at `sent` (under `mutex`).
  void believe(const wire::Heartbeat& h, Peer& peer, std::int64_t sent, std::vector<std::string>& recovered,
               bool& resync) {
    peer.control = h.control;
    // Records lost with nothing after them (an IceStorm crash at the end of a burst) show only
    // here: the heartbeat lists the last record sent. What the heartbeat two before this one
    // listed and has not come (the records may be on their way on the other topic until then):
    // reported as missed (EventStream::heard).
    const std::int64_t records_sent = options.records ? h.events : 0;
    if (const auto missed = peer.records.heard(records_sent)) {
      report_missed(peer, *missed);
      link->renew({kEventTopic});  // the records may no longer reach us at all
    }
    // The state streams too, whether records are followed or not: an update lost with
    // nothing after it on its interface would leave the view of that service stale. Behind on two
    // heartbeats in a row: the coordinator is asked to republish its full state; behind for
    // longer than the loss bound: lost (watch_loop), as a receiver whose subscription was taken
    // from it hears the heartbeats and not the stream.
    std::int64_t states_missed = 0;
    std::string behind;  // the first state stream it lists ahead of what the view holds
    peer.behind.clear();
    // Ahead of what the view holds (taken), not of what a proof listed.
    peer.fresh.ahead(h, [&](PeerFreshness::Slot slot, std::int64_t listed) {
      states_missed += listed - peer.fresh.taken(slot);
      if (behind.empty()) behind = state_stream(peer.fresh.iface(slot));
      peer.behind.emplace_back(slot.index, listed);
    });
    if (states_missed > 0 && peer.states_behind) {
      drops->note(h.coordinator + "/states-missed", "supervisor: " + std::to_string(states_missed) +
                                                        " state update(s) of '" + printable(h.coordinator) +
                                                        "' missed; asking for its full state");
      resync = true;
      peer.states_behind = false;
    } else {
      peer.states_behind = states_missed > 0;
    }
    if (peer.live.last_beat() == 0) print("supervisor: coordinator '" + h.coordinator + "' is up");
    // Lost if not caught up within the loss bound (watch_loop); back once caught up.
    // Back only over a link that is up: what comes while it reconnects comes through a subscription
    // about to be replaced (as for a coordinator, node.cpp).
    const bool hold = peer.live.lost() && !link->connected();
    // Settling (Liveness::believed): its state is about to change while it clears losses of its own
    // (the supervisor, a provider), or the records that the heartbeat before this one listed have
    // not all come (each topic's link between brokers comes back on its own after a partition;
    // records sent since may still be on their way). After a loss nothing is listed yet: the first
    // heartbeat believed is its proof, and one more is waited for. Its loss clears once that is
    // done, so each row changes once.
    const bool settling = !h.settling.empty() || !peer.records_listed || *peer.records_listed > peer.records.last();
    peer.records_listed = records_sent;
    if (!hold && peer.live.believed(steady_ns(), sent, behind, options.lost_after, settling))
      recovered = peer.components;
  }

  /// The supervisor starts toward safe (DESIGN §7): every coordinator is lost until it is proven
  /// alive and its state is received, and comes back as after a loss (announce_recovered).
  void raise_until_proven() {
    std::vector<std::pair<std::string, std::vector<std::string>>> unproven;
    {
      std::lock_guard lock(mutex);
      for (auto& [name, peer] : peers) {
        if (peer.live.lost() || peer.live.last_beat() != 0) continue;
        peer.live.start_lost(steady_ns());
        unproven.emplace_back(name, peer.components);
      }
    }
    for (const auto& [name, components] : unproven) {
      print("supervisor: coordinator '" + name +
            "' not proven alive yet (the supervisor just started); EVT_COORDINATOR_LOST on its components until it is");
      for (const std::string& c : components) (void)generate(model(), "EVT_COORDINATOR_LOST", address::framework(c));
    }
  }

  void announce_recovered(const std::string& who, const std::vector<std::string>& recovered) {
    if (recovered.empty()) return;
    print("supervisor: coordinator '" + who + "' recovered");
    for (const std::string& c : recovered) (void)generate(model(), "/EVT_COORDINATOR_LOST", address::framework(c));
  }

  /// After records of a coordinator were missed, its rows in the view may be stale: read its
  /// state list (the read model's rows, from its Control object found in its authenticated
  /// heartbeat) and print every row that differs from the view. Never on the dispatch thread.
  void refresh_missed() {
    struct Due {
      std::string name;
      std::string control;       ///< its Control proxy
      std::int64_t seq;          ///< the last record received when the read began
      std::int64_t incarnation;  ///< of its process proven alive
    };
    std::vector<Due> due;
    {
      std::lock_guard lock(mutex);
      for (auto& [name, peer] : peers) {
        if (!peer.refresh || peer.control.empty() || peer.fresh.incarnation() == 0) continue;
        peer.refresh = false;
        due.push_back(Due{name, peer.control, peer.records.last(), peer.fresh.incarnation()});
      }
    }
    for (const auto& [name, control, seq_before, incarnation_before] : due) {
      const std::string who = printable(name);
      std::vector<introspect::StateRow> rows;
      std::map<std::string, std::string> causes;
      // Read only from the process proven alive, over a connection to it (its certificate names
      // it) at the endpoint it proves to serve: a heartbeat of a member names an endpoint, but
      // whoever serves that endpoint speaks for nobody.
      auto proven = prove_at(ic, *keyring, name, control, std::chrono::milliseconds(1000));
      if (!proven || proven->beat.incarnation != incarnation_before) {
        refuse(name, "the state list of '" + who + "' after missed records: " +
                         (proven ? "the process at its endpoint is not the one proven alive" : proven.error().message));
        continue;
      }
      const auto prx = Ice::uncheckedCast<wire::ControlPrx>(proven->proxy);
      try {
        for (const wire::StateEntry& w : prx->stateList("")) {
          introspect::StateRow r;
          if (!from_wire(w, r) || r.kind == introspect::RowKind::System || r.kind == introspect::RowKind::Service)
            continue;
          // A member speaks only for its own components (a coordinator lists the stand-ins of
          // its remote providers too: what it believes of them is not theirs to say).
          if (!members->runs(name, Members::component_of(r.address))) continue;
          if (r.state != State::Normal) {
            // Read after the list, an answer about the row gives the newer state and that
            // state's causes (the machine may have changed between the two requests).
            const introspect::ExplainAnswer why = from_wire(prx->explain(r.address));
            if (why.address == r.address) {
              r.state = why.state;
              for (const Explanation& e : why.conditions) {
                if (e.outstanding || causes[r.address].empty()) causes[r.address] = e.root.name();
              }
            }
          }
          rows.push_back(std::move(r));
        }
      } catch (const wire::OperationError& e) {
        print("supervisor: cannot refresh the view of '" + who + "' after missed records: " + printable(e.message));
        continue;
      } catch (const Ice::Exception& e) {
        print("supervisor: cannot refresh the view of '" + who + "' after missed records: " + e.ice_id());
        continue;
      }
      struct Changed {
        std::string address;
        State state;
        std::string note;
      };
      std::vector<Changed> lines;
      {
        std::lock_guard lock(mutex);
        // The rows are at least as new as every record received when the read began: they are
        // stamped with that record's number, so that an older record arriving late does not take
        // them back. A row a newer record set while the read was on its way is newer than the
        // read's answer may be, and is kept (the read takes several requests; the coordinator
        // goes on).
        for (const introspect::StateRow& r : rows) {
          const auto it = view.find(r.address);
          if (it == view.end() && r.state == State::Normal) continue;  // never reported, still Normal
          if (it != view.end() && it->second.coordinator == name && it->second.record_seq > seq_before) continue;
          const std::string cause = r.state == State::Normal ? std::string() : causes[r.address];
          if (it != view.end() && it->second.state == r.state) continue;
          view[r.address] = ViewRow{name, r.address, r.state, cause, seq_before};
          lines.push_back(
              Changed{r.address, r.state, "refreshed after missed records" + (cause.empty() ? "" : "; root " + cause)});
        }
      }
      for (const Changed& c : lines) emit(SupervisorLine::of_state(name, c.address, c.state, c.note));
    }
  }

  /// Reports the gaps past their grace and says the records missed, reads again the views of
  /// coordinators whose records were missed, and declares lost the coordinators past their bound.
  /// It sleeps until the next of these is due (a loss: Liveness::due; a gap: its grace; a line of
  /// missed records: MissedRecords::due_at), at most the shorter of the two
  /// bounds, since a new duty is due no sooner than that after it starts; a view to read again
  /// wakes it.
  void watch_loop() {
    const std::int64_t cap =
        std::chrono::nanoseconds(std::min<std::chrono::milliseconds>(options.lost_after, kReorderGrace)).count();
    const std::int64_t grace = std::chrono::nanoseconds(kReorderGrace).count();
    const std::chrono::nanoseconds round = subscription_round(kHeartbeatPeriod);
    for (std::int64_t next = steady_ns(); watch_sleeper.sleep_until(next);) {
      const std::int64_t now = steady_ns();
      next = now + cap;
      report_gaps(now);
      drops->flush("supervisor", now);
      refresh_missed();
      // A coordinator of the system file that was never heard from is lost too, once the bound
      // has passed since the supervisor connected: silence is never taken for health.
      const std::int64_t since = watching_since.load();
      struct Lost {
        std::string name;
        std::vector<std::string> components;
        std::string why;
      };
      std::vector<Lost> lost_now;
      std::vector<std::pair<std::string, std::uint32_t>> renew_now;
      {
        std::lock_guard lock(mutex);
        for (auto& [name, peer] : peers) {
          if (std::string why = peer.live.check(now, since, options.lost_after, "the supervisor connected");
              !why.empty()) {
            peer.fresh.doubt();           // back only on a new proof of life, never on a recording of it
            peer.records_listed.reset();  // what it sent while out of reach is not known yet
            lost_now.push_back(Lost{name, peer.components, std::move(why)});
          } else if (const std::uint32_t renewal = peer.live.renew_due(now, round); renewal != 0) {
            renew_now.emplace_back(name, renewal);
          }
          next = std::min(next, peer.live.due(since, options.lost_after, round));
          next = std::min(next, peer.records.overdue_at(grace));
          next = std::min(next, peer.missed.due_at());
        }
      }
      for (const auto& [name, components, why] : lost_now) {
        print("supervisor: coordinator '" + name + "' lost: " + why + "; EVT_COORDINATOR_LOST on its components");
        // Its messages may have stopped reaching the supervisor only (subscriptions taken by
        // another endpoint under its identities): new identities bring them back if it is alive.
        link->renew(peer_topics(name));
        for (const std::string& c : components) (void)generate(model(), "EVT_COORDINATOR_LOST", address::framework(c));
      }
      // Still lost a round on: its subscriptions may have been taken before the loss began (the
      // supervisor's start begins none) or since; new identities again, each round while it lasts.
      for (const auto& [name, renewal] : renew_now) {
        if (renewal == 1)
          print("supervisor: coordinator '" + name +
                "' still lost a subscription round on; subscribing to its topics again under new identities, each "
                "round until it is back");
        link->renew(peer_topics(name), true);
      }
    }
    report_gaps(steady_ns(), true);  // stopping: the records missed that wait for their line are said now
  }

  /// The next heartbeat (`next`), or the last one sent (a proof of life).
  wire::Heartbeat heartbeat(bool next) {
    wire::Heartbeat h;
    h.coordinator = std::string(kSupervisorSigner);
    h.incarnation = incarnation;
    h.time = steady_ns();
    h.seq = next ? ++heartbeat_seq : heartbeat_seq.load();
    h.control = alive;
    static const std::int64_t no_streams = StateStreams::of({}).id;  // it provides no interface
    h.statesId = no_streams;
    return h;
  }

  /// Connected, or subscriptions made again (link thread): every coordinator republishes its state.
  void rejoined() {
    request_resync("");
    // From now on every coordinator of the system file is watched, heard from or not.
    std::int64_t unset = 0;
    (void)watching_since.compare_exchange_strong(unset, steady_ns());
  }
};

namespace {

class AliveServant final : public wire::Alive {
public:
  explicit AliveServant(Supervisor::Impl& d) : d_(d) {}
  wire::Signed prove(wire::Bytes nonce, const Ice::Current&) override {
    return make_proof(*d_.signer, d_.ic, nonce, d_.heartbeat(false));
  }

private:
  Supervisor::Impl& d_;
};
}  // namespace

Expected<std::unique_ptr<Supervisor>> Supervisor::create(const spec::SystemSpec& system, SupervisorOptions options) {
  if (options.ice.port <= 0) return fail(ErrorCode::InvalidArgument, "supervisor: no IceStorm port given");
  auto dir = bus_keys_dir(options.keys_dir);
  if (!dir) return tl::unexpected(dir.error());
  options.tls = tls_from_keys(*dir, options.tls, kSupervisorSigner);
  if (auto r = check_transport("supervisor", options.tls, options.insecure, {options.ice.host, options.listen_host});
      !r) {
    return tl::unexpected(r.error());
  }
  auto impl = std::make_unique<Impl>(system, std::move(options));
  auto keyring = Keyring::load(*dir);
  if (!keyring) return tl::unexpected(keyring.error());
  auto signer = Signer::load(*dir, kSupervisorSigner, *keyring);
  if (!signer) return tl::unexpected(signer.error());
  impl->keyring = std::move(*keyring);
  impl->signer = std::move(*signer);
  if (!impl->options.tls.enabled()) impl->print("supervisor: " + plain_tcp_warning(*dir));
  {
    Impl* d = impl.get();
    impl->drops = std::make_shared<DropLog>([d](const std::string& line) { d->print(line); });
  }
  const FilterRegistry* registry = impl->options.registry;
  if (registry == nullptr) {
    register_builtin_filters(impl->builtin);
    registry = &impl->builtin;
  }
  spec::InstanceOptions view;
  view.name = "supervisor";
  auto built = spec::build_instance(system, *registry, view);
  if (!built) return fail(ErrorCode::InvalidArgument, "supervisor: " + spec::to_text(built.error()));
  impl->instance = std::move(*built);
  for (const auto& [name, components] : system.coordinators) impl->peers[name].components = components;
  impl->members = std::make_unique<Members>(system);
  for (auto& [name, peer] : impl->peers) peer.fresh.follow(impl->members->state_streams(name));
  for (const spec::ComponentSpec& c : system.components) {
    const auto peer = impl->peers.find(impl->members->coordinator_of(c.name));
    if (peer == impl->peers.end()) continue;
    Impl::Peer& to = peer->second;
    to.services.resize(to.fresh.size());
    for (const std::string& p : c.provided) {
      const PeerFreshness::Slot slot = *to.fresh.slot(c.name + "." + p);
      to.services[slot.index].address = address::service(c.name, p);
    }
  }
  Impl* d = impl.get();
  impl->model().subscribe([d](const Record& r) {
    if (r.kind != RecordKind::Transition) return;
    const introspect::HistoryEntry entry = introspect::history_entry(r, d->model());
    d->emit(SupervisorLine::of_record({}, entry));
  });
  return std::unique_ptr<Supervisor>(new Supervisor(std::move(impl)));
}

SupervisorLine SupervisorLine::of_record(std::string_view coordinator, const introspect::HistoryEntry& record,
                                         std::string_view note) noexcept {
  SupervisorLine l;
  l.kind_ = Kind::Record;
  l.coordinator_ = coordinator;
  l.record_ = &record;
  l.note_ = note;
  return l;
}

SupervisorLine SupervisorLine::of_state(std::string_view coordinator, std::string_view address, State state,
                                        std::string_view note) noexcept {
  SupervisorLine l;
  l.kind_ = Kind::State;
  l.coordinator_ = coordinator;
  l.address_ = address;
  l.state_ = state;
  l.note_ = note;
  return l;
}

SupervisorLine SupervisorLine::notice(std::string_view text) noexcept {
  SupervisorLine l;
  l.kind_ = Kind::Notice;
  l.note_ = text;
  return l;
}

std::string SupervisorLine::text() const {
  switch (kind_) {
    case Kind::Record: {
      std::string line = coordinator_.empty() ? "supervisor: " : "[" + std::string(coordinator_) + "] ";
      line += introspect::live_line(*record_);
      if (!note_.empty()) line.append(" (").append(note_).append(")");
      return printable(line);
    }
    case Kind::State:
      return printable("[" + std::string(coordinator_) + "] " + introspect::live_state_line(address_, state_, note_));
    case Kind::Notice: break;
  }
  return std::string(note_);
}

Supervisor::Supervisor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Supervisor::~Supervisor() { stop(); }

Expected<void> Supervisor::start() {
  Impl& d = *impl_;
  if (d.running.load()) return {};
  try {
    d.ic = make_communicator(d.options.tls, d.options.ice);
    auto adapter = d.ic->createObjectAdapterWithEndpoints("SafecassSupervisor",
                                                          protocol(d.options.tls) + " -h " + d.options.listen_host);
    BusLinkOptions bus;
    bus.who = "supervisor";
    bus.publish_on = {kResyncTopic, heartbeat_topic(kSupervisorSigner)};
    bus.heartbeat_topic = Impl::PublishHeartbeat;
    // The monitor is itself monitored (DESIGN §4): coordinators watch this heartbeat.
    bus.period = Impl::kHeartbeatPeriod;
    bus.heartbeat = [&d] { return d.signer->sign(kKindHeartbeat, encode(d.ic, d.heartbeat(true))); };
    bus.rejoined = [&d] { d.rejoined(); };
    bus.log = [&d](const std::string& line) { d.print(line); };
    d.link = std::make_unique<BusLink>(d.ic, d.options.ice, d.options.tls, std::move(bus));
    d.prover = std::make_unique<Prover>(
        d.ic, *d.keyring,
        [&d](const std::string& who, const wire::Heartbeat& beat, std::int64_t asked) {
          d.on_proven(who, beat, asked);
        },
        [&d](const std::string& who, const std::string& why) {
          d.drops->drop(who, "supervisor: '" + printable(who) + "' not proven alive: " + why);
        },
        std::chrono::milliseconds(100));
    auto guarded = [&](std::shared_ptr<Ice::Object> servant) {
      return adapter->addWithUUID(std::make_shared<Guard>(std::move(servant), d.drops, "supervisor"));
    };
    auto subscriber = [&](const char* operation, void (Impl::*handle)(const wire::Signed&)) {
      return add_subscriber(
          adapter,
          std::make_shared<TopicSubscriber>(
              d.ic, operation, [&d, handle](const wire::Signed& m) { (d.*handle)(m); }, d.drops, "supervisor"),
          "safecass-supervisor-" + std::to_string(d.incarnation) + "-" + operation);
    };
    if (d.options.records) d.link->subscribe_to(kEventTopic, subscriber("records", &Impl::on_events));
    auto state = subscriber("updates", &Impl::on_updates);
    auto beat = subscriber("beat", &Impl::on_beat);
    for (const auto& [name, _] : d.peers) {
      d.link->subscribe_to(state_topic(name), state);
      d.link->subscribe_to(heartbeat_topic(name), beat);
    }
    // Its own heartbeat coming back proves its subscriptions work; another supervisor's is said.
    d.link->subscribe_to(heartbeat_topic(kSupervisorSigner), beat);
    d.alive = guarded(std::make_shared<AliveServant>(d))->ice_toString();
    adapter->activate();
  } catch (const Ice::Exception& e) {
    if (d.ic) d.ic->destroy();
    d.ic = nullptr;
    return fail(ErrorCode::Io, std::string("supervisor: cannot listen: ") + e.what());
  }
  d.raise_until_proven();
  d.running.store(true);
  d.link->start();
  d.watch_sleeper.restart();
  d.watch_thread = std::thread([&d] { d.watch_loop(); });
  return {};
}

void Supervisor::stop() noexcept {
  Impl& d = *impl_;
  if (!d.running.exchange(false)) return;
  d.link->stop();
  d.watch_sleeper.stop();
  if (d.watch_thread.joinable()) d.watch_thread.join();
  try {
    d.ic->shutdown();
    d.ic->waitForShutdown();
    d.ic->destroy();
  } catch (...) {
  }
}

std::vector<ViewRow> Supervisor::view() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<ViewRow> out;
  out.reserve(impl_->view.size());
  for (const auto& [_, row] : impl_->view) out.push_back(row);
  std::sort(out.begin(), out.end(), [](const ViewRow& a, const ViewRow& b) { return a.address < b.address; });
  return out;
}

std::vector<std::string> Supervisor::lost() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<std::string> out;
  for (const auto& [name, peer] : impl_->peers) {
    if (peer.live.lost()) out.push_back(name);
  }
  return out;
}

std::uint64_t Supervisor::messages_refused() const { return impl_->drops->count(); }

const Coordinator& Supervisor::model() const { return impl_->model(); }

}  // namespace safecass::middleware
