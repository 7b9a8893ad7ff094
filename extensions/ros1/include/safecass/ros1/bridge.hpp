#pragma once
/// @file bridge.hpp
/// The ROS 1 framework extension: a SAFECASS coordinator inside a roscpp node.
///
/// - ROS nodes are GCM components and topics are connections between a provided and required
///   interfaces, as the mapping file says (mapping.hpp); the graph declared there is checked
///   against the master's live graph: a missing node, publisher or subscriber raises
///   EVT_ROS_GRAPH_MISSING on the interface's machine (and a ROS warning), cleared when it appears.
/// - Numeric message fields feed signals; each message runs the ACTIVE filters of the components
///   whose signals it fed. Per topic, an arrival/rate signal and an age signal feed the
///   Frequency and Watchdog filters.
/// - The GCM states are published as diagnostic_msgs/DiagnosticArray (one status per component
///   and per state machine), periodically and at once after a change.
/// - Statuses of other nodes on /diagnostics become events (OK/WARN/ERROR/STALE).
///
/// The model and everything that does not depend on roscpp is the shared ros_common::Shadow
/// (extensions/ros_common); this class moves messages between roscpp and it.
/// Lifecycle: create() (loads the mapping and the system, builds the model; no ROS call) →
/// add_loop() for components whose code runs in this node → start() (ros::init() done: subscribes,
/// advertises, starts timers, the monitor thread and the graph-check thread) → the application
/// spins the global callback queue from ONE thread (ros::spin()): message callbacks, loops and the
/// diagnostics timer all run there, so each component's ACTIVE filters run on one thread → stop().
/// Bad messages (wrong array length, unknown diagnostic level) are counted, warned about
/// (throttled) and change nothing; NaN/Inf samples raise EVT_INVALID_SAMPLE through the filters.

#include <memory>
#include <string>
#include <string_view>

#include "safecass/ros_common/shadow.hpp"

namespace safecass::ros1 {

using ros_common::BridgeStats;
using ros_common::Mapping;

class Bridge {
public:
  using Body = ros_common::Shadow::Body;

  /// Loads `mapping_path` and the system it names, checks one against the other and builds the
  /// coordinator (named after the mapping's coordinator, or the system) and monitor. `clock` must
  /// outlive the bridge (null: a SteadyClock). Errors: Parse (every diagnostic, one per line),
  /// NotFound (unknown component, interface, signal, event), InvalidArgument (sizes).
  [[nodiscard]] static Expected<std::unique_ptr<Bridge>> create(const std::string& mapping_path,
                                                                const FilterRegistry& registry,
                                                                const Clock* clock = nullptr);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  Coordinator& coordinator() noexcept;
  Monitor& monitor() noexcept;
  const Mapping& mapping() const noexcept;
  ros_common::Shadow& shadow() noexcept;

  /// Runs `body` every `period` on the spinning thread, after `component`'s ACTIVE filters (the
  /// component's own loop; use dispatch() inside). A body that throws raises
  /// EVT_THREAD_EXCEPTION on s_F until a cycle completes. Errors: NotFound, InvalidArgument.
  [[nodiscard]] Expected<void> add_loop(std::string_view component, Time period, Body body);

  /// Connects to ROS. Call after ros::init(). Errors: InvalidState (already started, no master).
  [[nodiscard]] Expected<void> start();
  /// Stops timers and threads, unsubscribes. Idempotent; the destructor calls it.
  void stop() noexcept;

  BridgeStats stats() const noexcept;

  /// The DiagnosticStatus name of an address: "<prefix>: JR3", "<prefix>: JR3.s_A".
  std::string status_name(std::string_view address) const;

private:
  struct Impl;
  explicit Bridge(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::ros1
