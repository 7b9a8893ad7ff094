#pragma once
/// @file mapping.hpp
/// The ROS mapping file: how a SAFECASS system specification meets a ROS graph, ROS 1 or ROS 2.
/// The system file stays framework-free; this small file says which ROS node each component is,
/// which topic carries which connection, which message fields feed which signals, and how
/// diagnostics flow. One format for both frameworks (a ROS 1 mapping runs unchanged on ROS 2): it
/// is documented in docs/frameworks.md ("The ROS mapping file"). Plain C++17, no ROS header.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "safecass/core/event.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/ros_common/fields.hpp"
#include "safecass/spec/diagnostics.hpp"

namespace safecass::ros_common {

/// One signal fed by a topic: `"JR3.Fx": "wrench.force.x"`.
struct FieldBinding {
  std::string signal;  ///< "Component.signal"
  FieldPath path;
  std::size_t size = 0;  ///< required for a whole JointState array whose signal the spec does not declare
  spec::Position where;
};

/// Timing supervision of one topic, built as a filter on the topic's arrival signal.
struct TopicCheck {
  std::string target;     ///< machine address, e.g. "JR3.s_F"
  double timeout = 0.0;   ///< watchdog: seconds without a message
  double min_rate = 0.0;  ///< frequency: Hz (0: no bound)
  double max_rate = 0.0;
  int window = 10;
  std::string event;  ///< onset (default: EVT_STALE for a watchdog, EVT_ROS_TOPIC_RATE for a frequency)
};

/// A topic: the connection it carries (a provided interface and the required interfaces that use
/// it) and the signals it feeds.
struct TopicMapping {
  std::string topic;  ///< resolved ROS name, e.g. "/jr3/wrench"
  MessageType type = MessageType::Float64;
  std::string provided;               ///< "C.p": the publisher's component and interface (may be empty)
  std::vector<std::string> required;  ///< "C.r": subscribers' components and interfaces
  std::vector<FieldBinding> signals;
  std::string rate_signal;  ///< one sample per message: the rate in Hz over the last messages
  std::string age_signal;   ///< sampled at the diagnostics period: seconds since the last message
  std::optional<TopicCheck> watchdog;
  std::optional<TopicCheck> frequency;
  spec::Position where;
};

/// Existing `/diagnostics` statuses turned into events (OK/WARN/ERROR/STALE → events on a machine).
struct IngestRule {
  std::string name;    ///< status name, exactly, or a prefix when it ends with '*'
  std::string target;  ///< machine address
  std::string warn = "EVT_ROS_DIAG_WARN";
  std::string error = "EVT_ROS_DIAG_ERROR";
  std::string stale = "EVT_STALE";
  /// Seconds without news of a status after which it counts as STALE (a node that crashed after
  /// saying OK is not OK); 0: never. diagnostic_aggregator's analyzers default to 5 s.
  double stale_after = 5.0;
  spec::Position where;

  bool matches(std::string_view status_name) const noexcept;
};

struct Mapping {
  int ros_version = 1;                                     ///< the header: "safecass_ros1": 1 or "safecass_ros2": 1
  std::string path;                                        ///< the mapping file as given
  std::string system;                                      ///< the system file, resolved relative to the mapping file
  std::string coordinator;                                 ///< only this coordinator's components (empty: all)
  std::vector<std::pair<std::string, std::string>> nodes;  ///< component → ROS node name
  std::vector<EventDef> events;                            ///< extra events of the ROS side
  std::vector<TopicMapping> topics;
  // diagnostics
  std::string publish_topic = "/diagnostics";
  double publish_period = 1.0;  ///< seconds; a change is published at once in addition
  std::string prefix = "safecass";
  std::string hardware_id;  ///< default: the coordinator's name
  std::string ingest_topic = "/diagnostics";
  std::vector<IngestRule> ingest;
  // graph check
  double graph_period = 1.0;  ///< seconds between checks (0: no check)
  double graph_grace = 2.0;   ///< seconds after start before a missing node or topic counts
  std::string graph_event = "EVT_ROS_GRAPH_MISSING";

  /// The ROS node of a component, or empty.
  const std::string* node_of(std::string_view component) const noexcept;
};

struct MappingLoad {
  std::optional<Mapping> mapping;
  std::vector<spec::Diagnostic> diagnostics;  ///< every problem, "file:line:col: error: ..."
};

/// Reads and checks a mapping file (shape, types, field paths). Names of components, interfaces,
/// signals and events are checked against the system when the bridge is built.
MappingLoad load_mapping(const std::string& path);
/// The same with the text given (`name` is used in diagnostics and to resolve the system path).
MappingLoad load_mapping_from_text(std::string_view text, const std::string& name);

/// The events the bridge defines unless the system already does: EVT_ROS_DIAG_WARN (N2W),
/// EVT_ROS_DIAG_ERROR (N2E, W2E), EVT_ROS_GRAPH_MISSING (N2E, W2E), EVT_ROS_TOPIC_RATE (N2W), each
/// with its completion.
std::vector<EventDef> default_ros_events();

}  // namespace safecass::ros_common
