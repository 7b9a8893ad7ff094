// CoordinatorNode: one coordinator process on IceStorm (see node.hpp for the design).

#include "safecass/middleware/node.hpp"
#include "safecass/core/address.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>

#include "auth.hpp"
#include "bus_link.hpp"
#include "control.hpp"
#include "ice_util.hpp"
#include "read_model_wire.hpp"
#include "receiver.hpp"
#include "safecass/core/id_vector.hpp"
#include "safecass/middleware/keys.hpp"
#include "sleeper.hpp"

namespace safecass::middleware {

namespace {

/// One broker's "HOST:PORT", "PORT", "locator:HOST:PORT" or "NAME=HOST:PORT"; `whole` is the
/// option's text, for errors.
[[nodiscard]] Expected<IceEndpoint> parse_one_broker(std::string_view text, std::string_view whole) {
  IceEndpoint e;
  if (const auto eq = text.find('='); eq != std::string_view::npos) {
    e.name = std::string(text.substr(0, eq));
    text.remove_prefix(eq + 1);
    const bool valid = !e.name.empty() && std::all_of(e.name.begin(), e.name.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_';
    });
    if (!valid)
      return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': broker name '" + e.name +
                                        "' (write NAME=HOST:PORT; a name is letters, digits, '-' and '_')");
    if (text.starts_with(kLocatorPrefix))
      return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': a replicated broker (locator:) is not named");
  }
  if (text.starts_with(kLocatorPrefix)) {
    e.locator = true;
    text.remove_prefix(kLocatorPrefix.size());
    if (text.find(':') == std::string_view::npos)
      return fail(ErrorCode::Parse,
                  "--ice '" + std::string(whole) + "': write locator:HOST:PORT (the IceGrid registry)");
  }
  std::string_view port = text;
  if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    e.host = std::string(text.substr(0, colon));
    port = text.substr(colon + 1);
    if (e.host.empty())
      return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': empty host (write HOST:PORT)");
  }
  int value = 0;
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string_view::npos) {
    return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': the port must be a number (write HOST:PORT)");
  }
  for (char c : port) value = value * 10 + (c - '0');
  if (value < 1 || value > 65535)
    return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': port outside 1-65535");
  e.port = value;
  return e;
}

}  // namespace

[[nodiscard]] Expected<IceEndpoint> parse_ice_endpoint(std::string_view whole) {
  const auto comma = whole.find(',');
  auto e = parse_one_broker(whole.substr(0, comma), whole);
  if (!e || comma == std::string_view::npos) return e;
  if (e->locator)
    return fail(ErrorCode::Parse, "--ice '" + std::string(whole) +
                                      "': a replicated broker (locator:) and one broker per host (a list) exclude "
                                      "each other");
  std::string_view rest = whole.substr(comma + 1);
  while (true) {
    const auto next = rest.find(',');
    const std::string_view text = rest.substr(0, next);
    auto peer = parse_one_broker(text, whole);
    if (!peer) return peer;
    if (peer->locator)
      return fail(ErrorCode::Parse, "--ice '" + std::string(whole) + "': peer '" + std::string(text) +
                                        "' is a locator; one broker per host names each host's IceStorm as "
                                        "NAME=HOST:PORT");
    const auto same = [&](const IceEndpoint& other) { return other.host == peer->host && other.port == peer->port; };
    if (same(*e) || std::any_of(e->peers.begin(), e->peers.end(), same))
      return fail(ErrorCode::Parse,
                  "--ice '" + std::string(whole) + "': broker '" + std::string(text) + "' is given twice");
    const auto same_name = [&](const IceEndpoint& other) { return other.name == peer->name; };
    if (e->name.empty() || peer->name.empty() || same_name(*e) ||
        std::any_of(e->peers.begin(), e->peers.end(), same_name))
      return fail(ErrorCode::Parse, "--ice '" + std::string(whole) +
                                        "': with one broker per host, name each broker once (NAME=HOST:PORT, as "
                                        "scripts/start-icestorm --name NAME runs it): IceStorm tells the brokers' "
                                        "topics apart by their names");
    e->peers.push_back(std::move(*peer));
    if (next == std::string_view::npos) return e;
    rest.remove_prefix(next + 1);
  }
}

IceEndpoint tools_broker(IceEndpoint members) {
  members.tools = true;
  if (!members.locator) ++members.port;
  return members;
}

std::string instance_name(const IceEndpoint& ice) {
  const std::string instance(ice.tools ? kToolStormInstance : kIceStormInstance);
  return ice.name.empty() ? instance : instance + "." + ice.name;
}

std::string to_string(const IceEndpoint& ice) {
  std::string text = (ice.locator ? std::string(kLocatorPrefix) : std::string()) +
                     (ice.name.empty() ? std::string() : ice.name + "=") + ice.host + ":" + std::to_string(ice.port);
  for (const IceEndpoint& peer : ice.peers) text += "," + to_string(peer);
  return text;
}

namespace {
const spec::ComponentSpec* find_spec(const spec::SystemSpec& system, std::string_view name) {
  for (const auto& c : system.components) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

bool same_roots(const wire::RootSeq& a, const wire::RootSeq& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const wire::Root& x = a[i];
    const wire::Root& y = b[i];
    if (x.event != y.event || x.origin != y.origin || x.time != y.time || x.level != y.level || x.path != y.path) {
      return false;
    }
  }
  return true;
}
}  // namespace

[[nodiscard]] Expected<void> connect_remote_providers(const spec::SystemSpec& system, std::string_view coordinator_name,
                                                      Coordinator& coordinator) {
  const Members members(system);
  if (std::none_of(system.coordinators.begin(), system.coordinators.end(),
                   [&](const auto& c) { return c.first == coordinator_name; })) {
    return fail(ErrorCode::NotFound,
                "system '" + system.name + "' has no coordinator '" + std::string(coordinator_name) + "'");
  }
  for (const spec::ConnectionSpec& k : system.connections) {
    const std::string_view client = Members::component_of(k.required);
    const std::string provider(Members::component_of(k.provided));
    const std::string_view runs_provider = members.coordinator_of(provider);
    if (members.coordinator_of(client) != coordinator_name || runs_provider.empty() ||
        runs_provider == coordinator_name)
      continue;
    State propagate = State::Error;
    const std::string iface = k.provided.substr(k.provided.find('.') + 1);
    if (const spec::ComponentSpec* spec = find_spec(system, provider)) {
      for (const spec::ServiceSpec& s : spec->services) {
        if (s.provided == iface) propagate = s.dependency.propagate;
      }
    }
    if (!coordinator.structure().find_machine(address::provided(provider, iface))) {
      if (auto r = coordinator.add_remote_provided(k.provided, propagate); !r) return tl::unexpected(r.error());
    }
    if (auto r = coordinator.connect(k.required, k.provided); !r) return tl::unexpected(r.error());
  }
  return {};
}

// ---- the node ---------------------------------------------------------------------------------

struct CoordinatorNode::Impl {
  Coordinator& co;
  Monitor& monitor;
  const FilterRegistry& registry;
  const spec::SystemSpec& system;
  std::string name;
  NodeOptions options;
  std::int64_t incarnation = 0;
  Members members;  ///< which coordinator runs each component

  /// Log lines about messages too large to send whole (publisher thread): at most one per second
  /// per interface (and one for event records), with the number of similar ones in between. The
  /// counters in NodeStats count every one.
  struct OversizeLog {
    std::int64_t logged = 0;  ///< steady ns of the last line
    std::uint64_t quiet = 0;  ///< similar cases since then, not logged
  };

  /// A provided interface of a local component: one state stream.
  struct Stream {
    ComponentId component;
    std::uint32_t provided;
    std::string iface;          ///< "C.p"
    std::int32_t position = 0;  ///< among the process's streams in StateStreams order (wire::StateUpdate::stream)
    std::atomic<std::int64_t> seq{0};
    wire::RootSeq last;  ///< publisher thread only: the full state last sent (all its roots)
    bool dirty = true;   ///< under queue_mutex
    bool force = true;
    OversizeLog oversize;  ///< publisher thread only
  };
  std::vector<std::unique_ptr<Stream>> streams;
  IdVector<std::vector<std::size_t>, ComponentId> streams_of;
  /// The streams in the order its heartbeats list their numbers (StateStreams), and that list's id.
  std::vector<std::size_t> heartbeat_order;
  std::int64_t states_id = 0;
  /// The encoding of this process's wire::StateBatch without its updates, up to their sequence
  /// (its last member): what every state message's body starts with (encode_states).
  Ice::ByteSeq state_head;

  /// A remote provided interface held here (under peer_mutex).
  struct Held {
    MachineId proxy;
    std::string provider;          ///< the coordinator that runs the provider
    PeerFreshness::Slot slot;      ///< its stream in the provider's PeerFreshness
    std::int64_t incarnation = 0;  ///< of the provider process whose update the held state is
    std::int64_t last_seq = 0;     ///< the last update applied, of that incarnation
    bool behind = false;           ///< a heartbeat said we missed its last update
  };
  std::map<std::string, Held, std::less<>> held;
  /// Another signer on the bus (a coordinator, or the supervisor), as its authenticated
  /// messages describe it (under peer_mutex).
  struct Peer {
    PeerFreshness fresh;                  ///< its proven process, heartbeats and state streams
    std::int64_t resync_incarnation = 0;  ///< of its last accepted resync request
    std::int64_t resync_seq = 0;          ///< last accepted resync request of that incarnation
    std::int64_t last_resync = 0;         ///< when we last asked it to republish
    Liveness live;                        ///< lost or not, and since when it was heard
    std::int64_t last_honoured = 0;       ///< when we last republished at its request
    bool resync_pending = false;          ///< a request arrived too soon after the last one
    bool provider = false;                ///< it runs a provider of an interface held here
    std::vector<MachineId> feeds;         ///< required interfaces here that it feeds
    std::size_t behind = 0;               ///< interfaces held of it that a heartbeat showed ahead
    /// What its updates reach here, by their stream's position (PeerFreshness::Slot::index):
    /// the interface held of it, or null for one no component here requires (a provider only).
    std::vector<Held*> held;
  };
  std::map<std::string, Peer, std::less<>> peers;
  std::vector<std::string> cleared_since_heartbeat;  ///< under peer_mutex: losses cleared since (Heartbeat::settling)
  std::mutex peer_mutex;  ///< held, peers; taken before a coordinator write, never inside an observer
  std::int64_t started = 0;

  std::mutex queue_mutex;
  std::condition_variable queue_cv;
  std::deque<Record> records;
  bool any_dirty = true;
  bool publisher_holds_events = false;  ///< the publisher has event records it has not sent yet
  static constexpr std::size_t kQueueCapacity = 65536;
  /// Updates (or records) per Ice message: one message carries every interface that changed.
  static constexpr std::size_t kMaxBatch = 256;
  /// How long event records may wait behind state updates.
  static constexpr std::chrono::milliseconds kEventDelay{5};

  std::shared_ptr<Ice::Communicator> ic;
  std::shared_ptr<Ice::ObjectAdapter> adapter;
  /// The topics this process publishes on, in BusLink's order.
  enum Topic : std::size_t { PublishState, PublishEvents, PublishHeartbeat, PublishResync };
  std::unique_ptr<BusLink> link;
  std::string control;

  std::atomic<bool> running{false};
  std::atomic<std::int64_t> event_seq{0};
  std::atomic<std::int64_t> heartbeat_seq{0};  ///< the last heartbeat sent
  std::atomic<std::int64_t> resync_seq{0};
  std::optional<Signer> signer;
  SentDigests sent_events;  ///< what the next heartbeats vouch for to keyring-only readers
  std::optional<Keyring> keyring;
  std::shared_ptr<DropLog> drops;
  std::unique_ptr<Prover> prover;  ///< proves peers' processes alive (destroyed after the communicator)
  std::thread watch_thread;
  Sleeper watch_sleeper;  ///< the watch thread's waits, ended by stop()
  std::thread publisher_thread;
  Coordinator::SubscriptionId subscription = 0;

  std::atomic<std::uint64_t> updates_published{0}, updates_applied{0}, updates_rejected{0}, updates_missed{0},
      events_published{0}, events_dropped{0}, resyncs_requested{0}, state_messages_published{0},
      event_messages_published{0}, providers_lost{0}, duplicates_seen{0}, oversized_messages{0}, roots_truncated{0},
      updates_unproven{0};
  OversizeLog record_oversize;  ///< publisher thread only

  Impl(Coordinator& c, Monitor& m, const FilterRegistry& r, const spec::SystemSpec& s, std::string n, NodeOptions o)
      : co(c), monitor(m), registry(r), system(s), name(std::move(n)), options(std::move(o)), members(s) {}

  void log(const std::string& line) const {
    if (options.log) {
      options.log(line);
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
    }
  }

  // -- coordinator side (an observer, on the writing thread: no network, no blocking) --
  void on_record(const Record& r) {
    // Wakes the publisher only when it has something to do now: an interface that was clean
    // became dirty, the first event record while it holds none (it starts the kEventDelay
    // clock), or a full batch of records. Every other record only joins the queue.
    bool wake = false;
    {
      std::lock_guard lock(queue_mutex);
      // Every record travels, event records too (a follower shows the stream, never a second
      // fetch of it); records of stand-ins for remote components are that component's process's.
      if (!(to_index(r.component) < co.structure().component_count() && co.structure().is_remote(r.component))) {
        if (records.size() < kQueueCapacity) {
          records.push_back(r);
          wake = (records.size() == 1 && !publisher_holds_events) || records.size() == kMaxBatch;
        } else {
          events_dropped.fetch_add(1, std::memory_order_relaxed);
        }
      }
      if (streams_of.contains(r.component)) {
        for (std::size_t i : streams_of[r.component]) {
          wake = wake || !streams[i]->dirty;
          streams[i]->dirty = true;
          any_dirty = true;
        }
      }
    }
    if (wake) queue_cv.notify_one();
  }

  void mark_all(bool force) {
    {
      std::lock_guard lock(queue_mutex);
      for (auto& s : streams) {
        s->dirty = true;
        s->force = s->force || force;
      }
      any_dirty = true;
    }
    queue_cv.notify_one();
  }

  // -- publisher thread --
  wire::EventMessage to_message(const Record& r) {
    wire::EventMessage m{};  // every field set: no indeterminate enumerator reaches the encoder
    m.coordinator = name;
    m.incarnation = incarnation;
    m.seq = ++event_seq;
    m.record = to_wire(introspect::history_entry(r, co));
    return m;
  }

  /// Appends to `out` the full state of `s` when it differs from the last one sent (or `force`).
  /// Nothing about the stream changes until the batch is sent (commit()).
  void snapshot_stream(Stream& s, bool force, wire::StateUpdateSeq& out, std::vector<Stream*>& of) {
    wire::RootSeq roots;
    std::vector<RemoteRoot> now = co.service_roots(s.component, s.provided);
    roots.reserve(now.size());
    for (RemoteRoot& r : now) {
      roots.push_back(root_to_wire(r.root, to_wire(r.level), std::move(r.path)));
    }
    if (!force && same_roots(roots, s.last)) return;
    wire::StateUpdate u{};  // sent: stamped when its message goes (send_states)
    u.stream = s.position;
    u.seq = s.seq.load() + 1;
    u.state = to_wire(co.service_state(s.component, s.provided));
    u.roots = std::move(roots);
    out.push_back(std::move(u));
    of.push_back(&s);
  }

  // -- message size (publisher thread): every body is measured before it is sealed and sent --

  /// Bytes of the size prefix of a sequence (or string) of `n` elements in the Ice encoding.
  static std::size_t size_prefix(std::size_t n) noexcept { return n < 255 ? 1 : 5; }

  /// The body of a state message of the updates [first, first + n): the bytes encode() gives for
  /// a wire::StateBatch of this process holding only them, without copying them into one. The
  /// batch's other members come first in its encoding (state_head, made once).
  Ice::ByteSeq encode_states(const wire::StateUpdateSeq& items, std::size_t first, std::size_t n) const {
    Ice::OutputStream out(ic);
    out.writeBlob(state_head);
    out.writeSize(static_cast<Ice::Int>(n));
    for (std::size_t i = first; i < first + n; ++i) out.write(items[i]);
    Ice::ByteSeq bytes;
    out.finished(bytes);
    return bytes;
  }

  /// How many of the `n` items from `first` fit in one message whose body holds `head` bytes
  /// before the sequence (at least one: an item too large on its own is cut down by the caller).
  /// Measured item by item, only for a batch that does not fit as a whole.
  template <class T>
  std::size_t fitting(const std::vector<T>& items, std::size_t first, std::size_t n, std::size_t head) const {
    std::size_t total = head;
    std::size_t k = 0;
    for (; k < n; ++k) {
      const std::size_t size = encode(ic, items[first + k]).size();
      if (k > 0 && size_prefix(k + 1) + total + size > options.max_message_bytes) break;
      total += size;
    }
    return std::max<std::size_t>(k, 1);
  }

  /// Logs `line`, at most once per second per `log_of`, saying how many similar cases were not.
  void log_oversize(OversizeLog& log_of, const std::string& line) {
    const std::int64_t now = steady_ns();
    if (log_of.logged != 0 && now - log_of.logged < 1'000'000'000) {
      ++log_of.quiet;
      return;
    }
    const std::uint64_t quiet = log_of.quiet;
    log_of.logged = now;
    log_of.quiet = 0;
    log(line +
        (quiet == 0 ? std::string() : " (and " + std::to_string(quiet) + " similar case(s) since the last such line)"));
  }

  /// A state update too large for one message on its own: keeps the roots that fit, the most
  /// severe first (Error, then Warning, each in the provider's order, skipping a root too large
  /// while a smaller one still fits), so the client's view is never better than the provider's;
  /// `full` receives the whole state (what the stream records as sent). Logs and counts it.
  /// Returns false, and sends nothing, when no root of the service's level fits (a root or a
  /// name of megabytes): a cut without one would show the client a better state.
  bool cut_roots(Stream& s, wire::StateUpdate& u, std::size_t size, wire::RootSeq& full) {
    const std::size_t limit = options.max_message_bytes;
    full = std::move(u.roots);
    u.roots.clear();
    // One update in a batch, with an empty root sequence (whose size is one byte).
    const std::size_t base = state_head.size() + size_prefix(1) + encode(ic, u).size() - size_prefix(0);
    std::vector<std::size_t> order(full.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return full[a].level > full[b].level; });
    std::size_t used = base + size_prefix(0);
    for (std::size_t i : order) {
      const std::size_t root = encode(ic, full[i]).size();
      const std::size_t grown = used - size_prefix(u.roots.size()) + size_prefix(u.roots.size() + 1) + root;
      if (grown > limit) continue;
      used = grown;
      u.roots.push_back(full[i]);
    }
    const std::size_t left_out = full.size() - u.roots.size();
    oversized_messages.fetch_add(1, std::memory_order_relaxed);
    roots_truncated.fetch_add(left_out, std::memory_order_relaxed);
    const std::string what = "middleware: " + name + ": state update of " + s.iface + " (seq " + std::to_string(u.seq) +
                             ") is " + std::to_string(size) + " bytes, over the " + std::to_string(limit) +
                             "-byte message limit: ";
    wire::Level kept = wire::Level::Normal;
    for (const wire::Root& r : u.roots) kept = std::max(kept, r.level);
    if (used > limit || (!full.empty() && kept < u.state)) {
      // Sending fewer roots than the service's level needs would show the client a better state
      // than the provider's: nothing is sent instead (a root or a name of megabytes).
      State level = State::Error;
      from_wire(u.state, level);
      log_oversize(s.oversize, what + "not sent: no root of its level (" + std::string(to_string(level)) +
                                   ") fits in a message; clients keep its previous state");
      u.roots = std::move(full);
      return false;
    }
    log_oversize(s.oversize, what + "sent with " + std::to_string(u.roots.size()) + " of its " +
                                 std::to_string(full.size()) + " roots, the most severe first; " +
                                 std::to_string(left_out) + " left out");
    return true;
  }

  /// An event record too large for one message on its own: its text is cut to what fits, on a
  /// UTF-8 boundary, and marked; logged and counted. False when it does not fit even without its
  /// text: then it is not sent (logged, counted as dropped).
  bool cut_text(wire::EventMessage& m, RecordKind kind, std::size_t size) {
    const std::size_t limit = options.max_message_bytes;
    oversized_messages.fetch_add(1, std::memory_order_relaxed);
    const std::string what =
        "middleware: " + name + ": event record seq " + std::to_string(m.seq) + " (" + std::string(to_string(kind)) +
        " of " + printable(m.record.machine.empty() ? m.record.component : m.record.machine) + ") is " +
        std::to_string(size) + " bytes, over the " + std::to_string(limit) + "-byte message limit: ";
    std::string text = std::move(m.record.text);
    const std::string mark = " [cut: " + std::to_string(text.size()) + " bytes]";
    m.record.text.clear();
    // One record in a sequence; its text's size prefix may grow from 1 to 5 bytes.
    const std::size_t base = size_prefix(1) + encode(ic, m).size() + 4 + mark.size();
    if (base > limit) {
      events_dropped.fetch_add(1, std::memory_order_relaxed);
      log_oversize(record_oversize,
                   what + "dropped: it does not fit even without its " + std::to_string(text.size()) + "-byte text");
      return false;
    }
    std::size_t keep = std::min(text.size(), limit - base);
    while (keep > 0 && keep < text.size() && (static_cast<unsigned char>(text[keep]) & 0xC0) == 0x80) --keep;
    m.record.text = text.substr(0, keep) + mark;
    log_oversize(record_oversize, what + "sent with its text cut from " + std::to_string(text.size()) + " to " +
                                      std::to_string(keep) + " bytes");
    return true;
  }

  /// Publishes the state updates of one cycle, at most kMaxBatch and max_message_bytes per
  /// message (a batch that does not fit is split, an update that does not fit alone is cut down,
  /// cut_roots()), stamped with the send time. A stream's sequence number and last state advance
  /// only once its message is sent.
  void send_states(wire::StateUpdateSeq& updates, const std::vector<Stream*>& of,
                   const std::shared_ptr<wire::StateTopicPrx>& pub) {
    std::size_t first = 0;
    while (first < updates.size()) {
      std::size_t n = std::min(updates.size() - first, kMaxBatch);
      const std::int64_t sent = steady_ns();
      for (std::size_t i = first; i < first + n; ++i) updates[i].sent = sent;
      Ice::ByteSeq body = encode_states(updates, first, n);
      wire::RootSeq full;  // the whole state of an update sent cut down
      bool cut = false;
      if (body.size() > options.max_message_bytes) {
        n = fitting(updates, first, n, state_head.size());
        body = encode_states(updates, first, n);
        if (body.size() > options.max_message_bytes) {  // n == 1: one update too large on its own
          if (!cut_roots(*of[first], updates[first], body.size(), full)) {
            ++first;  // not sent: its stream stays where it was
            continue;
          }
          cut = true;
          body = encode_states(updates, first, 1);
        }
      }
      pub->updates(signer->seal(kKindState, std::move(body)));
      state_messages_published.fetch_add(1, std::memory_order_relaxed);
      for (std::size_t i = first; i < first + n; ++i) {
        Stream& s = *of[i];
        s.seq.store(updates[i].seq);
        // NOLINTNEXTLINE(bugprone-use-after-move): a cut update is always sent alone (n == 1), so full moves once
        s.last = cut ? std::move(full) : std::move(updates[i].roots);
        updates_published.fetch_add(1, std::memory_order_relaxed);
      }
      first += n;
    }
  }

  /// Publishes the queued event records, at most kMaxBatch and max_message_bytes per message (a
  /// record too large on its own goes out with its text cut, cut_text()); those sent leave
  /// `pending`.
  void send_events(std::vector<Record>& pending, const std::shared_ptr<wire::EventTopicPrx>& pub) {
    std::size_t sent = 0;
    try {
      while (sent < pending.size()) {
        std::size_t n = std::min(pending.size() - sent, kMaxBatch);
        wire::EventMessageSeq part;
        part.reserve(n);
        const std::int64_t seq_before = event_seq.load();
        for (std::size_t i = 0; i < n; ++i) part.push_back(to_message(pending[sent + i]));
        Ice::ByteSeq body = encode(ic, part);
        if (body.size() > options.max_message_bytes) {
          n = fitting(part, 0, n, 0);
          part.resize(n);
          event_seq.store(seq_before + static_cast<std::int64_t>(n));  // the others go next, with these numbers
          body = encode(ic, part);
          if (body.size() > options.max_message_bytes && !cut_text(part[0], pending[sent].kind, body.size())) {
            sent += 1;  // dropped (logged, counted): its number stays used, a gap receivers see
            continue;
          }
          body = encode(ic, part);
        }
        try {
          wire::Signed sealed = signer->seal(kKindEvents, std::move(body));
          Ice::ByteSeq digest = Signer::digest_of(sealed);
          pub->records(sealed);
          sent_events.add(std::move(digest));
        } catch (...) {
          event_seq.store(seq_before);  // not sent: the same numbers go out after the reconnection
          throw;
        }
        event_messages_published.fetch_add(1, std::memory_order_relaxed);
        events_published.fetch_add(n, std::memory_order_relaxed);
        sent += n;
      }
    } catch (...) {
      pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(sent));
      throw;
    }
    pending.clear();
  }

  void publisher_loop() {
    // State updates go out as soon as an interface is dirty (other processes' safety depends on
    // them). Event records are held here and sent kEventDelay after the oldest was queued, or as
    // soon as kMaxBatch are waiting: a few messages per second instead of one per record.
    std::vector<Record> events;
    std::int64_t oldest_event = 0;
    std::vector<std::pair<std::size_t, bool>> todo;
    wire::StateUpdateSeq updates;
    std::vector<Stream*> updated;
    TypedPublisher<wire::StateTopicPrx> state_publisher(*link, PublishState);
    TypedPublisher<wire::EventTopicPrx> event_publisher(*link, PublishEvents);
    const std::int64_t delay = std::chrono::nanoseconds(kEventDelay).count();
    while (running.load()) {
      todo.clear();
      {
        std::unique_lock lock(queue_mutex);
        if (!link->connected()) {
          queue_cv.wait_for(lock, std::chrono::milliseconds(20));
          continue;  // records and dirty marks wait (bounded) for the reconnection
        }
        const bool holding = !events.empty();
        publisher_holds_events = holding;
        auto ready = [&] {
          return !running.load() || any_dirty || records.size() >= kMaxBatch || (!holding && !records.empty());
        };
        if (holding) {
          const auto due = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(oldest_event + delay));
          queue_cv.wait_until(lock, due, ready);
        } else {
          queue_cv.wait_for(lock, std::chrono::milliseconds(50), ready);
        }
        if (!records.empty()) {
          if (events.empty()) oldest_event = steady_ns();
          for (const Record& r : records) {
            if (events.size() < kQueueCapacity) {
              events.push_back(r);
            } else {
              events_dropped.fetch_add(1, std::memory_order_relaxed);
            }
          }
          records.clear();
        }
        publisher_holds_events = !events.empty();
        if (any_dirty) {
          for (std::size_t i = 0; i < streams.size(); ++i) {
            if (!streams[i]->dirty) continue;
            todo.emplace_back(i, streams[i]->force);
            streams[i]->dirty = false;
            streams[i]->force = false;
          }
          any_dirty = false;
        }
      }
      const auto& spub = state_publisher.get();
      const auto& epub = event_publisher.get();
      if (spub == nullptr || epub == nullptr) {
        redo(todo);
        continue;
      }
      updates.clear();
      updated.clear();
      try {
        for (const auto& [i, force] : todo) snapshot_stream(*streams[i], force, updates, updated);
        send_states(updates, updated, spub);
        todo.clear();
        if (!events.empty() && (steady_ns() - oldest_event >= delay || events.size() >= kMaxBatch)) {
          send_events(events, epub);
        }
      } catch (const Ice::Exception& e) {
        log("middleware: " + name + ": publishing failed (" + std::string(e.ice_id()) + "); will reconnect and resync");
        link->reconnect();
        redo(todo);
      }
    }
  }

  /// Marks streams dirty again after a cycle that could not send them.
  void redo(const std::vector<std::pair<std::size_t, bool>>& todo) {
    std::lock_guard lock(queue_mutex);
    for (const auto& [i, force] : todo) {
      streams[i]->dirty = true;
      streams[i]->force = streams[i]->force || force;
    }
    any_dirty = any_dirty || !todo.empty();
  }

  // -- link thread (BusLink) --

  /// Connected, or subscriptions made again: everything is republished, and every provider asked to.
  void rejoined() {
    mark_all(true);
    Ice::uncheckedCast<wire::ResyncTopicPrx>(link->publisher(PublishResync))->resync(resync_request(""));
    resyncs_requested.fetch_add(1);
  }

  /// A sealed request that `target` (empty: everybody) republish its full state.
  wire::Signed resync_request(const std::string& target) {
    const wire::ResyncRequest r{name, incarnation, ++resync_seq, target};
    return signer->seal(kKindResync, encode(ic, r));
  }

  /// The next heartbeat (`next`), or the current one, as the last heartbeat sent said it, with
  /// the streams' numbers of now (a proof of life).
  wire::Heartbeat heartbeat(bool next = true) {
    wire::Heartbeat h;
    h.coordinator = name;
    h.incarnation = incarnation;
    h.time = steady_ns();
    h.seq = next ? ++heartbeat_seq : heartbeat_seq.load();
    h.states.reserve(heartbeat_order.size());
    for (const std::size_t i : heartbeat_order) h.states.push_back(streams[i]->seq.load());
    h.statesId = states_id;
    h.events = event_seq.load();
    if (!next) {  // a proof: its components, which never change within a process
      const Structure& shape = co.structure();
      for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
        if (!shape.is_remote(c)) h.components.emplace_back(shape.component_name(c));
      }
    }
    {
      std::lock_guard lock(peer_mutex);
      // Its receivers keep its loss until it has cleared its own (Liveness::believed): those it
      // holds now, and those cleared since the last heartbeat, whose state may not be sent yet. A
      // peer never heard (a supervisor not started) is not coming back after a partition: not
      // listed, or every receiver would wait the whole limit.
      for (const auto& [who, peer] : peers) {
        if (peer.live.lost() && peer.live.last_beat() != 0) h.settling.push_back(who);
      }
      for (const std::string& who : cleared_since_heartbeat) {
        if (std::find(h.settling.begin(), h.settling.end(), who) == h.settling.end()) h.settling.push_back(who);
      }
      if (next) cleared_since_heartbeat.clear();
    }
    h.control = control;
    if (next) h.sentEvents = sent_events.take();
    return h;
  }

  // -- Ice dispatch thread: every message is checked before anything in it is believed --

  /// Refuses a message: counted, logged (rate-limited per source).
  void refuse(const std::string& source, const std::string& what) {
    drops->drop(source, "middleware: " + name + ": refused " + what);
  }

  void on_updates(const wire::Signed& m) {
    wire::StateBatch batch;
    if (const std::string why = open_sealed(*signer, ic, m, kKindState, batch); !why.empty()) {
      updates_rejected.fetch_add(1);
      refuse(m.signer, "a state message signed '" + printable(m.signer) + "': " + why);
      return;
    }
    if (batch.coordinator != m.signer) {
      updates_rejected.fetch_add(1);
      refuse(m.signer, "state updates from coordinator '" + printable(batch.coordinator) + "': signed by '" +
                           printable(m.signer) + "', not by the coordinator it names");
      return;
    }
    if (batch.coordinator == name) return;
    std::lock_guard lock(peer_mutex);
    const auto peer = peers.find(batch.coordinator);
    if (peer == peers.end() || !peer->second.provider) {
      updates_rejected.fetch_add(1);
      refuse(m.signer, "state updates from coordinator '" + printable(batch.coordinator) +
                           "', which provides no interface held here");
      return;
    }
    if (const std::string why = peer->second.fresh.other_streams(batch.statesId); !why.empty()) {
      updates_rejected.fetch_add(1);
      refuse(m.signer, "state updates from coordinator '" + printable(batch.coordinator) + "': " + why);
      return;
    }
    for (const wire::StateUpdate& u : batch.updates) on_update(peer->second, batch, u);
  }

  /// An update of `batch`, a batch of `peer`'s list of state streams (under peer_mutex).
  void on_update(Peer& peer, const wire::StateBatch& batch, const wire::StateUpdate& u) {
    const std::string& from = batch.coordinator;
    const std::optional<PeerFreshness::Slot> slot = peer.fresh.slot(u.stream);
    const auto what = [&] {
      return "state update " + (slot ? peer.fresh.iface(*slot) : "#" + std::to_string(u.stream)) + " seq " +
             std::to_string(u.seq) + " from coordinator '" + printable(from) + "'";
    };
    if (!slot) {
      updates_rejected.fetch_add(1);
      refuse(from, what() + ": not one of its " + std::to_string(peer.fresh.size()) + " state streams");
      return;
    }
    Held* const held_here = peer.held[slot->index];
    if (held_here == nullptr) return;  // every client of the provider sees every update; this one is not for us
    Held& h = *held_here;
    std::int64_t missed = 0;
    std::string why;
    switch (peer.fresh.stream(*slot, batch.incarnation, u.seq, missed, why)) {
      case PeerFreshness::Verdict::Accept: break;
      case PeerFreshness::Verdict::Covered:  // (heartbeats only)
      case PeerFreshness::Verdict::Unproven:
        // A process not proven alive yet (a restart, or a replay of an earlier run): its state is
        // taken once its heartbeat is proven, from a republish.
        updates_unproven.fetch_add(1);
        return;
      case PeerFreshness::Verdict::Refuse:
        updates_rejected.fetch_add(1);
        refuse(from, what() + ": " + why);
        return;
    }
    if (missed > 0 && h.incarnation == batch.incarnation) {
      updates_missed.fetch_add(static_cast<std::uint64_t>(missed));
      drops->note(from + "/missed", "middleware: " + name + ": " + what() + ": " + std::to_string(missed) +
                                        " update(s) missed; this full state supersedes them");
    }
    std::vector<RemoteRoot> roots;
    roots.reserve(u.roots.size());
    for (const wire::Root& w : u.roots) {
      RemoteRoot r;
      root_from_wire(w, r.root);
      if (!from_wire(w.level, r.level)) {
        updates_rejected.fetch_add(1);
        refuse(from, what() + ": root '" + printable(w.event) + "' has an invalid level; nothing changed");
        return;
      }
      r.path = w.path;
      roots.push_back(std::move(r));
    }
    auto applied = co.apply_remote(h.proxy, roots);
    if (!applied) {
      updates_rejected.fetch_add(1);
      refuse(from, what() + ": nothing changed: " + applied.error().message);
      return;
    }
    h.incarnation = batch.incarnation;
    h.last_seq = u.seq;
    if (h.behind) {
      h.behind = false;
      if (--peer.behind == 0) peer.live.caught_up();  // every interface held of it, not only this one
    }
    updates_applied.fetch_add(1);
  }

  void on_beat(const wire::Signed& m) {
    if (link->heard_own(m)) return;
    const OpenedHeartbeat opened = open_heartbeat(*keyring, ic, m);
    if (!opened.why.empty()) {
      refuse(opened.source, opened.why);
      return;
    }
    const wire::Heartbeat& hb = opened.beat;
    const std::int64_t now = steady_ns();
    if (hb.coordinator == name) {
      if (hb.incarnation == incarnation) {
        link->own_heartbeat_heard();  // one of this run not among those sent last (heard_own): late
      } else {
        drops->drop(name + "/duplicate", "middleware: " + name + ": another process runs coordinator '" + name +
                                             "' (incarnation " + std::to_string(hb.incarnation) + ", ours " +
                                             std::to_string(incarnation) + "): two processes with one name; " +
                                             "receivers follow the newer one");
        duplicates_seen.fetch_add(1);  // after the line: a reader of the count finds it logged
      }
      return;
    }
    std::lock_guard lock(peer_mutex);
    Peer& peer = peers[hb.coordinator];  // a keyring name: bounded
    std::string why;
    switch (peer.fresh.heartbeat(hb, why)) {
      case PeerFreshness::Verdict::Accept: break;
      case PeerFreshness::Verdict::Unproven:
        // Believed only on a signed answer to a nonce of ours: a recorded heartbeat has none.
        prover->ask(hb.coordinator, hb.control);
        return;
      case PeerFreshness::Verdict::Covered: return;  // the proof was fresher
      case PeerFreshness::Verdict::Refuse:
        refuse(m.signer, "a heartbeat of '" + printable(hb.coordinator) + "': " + why);
        return;
    }
    believe(hb, peer, now, peer.fresh.sent_at(hb.time, now), false);
  }

  /// A proof of life of `who` (Prover, on an Ice thread), to a question sent at `asked`: its
  /// process is believed from now on.
  void on_proven(const std::string& who, const wire::Heartbeat& beat, std::int64_t asked) {
    std::lock_guard lock(peer_mutex);
    Peer& peer = peers[who];
    const std::int64_t before = peer.fresh.incarnation();
    if (std::string why; !peer.fresh.proven(beat, why, asked)) {
      refuse(who, "a proof of life of '" + printable(who) + "': " + why);
      return;
    }
    if (peer.provider && before != beat.incarnation) {
      log("middleware: " + name + ": coordinator '" + who + "' proved alive (incarnation " +
          std::to_string(beat.incarnation) + ")");
    }
    believe(beat, peer, steady_ns(), asked, true);
  }

  /// An authentic, fresh heartbeat of `peer`, sent at `sent` (under peer_mutex): it is alive; what
  /// it lists sent that is not held here is asked for, and a loss clears once everything is held.
  void believe(const wire::Heartbeat& hb, Peer& peer, std::int64_t now, std::int64_t sent, bool proof) {
    bool need = proof;          // a process just proven: nothing it sent before is taken, ask for all
    std::string behind_stream;  // the first stream it lists ahead of what is held here
    for (auto& [iface, h] : held) {
      if (h.provider != hb.coordinator) continue;
      const std::int64_t have = h.incarnation == hb.incarnation ? h.last_seq : 0;
      // A provider is back only once what it lists as sent is received (a stream it has sent
      // nothing on yet holds every machine's initial Normal, as this stand-in does). The list is
      // the one the system file gives the provider (PeerFreshness::heartbeat checked it).
      const bool behind = hb.states.at(h.slot.index) > have;
      // Two heartbeats in a row: the update may simply be on its way on the other topic. A lost
      // provider is asked at once: its clients stay in Error until they have its state.
      if (behind && (h.behind || peer.live.lost())) need = true;
      if (behind != h.behind) behind ? ++peer.behind : --peer.behind;
      h.behind = behind;
      if (behind && behind_stream.empty()) behind_stream = state_stream(iface);
    }
    // Lost if not caught up within the loss bound (watch_loop); back once caught up, and only over a
    // link that is up: what comes while it reconnects comes through a subscription about to be
    // replaced, and a loss cleared on it comes back once it is (make cluster-demo, a host rejoining).
    const bool hold = peer.live.lost() && !link->connected();
    // Its state, shown here, is about to change while it clears losses of its own: its loss
    // clears once that is done, so the view changes once (Liveness::believed).
    const bool settling = peer.provider && !hb.settling.empty();
    if (!hold && peer.live.believed(now, sent, behind_stream, lost_after(), settling)) recover(hb.coordinator, peer);
    if (!peer.provider) return;
    if (!need || now - peer.last_resync < 3 * std::chrono::nanoseconds(options.heartbeat).count()) return;
    peer.last_resync = now;
    const auto pub = Ice::uncheckedCast<wire::ResyncTopicPrx>(link->publisher(PublishResync));
    if (pub == nullptr) return;
    try {
      pub->resync(resync_request(hb.coordinator));
      resyncs_requested.fetch_add(1);
      if (!proof) {
        drops->note(hb.coordinator + "/republish", "middleware: " + name + ": missed state of coordinator '" +
                                                       hb.coordinator + "'; asked it to republish");
      }
    } catch (const Ice::Exception&) {
      // The link thread notices and reconnects.
    }
  }

  void on_resync(const wire::Signed& m) {
    // This process's own requests come back on the topic: nothing to republish for them (and a
    // message naming this process as its sender cannot be opened by it: it holds no tag for itself).
    if (m.signer == name) return;
    wire::ResyncRequest r;
    if (const std::string why = open_sealed(*signer, ic, m, kKindResync, r); !why.empty()) {
      refuse(m.signer, "a resync request signed '" + printable(m.signer) + "': " + why);
      return;
    }
    if (r.requester != m.signer) {
      refuse(m.signer,
             "a resync request naming '" + printable(r.requester) + "' signed by '" + printable(m.signer) + "'");
      return;
    }
    if (r.requester == name || (!r.coordinator.empty() && r.coordinator != name)) return;
    bool now_ok = false;
    {
      std::lock_guard lock(peer_mutex);
      Peer& peer = peers[r.requester];
      // A resync request only asks for a republish: its own numbers keep replays from costing
      // more than one, and say nothing of whether its sender is alive.
      if (r.incarnation < peer.resync_incarnation) {
        refuse(m.signer, "a resync request of '" + printable(r.requester) +
                             "': " + older_incarnation(r.incarnation, peer.resync_incarnation));
        return;
      }
      if (r.incarnation > peer.resync_incarnation) {
        if (const std::string why = incarnation_out_of_bounds("a resync request", r.requester, r.incarnation);
            !why.empty()) {
          refuse(m.signer, why);
          return;
        }
        peer.resync_incarnation = r.incarnation;
        peer.resync_seq = 0;
      }
      if (r.seq <= peer.resync_seq) {
        refuse(m.signer, "a resync request of '" + printable(r.requester) + "': seq " + std::to_string(r.seq) +
                             " not above " + std::to_string(peer.resync_seq) + " (replayed)");
        return;
      }
      peer.resync_seq = r.seq;
      // At most one republish per requester and heartbeat period: a flood of requests costs one
      // republish per period, and a request inside the period is kept, not lost.
      const std::int64_t now = steady_ns();
      if (now - peer.last_honoured >= std::chrono::nanoseconds(options.heartbeat).count()) {
        peer.last_honoured = now;
        now_ok = true;
      } else {
        peer.resync_pending = true;
      }
    }
    if (now_ok) mark_all(true);
  }

  /// Link thread, every heartbeat: republishes for the requests that came too soon.
  void honour_pending_resyncs() {
    bool any = false;
    {
      std::lock_guard lock(peer_mutex);
      const std::int64_t now = steady_ns();
      for (auto& [_, peer] : peers) {
        if (!peer.resync_pending || now - peer.last_honoured < std::chrono::nanoseconds(options.heartbeat).count())
          continue;
        peer.resync_pending = false;
        peer.last_honoured = now;
        any = true;
      }
    }
    if (any) mark_all(true);
  }

  // -- watch thread: fail toward safe on loss (DESIGN §4) --

  /// Raises the loss of a peer (under peer_mutex; the coordinator write comes after it).
  void declare_lost(const std::string& who, Peer& peer, const std::string& silent) {
    if (who == kSupervisorSigner) {
      // Two supervisors may watch one system: once the one believed is gone, whichever proves
      // itself alive next is believed, the older one too. (A coordinator runs once per name: one
      // that comes back is the same process or a newer one.)
      peer.fresh.forget();
      log("middleware: " + name + ": the supervisor is gone (" + silent +
          "); EVT_SUPERVISOR_LOST on s_F of every component");
      const Structure& shape = co.structure();
      for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
        if (!shape.is_remote(c)) co.generate(framework_event::kSupervisorLost, shape.framework_machine(c));
      }
      // As for a provider: its heartbeats may only have stopped reaching us (an identity taken).
      link->renew(peer_topics(who));
      return;
    }
    providers_lost.fetch_add(1);
    peer.fresh.doubt();  // back only on a new proof of life, never on a recording of it
    log("middleware: " + name + ": coordinator '" + who + "' lost (" + silent + "); EVT_COORDINATOR_LOST on the " +
        std::to_string(peer.feeds.size()) + " required interface(s) it feeds");
    // Its heartbeats or its state may have stopped reaching us only: subscriptions taken by
    // another endpoint under our identities. New identities bring them back if it is alive.
    link->renew(peer_topics(who));
    for (MachineId m : peer.feeds) co.generate(framework_event::kCoordinatorLost, m);
  }

  /// A peer still lost a subscription round after its loss began (or this node started) or after
  /// the last renewal: its subscriptions may be held by a member under our identities since before
  /// (a newcomer's loss begins with no renewal), so they are made again under new ones, each round
  /// while it lasts (Liveness::renew_due; said once per loss). Under peer_mutex.
  void renew_lost(const std::string& who, std::uint32_t renewal) {
    if (renewal == 1)
      log("middleware: " + name + ": " + (who == kSupervisorSigner ? "the supervisor" : "coordinator '" + who + "'") +
          " still lost a subscription round on; subscribing to its topics again under new identities, each round "
          "until it is back");
    link->renew(peer_topics(who), true);
  }

  /// A newcomer starts toward safe (DESIGN §7): until a provider is proven alive and its state is
  /// received here, the interfaces it feeds are at Error, as after a loss, and they clear the
  /// same way (recover()).
  void raise_until_proven() {
    std::lock_guard lock(peer_mutex);
    for (auto& [who, peer] : peers) {
      if (!peer.provider || peer.live.lost()) continue;
      peer.live.start_lost(steady_ns());
      log("middleware: " + name + ": coordinator '" + who + "' not proven alive yet (this node just started); " +
          "EVT_COORDINATOR_LOST on the " + std::to_string(peer.feeds.size()) +
          " required interface(s) it feeds until it is and its state is received");
      for (MachineId m : peer.feeds) co.generate(framework_event::kCoordinatorLost, m);
    }
  }

  /// Clears the loss of a peer that is back and whose state we hold again (under peer_mutex).
  void recover(const std::string& who, Peer& peer) {
    if (std::find(cleared_since_heartbeat.begin(), cleared_since_heartbeat.end(), who) == cleared_since_heartbeat.end())
      cleared_since_heartbeat.push_back(who);  // at most one entry per peer
    if (who == kSupervisorSigner) {
      log("middleware: " + name + ": the supervisor is back");
      const Structure& shape = co.structure();
      for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
        if (!shape.is_remote(c)) {
          co.generate(framework_event::completion_of(framework_event::kSupervisorLost), shape.framework_machine(c));
        }
      }
      return;
    }
    log("middleware: " + name + ": coordinator '" + who + "' is back and resynchronised; EVT_COORDINATOR_LOST cleared");
    for (MachineId m : peer.feeds) co.generate(framework_event::completion_of(framework_event::kCoordinatorLost), m);
  }

  /// Declares a peer lost once its bound has passed: it sleeps until the earliest peer is due
  /// (Liveness::due), one loss bound at most, so a loss is said as soon as it is one.
  void watch_loop() {
    const std::chrono::milliseconds bound = lost_after();
    const std::chrono::nanoseconds round = subscription_round(options.heartbeat);
    for (std::int64_t next = steady_ns(); watch_sleeper.sleep_until(next);) {
      const std::int64_t now = steady_ns();
      next = now + std::chrono::nanoseconds(bound).count();
      drops->flush("middleware: " + name, now);
      std::lock_guard lock(peer_mutex);
      for (auto& [who, peer] : peers) {
        // A provider is watched from the node's start (never heard of is as bad as gone); the
        // supervisor only once it has been seen (a system may run without one).
        const bool watched = peer.provider || (who == kSupervisorSigner && peer.live.last_beat() != 0);
        if (!watched) continue;
        if (const std::string why = peer.live.check(now, started, bound, "this node started"); !why.empty()) {
          declare_lost(who, peer, why);
        } else if (const std::uint32_t renewal = peer.live.renew_due(now, round); renewal != 0) {
          renew_lost(who, renewal);
        }
        next = std::min(next, peer.live.due(started, bound, round));
      }
    }
  }

  std::chrono::milliseconds lost_after() const {
    return options.lost_after.count() > 0 ? options.lost_after : 3 * options.heartbeat;
  }
};

Expected<std::unique_ptr<CoordinatorNode>> CoordinatorNode::create(Coordinator& coordinator, Monitor& monitor,
                                                                   const FilterRegistry& registry,
                                                                   const spec::SystemSpec& system,
                                                                   std::string coordinator_name, NodeOptions options) {
  if (options.ice.port <= 0) return fail(ErrorCode::InvalidArgument, "middleware: no IceStorm port given");
  if (options.heartbeat.count() <= 0)
    return fail(ErrorCode::InvalidArgument, "middleware: heartbeat period must be positive");
  auto impl =
      std::make_unique<Impl>(coordinator, monitor, registry, system, std::move(coordinator_name), std::move(options));
  if (std::none_of(system.coordinators.begin(), system.coordinators.end(),
                   [&](const auto& c) { return c.first == impl->name; })) {
    return fail(ErrorCode::NotFound, "system '" + system.name + "' has no coordinator '" + impl->name + "'");
  }
  auto dir = bus_keys_dir(impl->options.keys_dir);
  if (!dir) return tl::unexpected(dir.error());
  impl->options.tls = tls_from_keys(*dir, impl->options.tls, impl->name);
  if (auto r = check_transport("middleware: " + impl->name, impl->options.tls, impl->options.insecure,
                               {impl->options.ice.host, impl->options.listen_host});
      !r) {
    return tl::unexpected(r.error());
  }
  auto keyring = Keyring::load(*dir);
  if (!keyring) return tl::unexpected(keyring.error());
  auto signer = Signer::load(*dir, impl->name, *keyring);
  if (!signer) return tl::unexpected(signer.error());
  impl->keyring = std::move(*keyring);
  impl->signer = std::move(*signer);
  if (!impl->options.tls.enabled()) impl->log("middleware: " + impl->name + ": " + plain_tcp_warning(*dir));
  Impl* d = impl.get();
  impl->drops = std::make_shared<DropLog>([d](const std::string& line) { d->log(line); });
  impl->incarnation = new_incarnation();
  const Structure& shape = coordinator.structure();
  impl->streams_of.resize(shape.component_count());
  for (ComponentId c : id_range<ComponentId>(shape.component_count())) {
    if (shape.is_remote(c)) {
      for (MachineId m : shape.provided_machines(c)) {
        const std::string iface = std::string(shape.component_name(c)) + "." + std::string(shape.interface_name(m));
        const std::string provider(impl->members.coordinator_of(shape.component_name(c)));
        impl->held.emplace(iface, Impl::Held{m, provider, {}});
        if (!provider.empty()) impl->peers[provider].provider = true;
      }
      continue;
    }
    const auto& provided = shape.provided_machines(c);
    for (std::uint32_t p = 0; p < provided.size(); ++p) {
      auto s = std::make_unique<Impl::Stream>();
      s->component = c;
      s->provided = p;
      s->iface = std::string(shape.component_name(c)) + "." + std::string(shape.interface_name(provided[p]));
      impl->streams_of[c].push_back(impl->streams.size());
      impl->streams.push_back(std::move(s));
    }
  }
  // Its heartbeats list its streams' numbers in the order of their names (StateStreams); each
  // provider's, as the system file gives them, are followed in that order.
  impl->heartbeat_order.resize(impl->streams.size());
  std::iota(impl->heartbeat_order.begin(), impl->heartbeat_order.end(), std::size_t{0});
  std::sort(impl->heartbeat_order.begin(), impl->heartbeat_order.end(),
            [&](std::size_t a, std::size_t b) { return impl->streams[a]->iface < impl->streams[b]->iface; });
  std::vector<std::string> ifaces;
  for (const std::size_t i : impl->heartbeat_order) ifaces.push_back(impl->streams[i]->iface);
  impl->states_id = StateStreams::of(std::move(ifaces)).id;
  for (std::size_t k = 0; k < impl->heartbeat_order.size(); ++k)
    impl->streams[impl->heartbeat_order[k]]->position = static_cast<std::int32_t>(k);
  for (auto& [provider, peer] : impl->peers) {
    if (!peer.provider) continue;
    peer.fresh.follow(impl->members.state_streams(provider));
    peer.held.assign(peer.fresh.size(), nullptr);
  }
  for (auto& [iface, held] : impl->held) {
    const auto peer = impl->peers.find(held.provider);
    if (peer == impl->peers.end()) continue;
    const auto slot = peer->second.fresh.slot(iface);
    if (!slot) {
      return fail(ErrorCode::InvalidArgument, "coordinator '" + impl->name + "' holds " + iface + " of coordinator '" +
                                                  held.provider + "', which the system file does not give it");
    }
    held.slot = *slot;
    peer->second.held[slot->index] = &held;
  }
  // The required interfaces each provider coordinator feeds: where its loss is raised.
  for (const Connection& k : shape.connections()) {
    if (!shape.is_remote(k.provider) || shape.is_remote(k.client)) continue;
    const std::string_view provider = impl->members.coordinator_of(shape.component_name(k.provider));
    if (provider.empty()) continue;
    impl->peers[std::string(provider)].feeds.push_back(shape.required_machines(k.client)[k.required]);
  }
  return std::unique_ptr<CoordinatorNode>(new CoordinatorNode(std::move(impl)));
}

CoordinatorNode::CoordinatorNode(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

CoordinatorNode::~CoordinatorNode() { stop(); }

Expected<void> CoordinatorNode::start() {
  Impl& d = *impl_;
  if (d.running.load()) return {};
  try {
    d.ic = make_communicator(d.options.tls, d.options.ice);
    d.state_head = encode(d.ic, wire::StateBatch{d.name, d.incarnation, d.states_id, {}});
    d.state_head.pop_back();  // the empty sequence of updates: its size, 0, in one byte
    const std::string endpoint = protocol(d.options.tls) + " -h " + d.options.listen_host +
                                 (d.options.control_port > 0 ? " -p " + std::to_string(d.options.control_port) : "");
    d.adapter = d.ic->createObjectAdapterWithEndpoints("SafecassNode", endpoint);
    const std::string who = "middleware: " + d.name;
    d.prover = std::make_unique<Prover>(
        d.ic, *d.keyring,
        [&d](const std::string& signer, const wire::Heartbeat& beat, std::int64_t asked) {
          d.on_proven(signer, beat, asked);
        },
        [&d](const std::string& signer, const std::string& why) {
          d.drops->drop(signer, "middleware: " + d.name + ": '" + printable(signer) + "' not proven alive: " + why);
        },
        d.options.heartbeat);
    auto guarded = [&](std::shared_ptr<Ice::Object> servant) {
      return std::make_shared<Guard>(std::move(servant), d.drops, who);
    };
    auto subscriber = [&](const char* operation, void (Impl::*handle)(const wire::Signed&)) {
      return std::make_shared<TopicSubscriber>(
          d.ic, operation, [&d, handle](const wire::Signed& m) { (d.*handle)(m); }, d.drops, who);
    };
    const std::string id = "safecass-" + d.name + "-" + std::to_string(d.incarnation);
    auto state = add_subscriber(d.adapter, subscriber("updates", &Impl::on_updates), id + "-state");
    auto heartbeat = add_subscriber(d.adapter, subscriber("beat", &Impl::on_beat), id + "-heartbeat");
    auto resync = add_subscriber(d.adapter, subscriber("resync", &Impl::on_resync), id + "-resync");
    ControlContext context{
        d.co,
        d.monitor,
        d.registry,
        d.name,
        d.options.allow_write,
        d.options.token,
        [&d](const std::string& line) { d.log(line); },
        d.options.read_token,
        d.options.clock,
        [&d](const Ice::ByteSeq& nonce) { return make_proof(*d.signer, d.ic, nonce, d.heartbeat(false)); }};
    auto control = d.adapter->add(guarded(make_control(context)), Ice::Identity{"control-" + d.name, "safecass"});
    d.control = control->ice_toString();
    BusLinkOptions bus;
    bus.who = who;
    bus.publish_on = {state_topic(d.name), kEventTopic, heartbeat_topic(d.name), kResyncTopic};
    bus.heartbeat_topic = Impl::PublishHeartbeat;
    bus.period = d.options.heartbeat;
    bus.while_down = "running locally";
    bus.heartbeat = [&d] { return d.signer->sign(kKindHeartbeat, encode(d.ic, d.heartbeat())); };
    bus.rejoined = [&d] { d.rejoined(); };
    bus.every_period = [&d] { d.honour_pending_resyncs(); };
    bus.log = [&d](const std::string& line) { d.log(line); };
    d.link = std::make_unique<BusLink>(d.ic, d.options.ice, d.options.tls, std::move(bus));
    std::vector<std::string> providers;  // the coordinators whose interfaces this one holds
    for (const auto& [iface, h] : d.held) {
      if (!h.provider.empty() && std::find(providers.begin(), providers.end(), h.provider) == providers.end()) {
        providers.push_back(h.provider);
      }
    }
    for (const std::string& provider : providers) {
      d.link->subscribe_to(state_topic(provider), state);
      d.link->subscribe_to(heartbeat_topic(provider), heartbeat);
    }
    d.link->subscribe_to(heartbeat_topic(d.name), heartbeat);
    d.link->subscribe_to(heartbeat_topic(kSupervisorSigner), heartbeat);
    d.link->subscribe_to(kResyncTopic, resync);
    d.adapter->activate();
  } catch (const Ice::Exception& e) {
    if (d.ic) d.ic->destroy();
    d.ic = nullptr;
    return fail(ErrorCode::Io,
                "middleware: " + d.name + ": cannot listen on " + d.options.listen_host + ": " + e.what());
  }
  d.subscription = d.co.subscribe([&d](const Record& r) { d.on_record(r); });
  d.started = steady_ns();
  d.raise_until_proven();
  d.running.store(true);
  d.publisher_thread = std::thread([&d] { d.publisher_loop(); });
  d.link->start();
  d.watch_sleeper.restart();
  d.watch_thread = std::thread([&d] { d.watch_loop(); });
  return {};
}

void CoordinatorNode::stop() noexcept {
  Impl& d = *impl_;
  if (!d.running.exchange(false)) return;
  d.co.unsubscribe(d.subscription);
  d.queue_cv.notify_all();
  if (d.publisher_thread.joinable()) d.publisher_thread.join();
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

NodeStats CoordinatorNode::stats() const {
  const Impl& d = *impl_;
  NodeStats s;
  s.updates_published = d.updates_published.load();
  s.updates_applied = d.updates_applied.load();
  s.updates_rejected = d.updates_rejected.load();
  s.updates_missed = d.updates_missed.load();
  s.events_published = d.events_published.load();
  s.events_dropped = d.events_dropped.load();
  s.resyncs_requested = d.resyncs_requested.load();
  s.connects = d.link ? d.link->connects() : 0;
  s.resubscriptions = d.link ? d.link->resubscriptions() : 0;
  s.broker_pings = d.link ? d.link->pings() : 0;
  s.state_messages_published = d.state_messages_published.load();
  s.event_messages_published = d.event_messages_published.load();
  s.connected = d.link && d.link->connected();
  s.messages_refused = d.drops ? d.drops->count() : 0;
  s.providers_lost = d.providers_lost.load();
  s.duplicates_seen = d.duplicates_seen.load();
  s.oversized_messages = d.oversized_messages.load();
  s.roots_truncated = d.roots_truncated.load();
  s.updates_unproven = d.updates_unproven.load();
  return s;
}

std::string CoordinatorNode::control_proxy() const { return impl_->control; }

}  // namespace safecass::middleware
