#include "safecass/dds/ros2.hpp"

#include <cstdlib>

#include "ros2_msgs.h"

namespace safecass::dds {

std::string dds_topic(std::string_view ros_name) {
  std::string out(kTopicPrefix);
  if (ros_name.empty() || ros_name.front() != '/') out += '/';
  out += ros_name;
  return out;
}

std::optional<std::string> ros_topic(std::string_view dds_name) {
  if (dds_name.size() <= kTopicPrefix.size() + 1 || dds_name.substr(0, kTopicPrefix.size()) != kTopicPrefix ||
      dds_name[kTopicPrefix.size()] != '/')
    return std::nullopt;
  return std::string(dds_name.substr(kTopicPrefix.size()));
}

std::string_view dds_type(ros_common::MessageType type) noexcept {
  switch (type) {
    case ros_common::MessageType::Float64: return kFloat64Type;
    case ros_common::MessageType::WrenchStamped: return kWrenchStampedType;
    case ros_common::MessageType::JointState: break;
  }
  return kJointStateType;
}

const dds_topic_descriptor_t& descriptor(ros_common::MessageType type) noexcept {
  switch (type) {
    case ros_common::MessageType::Float64: return std_msgs_msg_dds__Float64__desc;
    case ros_common::MessageType::WrenchStamped: return geometry_msgs_msg_dds__WrenchStamped__desc;
    case ros_common::MessageType::JointState: break;
  }
  return sensor_msgs_msg_dds__JointState__desc;
}

const dds_topic_descriptor_t& diagnostic_array_descriptor() noexcept {
  return diagnostic_msgs_msg_dds__DiagnosticArray__desc;
}

dds_qos_t* qos(int depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_writer_data_lifecycle(q, false);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  return q;
}

[[nodiscard]] Expected<int> domain_id(int explicit_id) {
  if (explicit_id > kMaxDomainId)
    return fail(ErrorCode::InvalidArgument, "domain " + std::to_string(explicit_id) + " is outside [0, 232]");
  if (explicit_id >= 0) return explicit_id;
  const char* env = std::getenv("ROS_DOMAIN_ID");
  if (env == nullptr || *env == '\0') return 0;
  char* end = nullptr;
  const long id = std::strtol(env, &end, 10);
  if (*end != '\0' || id < 0 || id > kMaxDomainId) {
    return fail(ErrorCode::InvalidArgument,
                "ROS_DOMAIN_ID='" + std::string(env) + "' is not a domain id (an integer in [0, 232])");
  }
  return static_cast<int>(id);
}

[[nodiscard]] Expected<Participant> join(int domain, bool loopback) {
  auto id = domain_id(domain);
  if (!id) return tl::unexpected(id.error());
  Participant out;
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (loopback && (uri == nullptr || *uri == '\0')) {
    const dds_entity_t d = dds_create_domain(static_cast<dds_domainid_t>(*id), loopback_config().c_str());
    // PRECONDITION_NOT_MET: this process already has the domain, configured.
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET)
      return fail(ErrorCode::Io, std::string("DDS domain: ") + dds_strretcode(d));
    if (d > 0) out.domain = d;
  }
  out.participant = dds_create_participant(static_cast<dds_domainid_t>(*id), nullptr, nullptr);
  if (out.participant < 0) {
    const dds_return_t rc = out.participant;
    if (out.domain > 0) dds_delete(out.domain);
    return fail(ErrorCode::Io, std::string("DDS participant: ") + dds_strretcode(rc));
  }
  return out;
}

std::string loopback_config() {
  return "<CycloneDDS><Domain Id=\"any\">"
         "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast></General>"
         "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>60</MaxAutoParticipantIndex>"
         "<Peers><Peer address=\"127.0.0.1\"/></Peers><LeaseDuration>2s</LeaseDuration></Discovery>"
         "</Domain></CycloneDDS>";
}

}  // namespace safecass::dds
