#pragma once
/// @file shadow.hpp
/// The framework-free half of a ROS bridge: the Generic Component Model of a ROS graph, built from
/// a mapping file (mapping.hpp) and its system spec, and everything the bridge does with it that
/// does not depend on how messages travel. A framework extension (ROS 1 over roscpp, ROS 2 over
/// DDS) moves messages and calls the shadow; the shadow
/// - binds each mapped topic to its signals, its arrival-rate and age signals and its Watchdog and
///   Frequency filters;
/// - takes a message's numbers (deliver(); reject() for a message of the wrong shape), pushes them
///   and runs the ACTIVE filters of the components that have no loop of their own;
/// - runs the components' loops (run_loop(): EVT_THREAD_EXCEPTION and EVT_PERIOD_OVERRUN on s_F);
/// - samples the topics' ages and says when diagnostics are due (tick());
/// - builds the diagnostic statuses (statuses(): one per component and per state machine, with the
///   outstanding event and its root cause as key-values, plus the bridge's own);
/// - turns other nodes' statuses into events (ingest());
/// - compares the mapped graph with the live one (check_graph(): EVT_ROS_GRAPH_MISSING).
/// Threading: deliver(), run_loop(), tick(), statuses() and ingest() run on the extension's one
/// spinning thread; check_graph() may run on another. Plain C++17, no ROS header.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/ros_common/fields.hpp"
#include "safecass/ros_common/mapping.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::ros_common {

/// Counters, readable at any time (approximate while running).
struct BridgeStats {
  std::uint64_t messages = 0;      ///< topic messages that fed signals
  std::uint64_t bad_messages = 0;  ///< topic messages rejected (shape did not match the path)
  std::uint64_t diagnostics_published = 0;
  std::uint64_t statuses_ingested = 0;  ///< statuses of other nodes that matched a rule
  std::uint64_t bad_statuses = 0;       ///< statuses with a level that is not one
  std::uint64_t graph_checks = 0;
  std::uint64_t graph_problems = 0;  ///< missing items found by the last check
};

/// One diagnostic_msgs/DiagnosticStatus, framework-free.
struct Status {
  DiagnosticLevel level = DiagnosticLevel::Ok;
  std::string name;
  std::string message;
  std::string hardware_id;
  std::vector<std::pair<std::string, std::string>> values;
};

/// A status received from another node: its name and its level byte as sent.
struct ReceivedStatus {
  std::string_view name;
  int level = 0;
};

/// The live graph as the framework sees it.
struct GraphView {
  /// The node name of the bridge's own endpoints where nodes are not known: they count for a
  /// component whose loop runs in the bridge (its code is here), for no other.
  static constexpr std::string_view kSelf = "(this bridge)";
  /// False when the framework cannot name the nodes behind endpoints (then only topics are checked:
  /// a provided interface needs a publisher of its topic, a required one a subscriber).
  bool nodes_known = true;
  std::set<std::string> nodes;                               ///< running nodes
  std::map<std::string, std::set<std::string>> publishers;   ///< topic → nodes ("" when unknown)
  std::map<std::string, std::set<std::string>> subscribers;  ///< topic → nodes ("" when unknown)
  std::map<std::string, std::set<std::string>> mistyped;     ///< topic → other type names it is published with
};

class Shadow {
public:
  using Body = std::function<void(Time now)>;
  /// Where the shadow's warnings go (the extension logs them, throttled as it likes).
  using Warn = std::function<void(const std::string& text)>;

  /// Loads `mapping_path` and the system it names, checks one against the other and builds the
  /// coordinator (named after the mapping's coordinator, or the system) and monitor. `clock` must
  /// outlive the shadow (null: a SteadyClock). A non-empty `system_path` replaces the mapping's
  /// "system". Errors: Parse (every diagnostic, one per line), NotFound (unknown component,
  /// interface, signal, event), InvalidArgument (sizes).
  [[nodiscard]] static Expected<std::unique_ptr<Shadow>> create(const std::string& mapping_path,
                                                                const FilterRegistry& registry,
                                                                const Clock* clock = nullptr, Warn warn = {},
                                                                const std::string& system_path = {});
  ~Shadow();
  Shadow(const Shadow&) = delete;
  Shadow& operator=(const Shadow&) = delete;

  Coordinator& coordinator() noexcept { return instance_->coordinator(); }
  Monitor& monitor() noexcept { return instance_->monitor(); }
  /// The system file it was built from.
  const spec::SystemSpec& system() const noexcept { return instance_->spec(); }
  const Mapping& mapping() const noexcept { return mapping_; }

  // ---- topics ----
  struct Bound {
    Signal* signal = nullptr;
    FieldPath path;
    std::size_t width = 1;
  };
  std::size_t topic_count() const noexcept { return topics_.size(); }
  const TopicMapping& topic(std::size_t i) const noexcept;
  /// The signals a topic feeds, in the order deliver() takes their values.
  const std::vector<Bound>& bound(std::size_t i) const noexcept;
  /// Room for one message's values (all bound widths, in order): extract into it, then deliver().
  double* scratch(std::size_t i) noexcept;
  /// A message arrived on topic `i` and its values are in scratch(i): pushes them, the arrival
  /// rate, and runs the ACTIVE filters of the components it fed that have no loop.
  void deliver(std::size_t i, Time now);
  /// A message on topic `i` did not have the shape its paths need: counted, warned, nothing changed.
  void reject(std::size_t i, const std::string& why);

  // ---- loops ----
  /// Runs `body` every `period`, after `component`'s ACTIVE filters (the component's own loop). A
  /// body that throws raises EVT_THREAD_EXCEPTION on s_F until a cycle completes; one that takes
  /// longer than its period raises EVT_PERIOD_OVERRUN. Errors: InvalidState (after start()),
  /// NotFound, InvalidArgument.
  [[nodiscard]] Expected<void> add_loop(std::string_view component, Time period, Body body);
  std::size_t loop_count() const noexcept { return loops_.size(); }
  Time loop_period(std::size_t i) const noexcept;
  void run_loop(std::size_t i);

  // ---- running ----
  /// Decides which components each message runs, observes the coordinator for changes and starts
  /// the monitor. Errors: InvalidState (already started).
  [[nodiscard]] Expected<void> start();
  /// Stops the monitor and the observer. Idempotent; the destructor calls it.
  void stop() noexcept;
  bool started() const noexcept { return started_; }

  /// Every tick (the extensions tick at 50 Hz): samples the topics' ages and ages the ingested
  /// statuses; true when the diagnostics are due (a state changed, or the publish period passed).
  bool tick(Time now);
  /// True once after a state changed (tick() includes this): an extension that checks after each
  /// message publishes a change at once instead of at its next tick.
  bool take_change() noexcept { return dirty_.exchange(false, std::memory_order_acq_rel); }
  /// The statuses to publish now (components, machines, then the bridge); counts one publication.
  std::vector<Status> statuses();
  /// The status name of an address: "<prefix>: JR3", "<prefix>: JR3.s_A".
  std::string status_name(std::string_view address) const { return mapping_.prefix + ": " + std::string(address); }

  /// Statuses received from another node (not this one): those that match an ingest rule raise or
  /// clear the rule's events. A level that is not a level is counted, warned about and ignored. A
  /// status not received again within its rule's `stale_after` counts as STALE (tick() ages them).
  void ingest(const std::vector<ReceivedStatus>& statuses, std::string_view sender);
  bool ingests() const noexcept { return !ingests_.empty(); }

  /// Compares the mapping's nodes and topics with `live`: a missing node raises the graph event on
  /// its component's s_F, a missing publisher or subscriber (or a topic published with another
  /// type) on the interface's machine; each clears when the problem is gone. Thread-safe against
  /// the spinning thread (events go through the coordinator).
  void check_graph(const GraphView& live);

  BridgeStats stats() const noexcept;

private:
  struct Topic;
  struct Loop;
  struct Ingest;
  Shadow() = default;
  [[nodiscard]] Expected<void> bind();
  /// Ingested statuses not heard of within their rule's stale_after become STALE.
  void age_ingested(Time now);
  /// Raises and clears a rule's events after its statuses changed.
  void apply(Ingest& in);
  /// Warnings of bad input, at most one per 5 s (the counters in stats() keep the number).
  void warn_throttled(const std::string& text);
  void fill_status(Status& s, const std::string& address, StateSnapshot snap,
                   const std::optional<Condition>& outstanding) const;

  Mapping mapping_;
  Warn warn_;
  std::unique_ptr<spec::Instance> instance_;
  std::vector<std::unique_ptr<Topic>> topics_;
  std::vector<std::unique_ptr<Loop>> loops_;
  std::vector<Ingest> ingests_;
  EventId graph_event_ = kNoEvent;
  NameId graph_name_ = kNoName;
  NameId diagnostics_name_ = kNoName;
  bool started_ = false;
  Time last_publish_{};
  std::chrono::steady_clock::time_point last_throttled_warning_{};
  std::atomic<bool> dirty_{true};
  Coordinator::SubscriptionId observer_ = 0;
  std::map<MachineId, std::set<std::string>> graph_problems_;  ///< check_graph() only
  std::atomic<std::uint64_t> messages_{0}, bad_messages_{0}, published_{0}, ingested_{0}, bad_statuses_{0},
      graph_checks_{0}, graph_problem_count_{0};
};

}  // namespace safecass::ros_common
