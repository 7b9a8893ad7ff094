#pragma once
/// @file ros2.hpp
/// ROS 2's conventions on a DDS wire, as constants with the public sources they come from, so that
/// a plain Cyclone DDS participant and a ROS 2 node (rmw_cyclonedds_cpp) understand each other.
///
/// - Topics: a ROS topic "/a/b" is the DDS topic "rt/a/b" (ros2/rmw_cyclonedds,
///   rmw_cyclonedds_cpp/src/namespace_prefix.hpp: ROS_TOPIC_PREFIX = "rt"; ROS 2 design article
///   "Topic and Service name mapping to DDS").
/// - Types: message M of package P is the DDS type "P::msg::dds_::M_" (ros2/rmw_cyclonedds,
///   rmw_cyclonedds_cpp/src/MessageTypeSupport_impl.hpp: namespace, "dds_::", name, "_").
///   The IDL is extensions/dds/idl/ros2_msgs.idl, in plain CDR.
/// - QoS: rclcpp's default profile is reliable, volatile, keep last 10 (ros2/rmw,
///   rmw/include/rmw/qos_profiles.h: rmw_qos_profile_default); rmw_cyclonedds_cpp maps
///   SYSTEM_DEFAULT reliability to reliable and the system-default depth to 1, and disables
///   auto-dispose (rmw_cyclonedds_cpp/src/rmw_node.cpp, create_readwrite_qos()).
/// - /diagnostics: diagnostic_updater publishes with depth 1 (ros/diagnostics, branch ros2,
///   diagnostic_updater/include/diagnostic_updater/diagnostic_updater.hpp), the aggregator
///   subscribes with SystemDefaultsQoS().keep_last(1000) (diagnostic_aggregator/src/aggregator.cpp).
/// - Domain: ROS_DOMAIN_ID, 0 when unset (ros2/rcl, rcl/src/rcl/domain_id.c).

#include <optional>
#include <string>
#include <string_view>

#include <dds/dds.h>

#include "safecass/core/expected.hpp"
#include "safecass/ros_common/fields.hpp"

namespace safecass::dds {

/// The prefix of every ROS topic on DDS.
inline constexpr std::string_view kTopicPrefix = "rt";

inline constexpr std::string_view kFloat64Type = "std_msgs::msg::dds_::Float64_";
inline constexpr std::string_view kWrenchStampedType = "geometry_msgs::msg::dds_::WrenchStamped_";
inline constexpr std::string_view kJointStateType = "sensor_msgs::msg::dds_::JointState_";
inline constexpr std::string_view kDiagnosticArrayType = "diagnostic_msgs::msg::dds_::DiagnosticArray_";

/// rclcpp's default history depth (rmw_qos_profile_default).
inline constexpr int kDefaultDepth = 10;
/// diagnostic_updater's publisher depth, and diagnostic_aggregator's subscription depth.
inline constexpr int kDiagnosticsWriterDepth = 1;
inline constexpr int kDiagnosticsReaderDepth = 1000;

/// The highest domain id ROS 2 accepts (rcl: RCL_DEFAULT_DOMAIN_ID range, 0–232 for UDP ports).
inline constexpr int kMaxDomainId = 232;

/// "/jr3/wrench" → "rt/jr3/wrench". `ros_name` is a global ROS name (starts with '/').
std::string dds_topic(std::string_view ros_name);
/// "rt/jr3/wrench" → "/jr3/wrench"; nullopt for a DDS topic that is not a ROS topic.
std::optional<std::string> ros_topic(std::string_view dds_name);

/// The DDS type name of a message type the bridge reads.
std::string_view dds_type(ros_common::MessageType type) noexcept;
/// The IDL-compiled descriptor of a message type the bridge reads.
const dds_topic_descriptor_t& descriptor(ros_common::MessageType type) noexcept;
const dds_topic_descriptor_t& diagnostic_array_descriptor() noexcept;

/// QoS as a ROS 2 node sets it; the caller deletes it with dds_delete_qos().
/// Reliable, volatile, keep last `depth`, auto-dispose off, plain CDR (XCDR1).
dds_qos_t* qos(int depth = kDefaultDepth);

/// The domain: `explicit_id` when >= 0, else ROS_DOMAIN_ID, else 0. Errors: InvalidArgument for a
/// ROS_DOMAIN_ID that is not an integer in [0, 232].
[[nodiscard]] Expected<int> domain_id(int explicit_id);

/// A participant of ROS 2's DDS world, and the domain entity when this call configured the domain.
struct Participant {
  dds_entity_t domain = 0;       ///< > 0: created here (loopback_config()); delete it after the participant
  dds_entity_t participant = 0;  ///< > 0
};
/// Joins `domain` (see domain_id()): on 127.0.0.1 only (loopback_config()) when `loopback` and
/// CYCLONEDDS_URI does not configure Cyclone DDS (a domain this process already has keeps its
/// configuration); else as CYCLONEDDS_URI or Cyclone's defaults say. Errors: InvalidArgument (the
/// domain), Io (DDS refused, with its reason).
[[nodiscard]] Expected<Participant> join(int domain, bool loopback = true);

/// A Cyclone DDS configuration that keeps a participant on 127.0.0.1: unicast discovery of peers
/// on the loopback address, no multicast, a 2 s participant lease (a vanished participant's
/// endpoints go within ~2 s). Used when CYCLONEDDS_URI is not set.
std::string loopback_config();

}  // namespace safecass::dds
