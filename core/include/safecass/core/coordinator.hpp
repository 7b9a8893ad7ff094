#pragma once
/// @file coordinator.hpp
/// The coordinator: one per process. It owns the Generic Component Model of that process's
/// components (their state machines, the event definitions, the connections), applies events with
/// the severity policy of DESIGN §2.4, propagates errors along connections (§2.6), fires callbacks
/// (§2.5) and publishes everything that happens on one observer stream. The severity policy itself
/// is ConditionSet (condition_set.hpp), one per machine; the coordinator orchestrates: records,
/// callbacks, propagation, history.
///
/// The model is read and written through three groups, each in its own header:
/// - structure.hpp, `structure()`: the shape (components, machines, events, connections, names),
///   fixed by configuration, every read lock-free;
/// - this class: configuration, the id-based writes, the lock-free state reads, introspection
///   (conditions, history, explain: snapshots taken under the lock) and the observer stream;
/// - named.hpp: the writes and explain by name, for tools and people.
///
/// Lifecycle: configure (add components, interfaces, events, services, connections, callbacks),
/// then run (generate, reset, read). Configuration calls are not safe against concurrent readers:
/// finish the configuration before other threads start reading or generating. After that:
/// - state reads (`state()`, `snapshot()`, `extended()`, `service_state()`, `dispatch()`) are
///   lock-free, wait-free and never allocate;
/// - a write (`generate()`, `reset()`, `apply_remote()`, `publish()`) takes the coordinator's lock
///   for the change and its propagation; once the condition vectors have grown to their working
///   size `generate()` does not allocate. `reset()` may allocate (it records who and why);
/// - callbacks and observers run after the change, with the lock released, on the thread that made
///   the change, before its write returns; the records of all writes reach them in the order the
///   writes were made (one write's are handed out when the earlier writes' have been). They must not
///   block. They may read the coordinator (history(), explain(), ...: plain calls that take the
///   lock); a write they make is queued and made, as a write of its own, once the current one has
///   been handed out, before the outer call returns; a registration they make takes effect after
///   the records being handed out. An exception thrown by a callback becomes EVT_CALLBACK_EXCEPTION
///   on the component's s_F (docs/semantics.md §5).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "safecass/core/address.hpp"
#include "safecass/core/clock.hpp"
#include "safecass/core/condition.hpp"
#include "safecass/core/condition_set.hpp"
#include "safecass/core/event.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/ids.hpp"
#include "safecass/core/observer.hpp"
#include "safecass/core/state.hpp"
#include "safecass/core/structure.hpp"

namespace safecass {

/// A state and the event that explains it, read atomically together.
struct StateSnapshot {
  State state = State::Normal;
  EventId outstanding = kNoEvent;
};

/// Passed to on_transition callbacks.
struct TransitionInfo {
  ComponentId component = kNoComponent;
  MachineId machine = kNoMachine;  ///< kNoMachine for the extended component state
  Transition transition = Transition::N2W;
  EventId event = kNoEvent;         ///< the event processed (kNoEvent for a reset)
  const RootCause* root = nullptr;  ///< the root cause of the condition added/removed, if any
  Time time{};
};

/// Callbacks on a machine or on a component's extended state, fired in the order
/// on_exit(old), on_transition(info), on_entry(new). Any of them may be empty.
struct StateCallbacks {
  std::function<void(State)> on_exit;
  std::function<void(const TransitionInfo&)> on_transition;
  std::function<void(State)> on_entry;
};

/// One active condition, with its root cause and the path it took (DESIGN §2.6 `explain`). Its
/// text and JSON are the read model's (introspect::explanation_text, explanation_json).
struct Explanation {
  std::string machine;  ///< address of the machine holding the condition
  std::string event;
  State level = State::Normal;
  int severity = 0;
  bool mirror = false;
  bool outstanding = false;  ///< the machine's outstanding condition
  std::uint32_t count = 0;
  Time first{};
  Time last{};
  ResolvedRoot root;
  std::string hazard;             ///< of the root event
  std::vector<std::string> path;  ///< origin machine → services/interfaces … → this machine
};

/// A root condition reported by another process for one of its provided interfaces: one element
/// of the full state that replaces the set held by a remote provided interface (apply_remote()).
/// Identity across processes is (origin, event, time).
struct RemoteRoot {
  ResolvedRoot root;           ///< identity across processes: (origin, event, time)
  State level = State::Error;  ///< the root's level (Warning or Error)
  /// Hops from the origin to the provider's machine that feeds the service (as explain() writes
  /// them); the path-vector rule drops a root whose path already contains a receiving machine.
  std::vector<std::string> path;
};

/// What apply_remote() changed.
struct RemoteApplyResult {
  std::size_t added = 0;    ///< roots new in this update
  std::size_t removed = 0;  ///< roots no longer reported
  std::size_t kept = 0;     ///< roots reported again (their path may have changed)
  std::size_t dropped = 0;  ///< roots dropped by the path-vector rule (a cycle across processes)
};

/// History (DESIGN §2.4 "every processed, ignored, masked, override and reset event is in the
/// history"): the coordinator keeps the records of all its machines and components in ONE ring,
/// allocated while the model is configured (never while events are processed). The ring holds
/// max(`history_records`, `history_per_address` × (machines + components)) records, at most
/// `history_records_max`; the oldest record of the whole coordinator goes first. history(id)
/// returns the newest `history_capacity` records of one machine that are still in the ring. A quiet address keeps its
/// records as long as the whole coordinator has not produced a ring's worth of newer ones (docs/semantics.md §8).
struct CoordinatorOptions {
  std::size_t history_capacity = 256;                      ///< at most this many records returned per address
  std::size_t history_records = 8192;                      ///< the ring holds at least this many records
  std::size_t history_per_address = 8;                     ///< ... and this many per machine and component
  std::size_t history_records_max = std::size_t{1} << 20;  ///< ... and at most this many
  std::size_t pending_capacity = 256;  ///< writes made by callbacks and observers, reserved up front per thread
};

class Coordinator {
public:
  /// `clock` must outlive the coordinator; null means an owned SteadyClock.
  explicit Coordinator(std::string name = "local", const Clock* clock = nullptr, CoordinatorOptions options = {});
  ~Coordinator();
  Coordinator(const Coordinator&) = delete;
  Coordinator& operator=(const Coordinator&) = delete;

  const Clock& clock() const noexcept { return *clock_; }
  /// The shape of the model: components, machines, events, connections, names (structure.hpp).
  const Structure& structure() const noexcept { return structure_; }

  // ---- configuration -------------------------------------------------------------------------
  /// Errors: Duplicate, InvalidArgument (empty or dotted name).
  [[nodiscard]] Expected<ComponentId> add_component(std::string_view name);
  /// Adds provided interface `name` (machine C.s_P.name). Errors: NotFound, Duplicate, InvalidArgument.
  [[nodiscard]] Expected<MachineId> add_provided(ComponentId component, std::string_view name);
  /// Adds required interface `name` (machine C.s_R.name). Errors: NotFound, Duplicate, InvalidArgument.
  [[nodiscard]] Expected<MachineId> add_required(ComponentId component, std::string_view name);
  /// Errors: Duplicate name, InvalidArgument (severity outside 1–255, empty or mixed transitions,
  /// `completes`/`latched` on the wrong kind of event, completion with no onset name).
  [[nodiscard]] Expected<EventId> add_event(const EventDef& def);
  /// Sets the service dependency entry of a provided interface.
  /// Errors: NotFound (component, provided or required interface), InvalidArgument (propagate
  /// Normal), InvalidState (a machine of the component holds a condition: the mirrors it feeds
  /// would no longer match the entry).
  [[nodiscard]] Expected<void> set_service(ComponentId component, std::string_view provided,
                                           const ServiceDependency& dependency);
  /// Connects `client_required` ("C.r") to `provider_provided` ("P.p").
  /// Errors: NotFound, InvalidArgument (malformed, self-connection), Duplicate (already connected),
  /// InvalidState (called from a callback or observer of this coordinator).
  [[nodiscard]] Expected<ConnectionId> connect(std::string_view client_required, std::string_view provider_provided);

  // ---- remote providers (cross-process propagation, DESIGN §2.6 and §4) --------------------
  /// Declares provided interface `provider_provided` ("P.p") of a component that runs in another
  /// process, so that connect() accepts it as a provider. The first call for P adds a *remote
  /// component* P (Structure::is_remote(); left out of coordinator_state()) whose machine P.s_P.p holds the
  /// roots the provider reports and whose service state is that machine alone; `propagate` is
  /// the provider's propagation level for the service. Configuration call.
  /// Errors: InvalidArgument (malformed, propagate Normal), Duplicate (P is a local component, or
  /// P.p was declared already).
  [[nodiscard]] Expected<MachineId> add_remote_provided(std::string_view provider_provided,
                                                        State propagate = State::Error);
  /// Replaces, as a whole, the set of roots held by remote provided interface `remote_provided`
  /// (a machine returned by add_remote_provided()) with `roots`, then propagates locally exactly
  /// as for a local change: roots no longer reported clear their mirrors, new roots are mirrored
  /// into every reachable machine (EVT_SERVICE_FAILURE / EVT_SERVICE_DEGRADED). A root whose path
  /// already contains a machine this interface feeds is dropped (path-vector rule: a cycle across
  /// processes cannot latch). Takes the lock; callbacks and observers run as for generate().
  /// Errors (nothing is changed): NotFound (not a remote provided interface), InvalidArgument
  /// (unknown or non-onset event, level Normal, empty origin), InvalidState (called from a
  /// callback or observer of this coordinator: it returns a result, so it cannot be queued).
  [[nodiscard]] Expected<RemoteApplyResult> apply_remote(MachineId remote_provided,
                                                         const std::vector<RemoteRoot>& roots);
  /// The full state another process needs for service `service` (a provided interface index of a
  /// local component): one RemoteRoot per root active at s_S.p (any level), with the shortest
  /// hop path that brings it to a machine feeding the service. Takes the lock; allocates.
  std::vector<RemoteRoot> service_roots(ComponentId component, std::uint32_t service) const;
  /// `root` with its names: the event, the origin machine's address (a remote root's in its own
  /// process), the filter and signal. Takes no lock (it reads what configuration fixed and the
  /// interned names); safe from observers and callbacks.
  ResolvedRoot resolve_root(const RootCause& root) const;

  /// Interns a text (filter, signal or reason name) for use in SampleCause; Structure::name_of()
  /// reads it back. Thread-safe.
  NameId intern(std::string_view text) { return structure_.intern(text); }

  // ---- events --------------------------------------------------------------------------------
  /// Processes `event` on machine `target` (broadcast events: on s_A of every component) with the
  /// rules of DESIGN §2.4 and propagates the consequences (§2.6). `target` and `event` must be
  /// valid ids. Allocation-free once condition vectors have reached their working size.
  void generate(EventId event, MachineId target, const SampleCause& cause = {}) noexcept;
  /// Clears every condition originating in `target` (machine, component, SYSTEM), latched ones
  /// too, and records who and why. Mirrored conditions whose root is outside the target and still
  /// active stay: the fault they report is still present. A service address resets its component.
  void reset(const Address& target, std::string_view who, std::string_view why);

  // ---- lock-free reads -----------------------------------------------------------------------
  State state(MachineId id) const noexcept {
    return unpack(machines_[id].snapshot.load(std::memory_order_acquire)).state;
  }
  StateSnapshot snapshot(MachineId id) const noexcept {
    return unpack(machines_[id].snapshot.load(std::memory_order_acquire));
  }
  /// The extended component state ŝ_ext(C) and its outstanding event.
  StateSnapshot extended(ComponentId id) const noexcept {
    return unpack(components_[id].snapshot.load(std::memory_order_acquire));
  }
  /// Service state s_S.p of provided interface `provided` (index) of `component`.
  State service_state(ComponentId component, std::uint32_t provided) const noexcept;
  /// Product over every component of this coordinator.
  State coordinator_state() const noexcept;
  /// State of any address (SYSTEM, component, machine or service).
  State state_of(const Address& address) const noexcept;

  /// Calls exactly one of normal(), warning(const Event&), error(const Event&) according to the
  /// extended state of `component`, passing its outstanding event. Lock-free (paper §V-B).
  template <class Normal, class Warning, class Error>
  void dispatch(ComponentId component, Normal&& normal, Warning&& warning, Error&& error) const {
    const StateSnapshot s = extended(component);
    switch (s.state) {
      case State::Normal: normal(); return;
      case State::Warning: warning(structure_.event(s.outstanding)); return;
      case State::Error: error(structure_.event(s.outstanding)); return;
    }
  }

  /// Writes requested by callbacks and observers beyond the chain bound (65536 per outer call) and
  /// therefore not processed. Non-zero means a callback loop: a bug in the application.
  std::uint64_t dropped_requests() const {
    const std::lock_guard lock(mutex_);
    return dropped_requests_;
  }

  // ---- introspection (takes the lock; allocates) ---------------------------------------------
  std::vector<Condition> conditions(MachineId id) const;
  /// The machine's outstanding condition, if any.
  std::optional<Condition> outstanding(MachineId id) const;
  /// The last records of a machine still in the history (at most history_capacity), oldest first.
  std::vector<Record> history(MachineId id) const;
  /// The records in the history about `scope`, oldest first: for a machine, its records; for a
  /// service, its component and SYSTEM, the records of every machine and component transition in
  /// scope. At most history_capacity for an address other than SYSTEM (SYSTEM: the whole ring).
  /// Only the newest `last` of them (0: all kept) and, when
  /// `kind` is given, only records of that kind (a component's extended-state transitions: its
  /// scope and RecordKind::ComponentTransition). One backwards pass that stops at the `last`-th
  /// record found: only what is returned is decoded.
  std::vector<Record> history(const Address& scope, std::size_t last = 0,
                              std::optional<RecordKind> kind = std::nullopt) const;
  /// The records still in the history whose sequence number is above `seq`, oldest first, at most
  /// `max` and never more than history_capacity (0: history_capacity): how a follower fills a gap,
  /// reading again from the last record it got until an answer is empty. The ring is ordered by sequence
  /// number, so the first one is found by bisection and only the records returned are decoded:
  /// the lock that generate() takes is held for O(log ring + max), however large the ring is
  /// (docs/semantics.md §8.3). A first record above seq + 1 means the ring has overwritten those
  /// in between.
  std::vector<Record> records_since(std::uint64_t seq, std::size_t max) const;
  /// How many records the history can hold (see CoordinatorOptions).
  std::size_t history_size() const noexcept { return history_.items.size(); }
  /// Every active condition at `address` (machine, service, component, SYSTEM) with its root
  /// cause and hop path.
  std::vector<Explanation> explain(const Address& address) const;

  // ---- callbacks and observers ---------------------------------------------------------------
  // A registration waits until the records being handed out (by another thread) have been; once
  // it returns, the callbacks or observer see every later record, and an unsubscribed observer is
  // never called again. Made from inside a callback or observer, it takes effect once the records
  // being handed out have been.
  using SubscriptionId = std::uint32_t;
  /// Registers callbacks on one machine.
  void on_machine(MachineId id, StateCallbacks callbacks);
  /// Registers callbacks on a component's extended state.
  void on_component(ComponentId id, StateCallbacks callbacks);
  /// Subscribes to the observer stream. The function must not block or throw.
  SubscriptionId subscribe(std::function<void(const Record&)> observer);
  void unsubscribe(SubscriptionId id);
  /// Publishes a record that originates outside the core (e.g. an injection) on the stream and,
  /// when it names a machine, in that machine's history. A write, as generate().
  void publish(Record record);

private:
  struct Edge {
    MachineId to;
    State min_level;
    ConnectionId via;
  };
  /// A record as the history stores it (docs/semantics.md §8.3): 40 bytes instead of Record's
  /// 120. The component of a machine record is its machine's, names and texts are ids resolved
  /// when the history is read, and the root cause is a slot of History::roots, written once for
  /// a run of records that share it (a propagation writes hundreds of records with one root).
  struct StoredRecord {
    Time::rep time = 0;
    std::uint64_t seq = 0;
    std::uint32_t subject = kNone;  ///< the machine; the component for component transitions
    std::uint32_t event = kNone;
    std::uint32_t via = kNone;
    std::uint32_t root = kNone;  ///< slot in History::roots; kNone: no root cause
    std::uint32_t text = kNone;  ///< a NameId, one of the kText* codes, or kNone
    RecordKind kind = RecordKind::Event;
    Outcome outcome = Outcome::None;
    std::uint8_t states = 0;  ///< from | to << 2 | level << 4 | mirror << 6
    std::uint8_t severity = 0;
  };
  /// Texts of ignored completions (static, never interned).
  static constexpr std::uint32_t kTextNoOnset = kNone - 1;
  static constexpr std::uint32_t kTextNotActive = kNone - 2;
  static constexpr std::uint32_t kTextLatched = kNone - 3;
  /// Text of a remote root's clear (apply_remote()).
  static constexpr std::uint32_t kTextNoLongerReported = kNone - 4;
  /// The text a code stands for (kNone: empty).
  std::string_view text_of(std::uint32_t text) const;
  /// The history: one ring of stored records and one ring of root causes of the same capacity.
  /// A record refers to the root slot written last when it was stored; each record writes at most
  /// one root, so while a record is in its ring, fewer than `capacity` roots were written after
  /// its own and that root's slot has not been reused.
  struct History {
    std::vector<StoredRecord> items;
    std::vector<RootCause> roots;
    std::size_t next = 0;
    std::size_t size = 0;
    std::size_t next_root = 0;
    std::uint32_t last_root = kNone;  ///< slot of the root written last
    void push(const Record& r, std::uint32_t text) noexcept;
    /// Grows to `capacity` keeping the records in order (configuration time only).
    void grow(std::size_t capacity);
  };
  /// Sizes the history for the model configured so far (CoordinatorOptions).
  void size_history();
  /// The Record a stored record stands for.
  Record decode(const StoredRecord& s) const;
  /// The component a stored record is about.
  ComponentId stored_component(const StoredRecord& s) const noexcept;
  History history_;  ///< every machine and component record of this coordinator
  /// The run-time side of a machine (its shape is Structure's).
  struct MachineData {
    ComponentId component = kNoComponent;  ///< Structure's, copied to the line the hot path reads
    std::atomic<std::uint64_t> snapshot{0};
    std::vector<Edge> fanout;
    ConditionSet conditions;  ///< §2.4: the machine's state and outstanding condition
    std::vector<StateCallbacks> callbacks;
  };
  /// The run-time side of a component (its shape is Structure's).
  struct ComponentData {
    // Read or written on every change of one of its machines (update_component): first.
    std::array<std::uint32_t, 3> machine_state_count{};
    State state = State::Normal;
    /// Its machines are ids [first_machine, first_machine + machine_count) when `contiguous` (the
    /// usual case: interfaces are added right after their component); else see Structure's lists.
    bool contiguous = true;
    EventId outstanding = kNoEvent;
    MachineId first_machine = kNoMachine;
    std::uint32_t machine_count = 0;
    std::atomic<std::uint64_t> snapshot{0};
    std::vector<StateCallbacks> callbacks;
  };
  /// What update_component() reads of each machine, in one dense array by machine id: the
  /// machines of a component are created together, so their summaries share a cache line and a
  /// component's outstanding event is found without visiting its machines.
  struct MachineSummary {
    std::uint64_t seq = 0;     ///< the outstanding condition's activation order
    EventId event = kNoEvent;  ///< the outstanding condition's event; kNoEvent in Normal
    State state = State::Normal;
    std::uint8_t severity = 0;  ///< the outstanding condition's severity
  };
  /// One write: what generate(), reset() and publish() do under the lock, and what a callback or
  /// observer asks them to do (queued until the records being handed out have been).
  enum class PendingKind : std::uint8_t { Generate, Reset, Publish };
  struct Pending {
    PendingKind kind = PendingKind::Generate;
    EventId event = kNoEvent;
    MachineId machine = kNoMachine;
    SampleCause cause;
    Address address;
    NameId why = kNoName;  ///< Reset: the interned "who: why" text
    Record record;         ///< Publish
  };
  /// A record to hand out after the write that made it, with the lock released: to the observers,
  /// and for a transition with callbacks, to the callbacks of its machine (or component).
  struct Delivery {
    Record record;
    std::uint64_t ticket = 0;  ///< the write it belongs to (writes are handed out in ticket order)
    bool observe = false;
    bool callbacks = false;
  };
  /// A registration made from inside a callback or observer, applied after the records being
  /// handed out.
  struct Registration {
    enum class Kind : std::uint8_t { Machine, Component, Subscribe, Unsubscribe } kind;
    std::uint32_t id = 0;  ///< machine, component or subscription
    StateCallbacks callbacks;
    std::function<void(const Record&)> observer;
  };
  class Requests;  ///< the writes requested while records are handed out (coordinator.cpp)

  static constexpr std::uint64_t pack(StateSnapshot s) noexcept {
    return static_cast<std::uint64_t>(s.state) | (static_cast<std::uint64_t>(s.outstanding) << 8);
  }
  static constexpr StateSnapshot unpack(std::uint64_t v) noexcept {
    return StateSnapshot{static_cast<State>(v & 0xffu), static_cast<EventId>(v >> 8)};
  }

  EventId add_event_unchecked(Event event);
  /// Adds provided or required interface `name` to `component` (add_provided, add_required).
  [[nodiscard]] Expected<MachineId> add_interface(ComponentId component, std::string_view name, MachineKind kind);
  MachineId add_machine(ComponentId component, MachineKind kind, std::uint32_t iface, std::string address);
  /// Recomputes the fan-out edges of `provider`'s machines (its connections as a provider).
  void rebuild_fanout(ComponentId provider);
  /// True when machine `id` feeds the service state of provided interface `provided` of `component`.
  bool depends_on(ComponentId component, std::uint32_t provided, MachineId id) const noexcept;

  // Writes: one operation under the lock, then its records handed out without it.
  /// Makes `op` and hands its records out (finish()); queued instead when called from a callback
  /// or observer of this coordinator.
  void write(const Pending& op) noexcept;
  /// The write `op` under the lock: processing, propagation, records staged in outbox_.
  void run(const Pending& op) noexcept;
  /// A write's staged records: their ticket (0: none) and whether this thread holds their turn
  /// already (the records in handing_).
  struct Sealed {
    std::uint64_t ticket = 0;
    bool turn = false;
  };
  /// After a write: hands its records out, then makes the writes its callbacks and observers
  /// queued, and theirs, at most 65536 of them.
  void finish(Sealed sealed) noexcept;
  /// Closes the staged records of the write just made (mutex_ held) with the next ticket, and
  /// takes their turn at once when it can.
  Sealed seal() noexcept;
  /// Hands out the records of a sealed write once every earlier write's have been; the writes its
  /// callbacks and observers make are appended to `queue`.
  void deliver(Sealed sealed, Requests& queue) noexcept;
  /// Calls the callbacks of a transition record's machine or component.
  void fire(const Delivery& d, Requests& queue) noexcept;
  /// Applies the registrations made while records were handed out (the turn held).
  void apply_registrations() noexcept;
  /// Makes a registration in a turn of its own; deferred when called while handing out.
  void register_now(Registration registration);
  /// Waits until every earlier ticket's turn is over.
  void wait_turn(std::uint64_t ticket) noexcept;
  /// Ends the turn of `ticket` and wakes the threads waiting for theirs.
  void end_turn(std::uint64_t ticket) noexcept;
  /// True on the thread that is handing out this coordinator's records (from its callbacks and
  /// observers): its writes are queued and its registrations deferred.
  bool delivering_here() const noexcept;
  void process(EventId event, MachineId target, const SampleCause& cause) noexcept;
  void process_onset(const Event& event, MachineId target, const SampleCause& cause, Time now) noexcept;
  void process_completion(const Event& event, MachineId target, Time now) noexcept;
  void reset_locked(const Address& target, NameId who_why, Time now) noexcept;
  /// Adds a condition (root or mirror) to a machine and applies §2.4 step 2.
  void add_condition(MachineId id, const Condition& c, Time now) noexcept;
  /// Removes condition `index` of a machine; `completion` is the event recorded.
  void remove_condition(MachineId id, std::size_t index, EventId completion, Time now, std::uint32_t text) noexcept;
  void propagate_onset(const Condition& root) noexcept;
  void propagate_clear(const RootCause& root, State level, Time now) noexcept;
  /// Calls `visit(edge)` once for every machine an error of `level` at `origin` reaches along the
  /// connections, breadth first: the walk of an onset's propagation and of its clearing alike.
  template <class Visit>
  void each_reached(MachineId origin, State level, Visit&& visit) noexcept;
  /// Writes the event record of a condition just added (change.index) and publishes the machine.
  void record_added(MachineId id, const ConditionChange& change, Time now) noexcept;
  /// Writes the event record of a condition just removed and publishes the machine.
  void record_removed(MachineId id, const ConditionChange& change, EventId event, Time now,
                      std::uint32_t text) noexcept;
  void update_machine(MachineId id, State old_state, EventId event, const RootCause* root, Time now) noexcept;
  void update_component(ComponentId id, EventId event, const RootCause* root, Time now) noexcept;
  /// Stages a record for the observers and, when `callbacks`, for the callbacks of its subject.
  void stage(const Record& r, bool callbacks) noexcept {
    if (observed_ || callbacks) outbox_.push_back(Delivery{r, 0, observed_, callbacks});
  }
  /// Numbers, stores and publishes a machine or component record; `text` as in StoredRecord.
  void record(Record& r, std::uint32_t text) noexcept;
  std::vector<Explanation> explain_machine(MachineId id) const;
  std::vector<std::string> hop_path(MachineId holder, const Condition& c) const;

  Structure structure_;
  std::unique_ptr<Clock> owned_clock_;
  const Clock* clock_;
  CoordinatorOptions options_;

  // The run-time side of machines and components, by the same ids as the structure's: a fault
  // that visits thousands of machines walks memory in order instead of chasing one heap object
  // per machine.
  detail::StableVector<MachineData, MachineId> machines_;
  detail::StableVector<ComponentData, ComponentId> components_;

  // ---- lock discipline ------------------------------------------------------------------------
  // - mutex_ guards everything that changes at run time (conditions, history, staged records,
  //   tickets); state reads never take it (they read the published atomic words). Every public
  //   member that needs it takes it once, on entry; private members assume it is held. It is never
  //   held while a callback or observer runs, so nothing ever takes it twice on one thread.
  // - Turns: a write stages its records in outbox_ and takes the next ticket under mutex_; with
  //   mutex_ released, it waits until `delivered_` reaches the ticket before it, hands its records
  //   out, and ends its turn by moving `delivered_` on. A registration takes a ticket too and
  //   changes the lists in its own turn, so no list is changed while it is walked. The turn holder
  //   alone touches handing_, deferred_ and requests_, and walks the lists. The thread handing out
  //   records (deliverer_) defers its own registrations and queues its own writes instead.
  // - Lock order: mutex_, then the structure's names lock; never the other way. Waiting for a turn
  //   holds no lock.
  mutable std::mutex mutex_;
  std::atomic<std::uint64_t> delivered_{0};   ///< the last ticket whose records were handed out
  std::atomic<std::uint32_t> waiters_{0};     ///< threads waiting for their turn
  std::atomic<std::thread::id> deliverer_{};  ///< the thread handing out records now; none: id{}
  Requests* requests_ = nullptr;              ///< its queue of requested writes (that thread only)
  std::uint64_t issued_ = 0;                  ///< the last ticket issued (mutex_)
  std::vector<Delivery> outbox_;              ///< staged records of the writes not yet handed out (mutex_)
  std::vector<Delivery> handing_;             ///< the records being handed out (the turn holder)
  std::vector<Registration> deferred_;        ///< registrations waiting for the end of a turn (the turn holder)
  bool observed_ = false;                     ///< observers_ is not empty (mutex_)
  static thread_local std::vector<Pending> spare_queue_;  ///< the queue of this thread's outermost write
  static thread_local bool spare_busy_;
  std::uint64_t condition_seq_ = 0;
  std::uint64_t record_seq_ = 0;
  std::uint64_t dropped_requests_ = 0;
  std::vector<MachineSummary> summaries_;   ///< by machine id, kept by update_machine()
  std::vector<MachineId> work_;             ///< BFS queue for propagation, reserved up front
  std::vector<std::uint64_t> visit_marks_;  ///< per machine: last BFS that visited it
  std::uint64_t visit_epoch_ = 0;
  std::vector<std::pair<SubscriptionId, std::function<void(const Record&)>>> observers_;
  SubscriptionId next_subscription_ = 1;

  struct RemoteRootData {
    std::string origin;
    std::vector<std::string> path;
    bool used = false;
  };
  std::vector<RemoteRootData> remote_roots_;  ///< indexed by RootCause::remote; slots are reused
  std::vector<std::uint32_t> free_remote_;
};

}  // namespace safecass
