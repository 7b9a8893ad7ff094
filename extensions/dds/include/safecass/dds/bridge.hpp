#pragma once
/// @file bridge.hpp
/// The ROS 2 framework extension over Eclipse Cyclone DDS: a SAFECASS coordinator that joins a
/// ROS 2 system at the wire level, without rclcpp, following ROS 2's conventions (ros2.hpp).
///
/// It reads the same mapping file as the ROS 1 extension (docs/frameworks.md, "The ROS mapping
/// file"), and the model and all that does not depend on how messages travel is the shared
/// ros_common::Shadow:
/// - each mapped topic "/a/b" is read from the DDS topic "rt/a/b" with its ROS 2 type; numeric
///   fields feed signals; each message runs the ACTIVE filters of the components it fed;
/// - GCM states are published as diagnostic_msgs/msg/DiagnosticArray on rt/diagnostics, as
///   diagnostic_updater does (periodically and at once after a change);
/// - statuses of other participants on rt/diagnostics become events (OK/WARN/ERROR/STALE);
/// - the graph check reads DDS discovery (DCPSPublication, DCPSSubscription): a mapped interface
///   with nobody on its topic, or a topic published with another type, raises
///   EVT_ROS_GRAPH_MISSING on the interface's machine. DDS does not name ROS nodes, so node
///   presence is not checked.
///
/// Lifecycle: create() (loads mapping and system; no DDS call) → add_loop() → start() (joins the
/// domain and starts the bridge's one spinning thread: messages, loops, diagnostics and the graph
/// check all run there) → stop(). Bad messages are counted, warned about and change nothing.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "safecass/ros_common/shadow.hpp"

namespace safecass::dds {

using ros_common::BridgeStats;
using ros_common::Mapping;

struct BridgeOptions {
  /// The DDS domain; -1: ROS_DOMAIN_ID, else 0.
  int domain = -1;
  /// Keep the participant on 127.0.0.1 (loopback_config()) unless CYCLONEDDS_URI configures
  /// Cyclone DDS; false: Cyclone's own defaults or CYCLONEDDS_URI.
  bool loopback = true;
  /// Where warnings go (default: stderr).
  std::function<void(const std::string&)> warn;
  /// Replaces the mapping's "system" when not empty.
  std::string system;
};

class Bridge {
public:
  using Body = ros_common::Shadow::Body;

  /// Loads `mapping_path` and the system it names and builds the model (ros_common::Shadow::create()
  /// says what is checked). Errors: Parse, NotFound, InvalidArgument.
  [[nodiscard]] static Expected<std::unique_ptr<Bridge>> create(const std::string& mapping_path,
                                                                const FilterRegistry& registry,
                                                                const Clock* clock = nullptr,
                                                                BridgeOptions options = {});
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  Coordinator& coordinator() noexcept;
  Monitor& monitor() noexcept;
  const Mapping& mapping() const noexcept;
  ros_common::Shadow& shadow() noexcept;

  /// Runs `body` every `period` on the spinning thread, after `component`'s ACTIVE filters.
  [[nodiscard]] Expected<void> add_loop(std::string_view component, Time period, Body body);

  /// Joins the DDS domain, creates the readers and the writer and starts the spinning thread.
  /// Errors: InvalidState (already started), InvalidArgument (domain), Io (DDS refused, with its reason).
  [[nodiscard]] Expected<void> start();
  /// Stops the thread and leaves the domain. Idempotent; the destructor calls it.
  void stop() noexcept;

  /// The domain joined (after start()).
  int domain() const noexcept;
  BridgeStats stats() const noexcept;
  std::string status_name(std::string_view address) const;

private:
  struct Impl;
  explicit Bridge(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::dds
