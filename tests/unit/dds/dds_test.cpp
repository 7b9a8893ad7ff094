// The ROS 2 (Cyclone DDS) extension against real Cyclone DDS participants in this process: ROS 2's
// wire conventions, QoS compatibility, a round trip of every mapped message type, diagnostics out
// and in, bad mappings, a topic of the wrong type and a participant that disappears. The domain
// is configured with no network peers, so each test process is a DDS world of its own.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <dds/ddsi/ddsi_serdata.h>

#include "ros2_msgs.h"
#include "safecass/dds/bridge.hpp"
#include "safecass/dds/ros2.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/ros_common/cdr.hpp"

using namespace safecass;
namespace ros2 = safecass::dds;

namespace {

constexpr dds_domainid_t kDomain = 7;
constexpr const char* kMapping = "tests/unit/dds/data/mapping.json";

/// A process-local domain: loopback only, no multicast, no peers.
dds_entity_t local_domain() {
  static const dds_entity_t domain = dds_create_domain(
      kDomain,
      "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
      "<AllowMulticast>false</AllowMulticast></General></Domain></CycloneDDS>");
  return domain;
}

/// Polls `done` until it holds or `seconds` pass.
bool wait_for(const std::function<bool()>& done, double seconds = 10.0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

/// A participant of its own (another "node") with ROS 2's default QoS.
struct Peer {
  dds_entity_t participant;
  Peer() : participant(dds_create_participant(kDomain, nullptr, nullptr)) {}
  ~Peer() {
    if (participant > 0) dds_delete(participant);
  }
  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& ros_topic, int depth = 10) {
    const dds_entity_t t = dds_create_topic(participant, &type, ros2::dds_topic(ros_topic).c_str(), nullptr, nullptr);
    dds_qos_t* q = ros2::qos(depth);
    const dds_entity_t w = dds_create_writer(participant, t, q, nullptr);
    dds_delete_qos(q);
    return w;
  }
  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& ros_topic, dds_qos_t* q) {
    const dds_entity_t t = dds_create_topic(participant, &type, ros2::dds_topic(ros_topic).c_str(), nullptr, nullptr);
    const dds_entity_t r = dds_create_reader(participant, t, q, nullptr);
    dds_delete_qos(q);
    return r;
  }
};

class Ros2Bridge : public ::testing::Test {
protected:
  void SetUp() override {
    ASSERT_GT(local_domain(), 0);
    register_builtin_filters(registry_);
    dds::BridgeOptions o;
    o.domain = kDomain;
    o.warn = [this](const std::string& text) {
      std::lock_guard<std::mutex> lock(warnings_mutex_);
      warnings_.push_back(text);
    };
    auto b = dds::Bridge::create(kMapping, registry_, nullptr, o);
    ASSERT_TRUE(b) << b.error().message;
    bridge_ = std::move(*b);
    ASSERT_TRUE(bridge_->start());
  }
  void TearDown() override {
    if (bridge_) bridge_->stop();
  }
  State state(const std::string& address) {
    auto m = bridge_->coordinator().structure().find_machine(address);
    return m ? bridge_->coordinator().snapshot(*m).state : State::Error;
  }
  bool latest(const std::string& signal, std::vector<double>& out) {
    Signal* s = bridge_->monitor().signals().find(signal);
    if (s == nullptr) return false;
    out.assign(s->size(), 0.0);
    Time t{};
    return s->latest(t, out.data());
  }
  std::string warnings() {
    std::lock_guard<std::mutex> lock(warnings_mutex_);
    std::string all;
    for (const auto& w : warnings_) all += w + "\n";
    return all;
  }

  FilterRegistry registry_;
  std::unique_ptr<dds::Bridge> bridge_;
  std::mutex warnings_mutex_;
  std::vector<std::string> warnings_;
};

geometry_msgs_msg_dds__WrenchStamped_ wrench(double fx, double fy, double fz) {
  static char frame[] = "jr3";
  geometry_msgs_msg_dds__WrenchStamped_ m{};
  m.header_.frame_id_ = frame;
  m.wrench_.force_ = {fx, fy, fz};
  m.wrench_.torque_ = {0.1, 0.2, 0.3};
  return m;
}

}  // namespace

// ---- ROS 2's conventions ------------------------------------------------------------------------

TEST(Ros2Conventions, ARosTopicIsTheDdsTopicWithTheRtPrefix) {
  EXPECT_EQ(ros2::dds_topic("/jr3/wrench"), "rt/jr3/wrench");
  EXPECT_EQ(ros2::dds_topic("/diagnostics"), "rt/diagnostics");
  EXPECT_EQ(ros2::ros_topic("rt/jr3/wrench"), "/jr3/wrench");
  EXPECT_FALSE(ros2::ros_topic("rq/add_two_intsRequest"));  // a service request, not a topic
  EXPECT_FALSE(ros2::ros_topic("DCPSPublication"));
  EXPECT_FALSE(ros2::ros_topic("rt"));
}

TEST(Ros2Conventions, TypeNamesArePackageMsgDdsNameUnderscore) {
  using ros_common::MessageType;
  EXPECT_STREQ(ros2::descriptor(MessageType::Float64).m_typename, "std_msgs::msg::dds_::Float64_");
  EXPECT_STREQ(ros2::descriptor(MessageType::WrenchStamped).m_typename, "geometry_msgs::msg::dds_::WrenchStamped_");
  EXPECT_STREQ(ros2::descriptor(MessageType::JointState).m_typename, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_STREQ(ros2::diagnostic_array_descriptor().m_typename, "diagnostic_msgs::msg::dds_::DiagnosticArray_");
  for (MessageType t : {MessageType::Float64, MessageType::WrenchStamped, MessageType::JointState})
    EXPECT_EQ(ros2::dds_type(t), ros2::descriptor(t).m_typename);
}

TEST(Ros2Conventions, MessageTypesAreWrittenAsRos1OrRos2Names) {
  EXPECT_EQ(*ros_common::parse_message_type("geometry_msgs/msg/WrenchStamped"), ros_common::MessageType::WrenchStamped);
  EXPECT_EQ(*ros_common::parse_message_type("geometry_msgs/WrenchStamped"), ros_common::MessageType::WrenchStamped);
  EXPECT_FALSE(ros_common::parse_message_type("geometry_msgs/msg/Twist"));
}

TEST(Ros2Conventions, TheDomainIsTheOptionElseRosDomainIdElseZero) {
  unsetenv("ROS_DOMAIN_ID");
  EXPECT_EQ(*ros2::domain_id(-1), 0);
  setenv("ROS_DOMAIN_ID", "42", 1);
  EXPECT_EQ(*ros2::domain_id(-1), 42);
  EXPECT_EQ(*ros2::domain_id(3), 3);
  setenv("ROS_DOMAIN_ID", "4x", 1);
  auto bad = ros2::domain_id(-1);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("ROS_DOMAIN_ID='4x'"), std::string::npos) << bad.error().message;
  setenv("ROS_DOMAIN_ID", "233", 1);
  EXPECT_FALSE(ros2::domain_id(-1));
  EXPECT_FALSE(ros2::domain_id(300));
  unsetenv("ROS_DOMAIN_ID");
}

// ---- QoS ----------------------------------------------------------------------------------------

TEST_F(Ros2Bridge, ReadersWithRos2sDefaultAndAggregatorQosMatchTheDiagnosticsWriter) {
  Peer peer;
  // rclcpp's default (rmw_qos_profile_default), spelled out here rather than taken from ros2::qos().
  dds_qos_t* ros2_default = dds_create_qos();
  dds_qset_reliability(ros2_default, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  dds_qset_durability(ros2_default, DDS_DURABILITY_VOLATILE);
  dds_qset_history(ros2_default, DDS_HISTORY_KEEP_LAST, 10);
  const dds_entity_t r1 = peer.reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", ros2_default);
  // diagnostic_aggregator: SystemDefaultsQoS().keep_last(1000); rqt and `ros2 topic echo` may use best effort.
  dds_qos_t* aggregator = dds_create_qos();
  dds_qset_history(aggregator, DDS_HISTORY_KEEP_LAST, 1000);
  dds_qset_reliability(aggregator, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  const dds_entity_t r2 = peer.reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", aggregator);
  dds_qos_t* best_effort = dds_create_qos();
  dds_qset_reliability(best_effort, DDS_RELIABILITY_BEST_EFFORT, 0);
  const dds_entity_t r3 = peer.reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", best_effort);
  for (dds_entity_t r : {r1, r2, r3}) {
    ASSERT_GT(r, 0);
    EXPECT_TRUE(wait_for([r] {
      dds_subscription_matched_status_t s{};
      return dds_get_subscription_matched_status(r, &s) == DDS_RETCODE_OK && s.current_count >= 1;
    })) << "reader "
        << r << " did not match the bridge's diagnostics writer";
  }
}

TEST_F(Ros2Bridge, AWriterWithRos2sDefaultQosMatchesTheTopicReader) {
  Peer peer;
  const dds_entity_t w = peer.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  ASSERT_GT(w, 0);
  EXPECT_TRUE(wait_for([w] {
    dds_publication_matched_status_t s{};
    return dds_get_publication_matched_status(w, &s) == DDS_RETCODE_OK && s.current_count >= 1;
  }));
}

// ---- round trips --------------------------------------------------------------------------------

TEST_F(Ros2Bridge, EveryMappedMessageTypeFeedsItsSignals) {
  Peer peer;
  const dds_entity_t w = peer.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  const dds_entity_t f = peer.writer(std_msgs_msg_dds__Float64__desc, "/jr3/temperature");
  const dds_entity_t j = peer.writer(sensor_msgs_msg_dds__JointState__desc, "/servo/joints");
  std::vector<double> v;
  const auto m = wrench(1.5, -2.5, 12.25);
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &m);
    return latest("JR3.Fz", v) && v[0] == 12.25;
  }));
  ASSERT_TRUE(latest("JR3.Fx", v));
  EXPECT_EQ(v[0], 1.5);
  ASSERT_TRUE(latest("JR3.Fy", v));
  EXPECT_EQ(v[0], -2.5);
  ASSERT_TRUE(latest("JR3.Torque", v));
  EXPECT_EQ(v, (std::vector<double>{0.1, 0.2, 0.3}));

  const std_msgs_msg_dds__Float64_ temperature{36.5};
  ASSERT_TRUE(wait_for([&] {
    dds_write(f, &temperature);
    return latest("JR3.Temperature", v) && v[0] == 36.5;
  }));

  double position[3] = {0.1, 0.2, 0.3}, velocity[2] = {5.0, 6.0};
  sensor_msgs_msg_dds__JointState_ js{};
  static char frame[] = "";
  js.header_.frame_id_ = frame;
  js.position_ = {3, 3, position, false};
  js.velocity_ = {2, 2, velocity, false};
  ASSERT_TRUE(wait_for([&] {
    dds_write(j, &js);
    return latest("SERVO.Speed1", v) && v[0] == 6.0;
  }));
  ASSERT_TRUE(latest("SERVO.Joints", v));
  EXPECT_EQ(v, (std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_EQ(bridge_->stats().bad_messages, 0u);
}

TEST_F(Ros2Bridge, AMessageOfTheWrongShapeIsCountedAndChangesNothing) {
  Peer peer;
  const dds_entity_t j = peer.writer(sensor_msgs_msg_dds__JointState__desc, "/servo/joints");
  double two[2] = {1.0, 2.0};
  sensor_msgs_msg_dds__JointState_ js{};
  static char frame[] = "";
  js.header_.frame_id_ = frame;
  js.position_ = {2, 2, two, false};  // the signal wants 3
  js.velocity_ = {2, 2, two, false};
  ASSERT_TRUE(wait_for([&] {
    dds_write(j, &js);
    return bridge_->stats().bad_messages >= 1;
  }));
  std::vector<double> v;
  EXPECT_FALSE(latest("SERVO.Joints", v));
  EXPECT_FALSE(latest("SERVO.Speed1", v));  // nothing of the message was pushed
  EXPECT_NE(warnings().find("position has 2 elements, the signal expects 3"), std::string::npos) << warnings();
}

TEST_F(Ros2Bridge, StatesArePublishedAsDiagnosticArraysWithTheirCause) {
  Peer peer;
  const dds_entity_t r = peer.reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics",
                                     ros2::qos(ros2::kDiagnosticsReaderDepth));
  const dds_entity_t w = peer.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  const auto m = wrench(0.0, 0.0, 45.0);  // above JR3's 30 N limit
  std::string level_message, root_cause;
  std::string hardware_id;
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &m);
    void* samples[4] = {};
    dds_sample_info_t infos[4];
    const dds_return_t n = dds_take(r, samples, infos, 4, 4);
    for (dds_return_t k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      const auto* a = static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[k]);
      for (std::uint32_t s = 0; s < a->status_._length; ++s) {
        const auto& st = a->status_._buffer[s];
        if (std::string(st.name_) != "safecass: JR3.s_A" || st.level_ != 2) continue;
        level_message = st.message_;
        hardware_id = st.hardware_id_;
        for (std::uint32_t v = 0; v < st.values_._length; ++v) {
          if (std::string(st.values_._buffer[v].key_) == "root_cause") root_cause = st.values_._buffer[v].value_;
        }
      }
    }
    if (n > 0) dds_return_loan(r, samples, n);
    return !level_message.empty();
  }));
  EXPECT_EQ(level_message.rfind("Error: EVT_FORCE_ERROR (cause JR3.s_A:EVT_FORCE_ERROR, force_limit judged", 0), 0u)
      << level_message;
  EXPECT_EQ(root_cause, "JR3.s_A:EVT_FORCE_ERROR");
  EXPECT_EQ(hardware_id, "robot");
}

TEST_F(Ros2Bridge, AnotherNodesDiagnosticsBecomeEventsAndClear) {
  Peer peer;
  const dds_entity_t w = peer.writer(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", 1);
  char name[] = "jr3_sim: saturation", empty[] = "";
  diagnostic_msgs_msg_dds__DiagnosticStatus_ s{};
  s.name_ = name;
  s.message_ = s.hardware_id_ = empty;
  diagnostic_msgs_msg_dds__DiagnosticArray_ a{};
  a.header_.frame_id_ = empty;
  a.status_ = {1, 1, &s, false};
  s.level_ = 1;  // WARN
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &a);
    return state("JR3.s_F") == State::Warning;
  }));
  s.level_ = 0;  // OK
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &a);
    return state("JR3.s_F") == State::Normal;
  }));
  s.level_ = 9;  // not a level: counted, ignored
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &a);
    return bridge_->stats().bad_statuses >= 1;
  }));
  EXPECT_EQ(state("JR3.s_F"), State::Normal);
}

TEST_F(Ros2Bridge, AnIngestedStatusThatFallsSilentIsStaleNotOk) {
  Peer peer;
  const dds_entity_t w = peer.writer(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", 1);
  char name[] = "jr3_sim: saturation", empty[] = "";
  diagnostic_msgs_msg_dds__DiagnosticStatus_ s{};
  s.name_ = name;
  s.message_ = s.hardware_id_ = empty;
  s.level_ = 0;  // OK
  diagnostic_msgs_msg_dds__DiagnosticArray_ a{};
  a.header_.frame_id_ = empty;
  a.status_ = {1, 1, &s, false};
  const auto m = wrench(0.0, 0.0, 5.0);  // keeps JR3's own force checks quiet
  const dds_entity_t force = peer.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &a);
    dds_write(force, &m);
    return bridge_->stats().statuses_ingested > 0 && state("JR3.s_F") == State::Normal;
  }));
  // The node falls silent (its status was OK): after the rule's 0.5 s it is STALE, an Error.
  const auto silent = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_for([&] {
    dds_write(force, &m);
    return state("JR3.s_F") == State::Error;
  }));
  EXPECT_GE(std::chrono::steady_clock::now() - silent, std::chrono::milliseconds(450));
  auto machine = bridge_->coordinator().structure().find_machine("JR3.s_F");
  EXPECT_EQ(bridge_->coordinator().structure().event(bridge_->coordinator().snapshot(*machine).outstanding).name,
            "EVT_STALE");
  // It speaks again: OK again.
  EXPECT_TRUE(wait_for([&] {
    dds_write(w, &a);
    dds_write(force, &m);
    return state("JR3.s_F") == State::Normal;
  }));
}

// ---- the graph ----------------------------------------------------------------------------------

TEST_F(Ros2Bridge, ATopicPublishedWithAnotherTypeRaisesTheGraphEventOnItsInterface) {
  Peer peer;
  const dds_entity_t w = peer.writer(std_msgs_msg_dds__Float64__desc, "/jr3/wrench");  // not a WrenchStamped
  ASSERT_GT(w, 0);
  ASSERT_TRUE(wait_for([&] { return state("JR3.s_P.ForceData") == State::Error; }));
  auto m = bridge_->coordinator().structure().find_machine("JR3.s_P.ForceData");
  const auto why = bridge_->coordinator().outstanding(*m);
  ASSERT_TRUE(why);
  const std::string cause(bridge_->coordinator().structure().name_of(why->root.sample.signal));
  EXPECT_NE(cause.find("/jr3/wrench is published as std_msgs::msg::dds_::Float64_, the mapping expects "
                       "geometry_msgs/WrenchStamped"),
            std::string::npos)
      << cause;
  std::vector<double> v;
  EXPECT_FALSE(latest("JR3.Fz", v));  // a reader of the right type never matched it
}

TEST_F(Ros2Bridge, AProviderThatDisappearsTurnsItsViewToErrorNotStale) {
  auto peer = std::make_unique<Peer>();
  const dds_entity_t w = peer->writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  const auto m = wrench(0.0, 0.0, 5.0);
  ASSERT_TRUE(wait_for([&] {
    dds_write(w, &m);
    return state("JR3.s_F") == State::Normal && state("JR3.s_P.ForceData") == State::Normal &&
           bridge_->stats().messages > 5;
  }));
  peer.reset();  // the driver's participant is gone
  EXPECT_TRUE(wait_for([&] { return state("JR3.s_F") == State::Error; }, 5.0)) << "the watchdog did not fire";
  EXPECT_TRUE(wait_for([&] { return state("JR3.s_P.ForceData") == State::Error; }, 5.0))
      << "the graph check did not see the publisher go";
  // It comes back: everything clears.
  Peer again;
  const dds_entity_t w2 = again.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  EXPECT_TRUE(wait_for([&] {
    dds_write(w2, &m);
    return state("JR3.s_F") == State::Normal && state("JR3.s_P.ForceData") == State::Normal;
  }));
}

// ---- bad input ----------------------------------------------------------------------------------

TEST(Ros2BridgeCreate, ABadMappingIsRefusedWithFileLineAndColumn) {
  const std::string path = ::testing::TempDir() + "bad_mapping.json";
  std::ofstream(path) << "{\n  \"safecass_ros2\": 1,\n  \"system\": \"x.json\",\n"
                         "  \"topics\": [ { \"topic\": \"/w\", \"type\": \"geometry_msgs/msg/WrenchStamped\",\n"
                         "                \"signals\": { \"JR3.Fz\": \"wrench.force.w\" } } ]\n}\n";
  FilterRegistry registry;
  register_builtin_filters(registry);
  auto b = dds::Bridge::create(path, registry);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code, ErrorCode::Parse);
  EXPECT_NE(b.error().message.find(path + ":5:40: error: field path 'wrench.force.w' of geometry_msgs/WrenchStamped: "
                                          "unknown field 'w' of a vector (expected x, y, z)"),
            std::string::npos)
      << b.error().message;
}

TEST(Ros2BridgeCreate, ASecondHeaderOrNoneIsRefused) {
  for (const char* header : {"\"safecass_ros1\": 1, \"safecass_ros2\": 1,", ""}) {
    const auto load =
        ros_common::load_mapping_from_text(std::string("{ ") + header + " \"system\": \"x.json\" }", "m.json");
    ASSERT_FALSE(load.mapping);
    ASSERT_FALSE(load.diagnostics.empty());
    EXPECT_NE(load.diagnostics[0].message.find("safecass_ros2"), std::string::npos) << load.diagnostics[0].message;
  }
}

// ---- CDR: the numbers of a message from its bytes (ROS 2 bags) ---------------------------------------

namespace {

/// The CDR bytes Cyclone DDS puts on the wire for `sample`.
std::vector<std::uint8_t> wire_bytes(const dds_topic_descriptor_t& type, const char* name, const void* sample) {
  const dds_entity_t pp = dds_create_participant(kDomain, nullptr, nullptr);
  const dds_entity_t topic = dds_create_topic(pp, &type, name, nullptr, nullptr);
  dds_qos_t* q = ros2::qos();
  const dds_entity_t w = dds_create_writer(pp, topic, q, nullptr);
  const dds_entity_t r = dds_create_reader(pp, topic, q, nullptr);
  dds_delete_qos(q);
  dds_write(w, sample);
  ddsi_serdata* data = nullptr;
  dds_sample_info_t info;
  std::vector<std::uint8_t> bytes;
  if (wait_for([&] { return dds_takecdr(r, &data, 1, &info, DDS_ANY_STATE) == 1; })) {
    bytes.resize(ddsi_serdata_size(data));
    ddsi_serdata_to_ser(data, 0, bytes.size(), bytes.data());
    ddsi_serdata_unref(data);
  }
  dds_delete(pp);
  return bytes;
}

}  // namespace

TEST(Ros2Cdr, EveryMappedTypeDecodesFromTheBytesCycloneDdsWrites) {
  ASSERT_GT(local_domain(), 0);
  using ros_common::MessageType;
  ros_common::DecodedMessage m;
  std::string error;

  const std_msgs_msg_dds__Float64_ f{-273.15};
  auto bytes = wire_bytes(std_msgs_msg_dds__Float64__desc, "cdr_f", &f);
  ASSERT_TRUE(ros_common::decode_cdr(MessageType::Float64, bytes.data(), bytes.size(), m, error)) << error;
  EXPECT_EQ(m.numbers.data, -273.15);

  // An odd-length frame id puts the doubles after padding.
  char frame[] = "sensor_frame_1";
  geometry_msgs_msg_dds__WrenchStamped_ w{};
  w.header_.stamp_ = {1700000000, 123};
  w.header_.frame_id_ = frame;
  w.wrench_.force_ = {1.0, 2.0, 3.0};
  w.wrench_.torque_ = {4.0, 5.0, 6.0};
  bytes = wire_bytes(geometry_msgs_msg_dds__WrenchStamped__desc, "cdr_w", &w);
  ASSERT_TRUE(ros_common::decode_cdr(MessageType::WrenchStamped, bytes.data(), bytes.size(), m, error)) << error;
  EXPECT_EQ(std::vector<double>(m.numbers.wrench, m.numbers.wrench + 6), (std::vector<double>{1, 2, 3, 4, 5, 6}));

  char a[] = "shoulder", b[] = "elbow_joint";
  char* names[] = {a, b};
  double position[2] = {0.5, -0.25}, effort[1] = {7.0};
  sensor_msgs_msg_dds__JointState_ js{};
  js.header_.frame_id_ = frame;
  js.name_ = {2, 2, names, false};
  js.position_ = {2, 2, position, false};  // velocity: empty
  js.effort_ = {1, 1, effort, false};
  bytes = wire_bytes(sensor_msgs_msg_dds__JointState__desc, "cdr_j", &js);
  ASSERT_TRUE(ros_common::decode_cdr(MessageType::JointState, bytes.data(), bytes.size(), m, error)) << error;
  EXPECT_EQ(m.position, (std::vector<double>{0.5, -0.25}));
  EXPECT_TRUE(m.velocity.empty());
  EXPECT_EQ(m.effort, (std::vector<double>{7.0}));
  EXPECT_EQ(m.numbers.position_size, 2u);
}

TEST(Ros2Cdr, BigEndianCdrDecodesToo) {
  // 00 00 (CDR big endian), then 1.5 as a big-endian double.
  const std::uint8_t bytes[] = {0, 0, 0, 0, 0x3f, 0xf8, 0, 0, 0, 0, 0, 0};
  ros_common::DecodedMessage m;
  std::string error;
  ASSERT_TRUE(ros_common::decode_cdr(ros_common::MessageType::Float64, bytes, sizeof bytes, m, error)) << error;
  EXPECT_EQ(m.numbers.data, 1.5);
}

TEST(Ros2Cdr, BytesThatAreNotTheMessageAreRefusedWithWhereAndWhat) {
  ros_common::DecodedMessage m;
  std::string error;
  using ros_common::MessageType;
  const std::uint8_t short_header[] = {0, 1};
  EXPECT_FALSE(ros_common::decode_cdr(MessageType::Float64, short_header, sizeof short_header, m, error));
  EXPECT_EQ(error, "byte 0: fewer than the 4 bytes of the CDR encapsulation header");
  const std::uint8_t xcdr2[] = {0, 7, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_FALSE(ros_common::decode_cdr(MessageType::Float64, xcdr2, sizeof xcdr2, m, error));
  EXPECT_EQ(error, "byte 0: encapsulation 00 07 is not plain CDR (00 00 or 00 01)");
  // A WrenchStamped whose frame id claims 4 GB.
  const std::uint8_t huge_string[] = {0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, 'a'};
  EXPECT_FALSE(ros_common::decode_cdr(MessageType::WrenchStamped, huge_string, sizeof huge_string, m, error));
  EXPECT_EQ(error, "byte 12: a string of 4294967295 bytes runs past the end (17 bytes)");
  // A JointState whose names claim 1,000,000 strings in a few bytes.
  const std::uint8_t many[] = {0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0x40, 0x42, 0x0f, 0x00};
  EXPECT_FALSE(ros_common::decode_cdr(MessageType::JointState, many, sizeof many, m, error));
  EXPECT_EQ(error, "byte 20: a sequence of 1000000 strings runs past the end (24 bytes)");
}

TEST(Ros2Graph, ARequiredInterfaceNeedsAnotherNodesSubscriptionNotTheBridgesOwnReader) {
  ASSERT_GT(local_domain(), 0);
  FilterRegistry registry;
  register_builtin_filters(registry);
  dds::BridgeOptions o;
  o.domain = kDomain;
  o.warn = [](const std::string&) {};
  auto b = dds::Bridge::create("tests/unit/dds/data/required_mapping.json", registry, nullptr, o);
  ASSERT_TRUE(b) << b.error().message;
  dds::Bridge& bridge = **b;
  ASSERT_TRUE(bridge.start());
  Coordinator& co = bridge.coordinator();
  const MachineId required = *co.structure().find_machine("CONTROL.s_R.ForceData");
  // The force flows (JR3 stays Normal), so only the graph can fail CONTROL's required interface.
  Peer driver;
  const dds_entity_t w = driver.writer(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench");
  const auto m = wrench(0.0, 0.0, 5.0);
  auto state = [&] {
    dds_write(w, &m);
    return co.snapshot(required).state;
  };
  const MachineId jr3 = *co.structure().find_machine("JR3.s_F");
  ASSERT_TRUE(wait_for([&] { return state() != State::Normal && co.snapshot(jr3).state == State::Normal; }))
      << "CONTROL.s_R.ForceData " << to_string(state()) << ", JR3.s_F " << to_string(co.snapshot(jr3).state);
  // Only the bridge reads /jr3/wrench: CONTROL's subscription is missing, and that is the cause.
  auto cause = [&] {
    const auto why = co.outstanding(required);
    return why ? std::string(co.structure().name_of(why->root.sample.signal)) : std::string();
  };
  EXPECT_TRUE(wait_for([&] {
    return state() == State::Error && cause() == "nobody subscribes to /jr3/wrench (CONTROL.ForceData)";
  })) << cause();
  // A ROS 2 node (another participant) subscribes: the interface is complete again.
  Peer control;
  dds_qos_t* q = ros2::qos();
  const dds_entity_t reader = control.reader(geometry_msgs_msg_dds__WrenchStamped__desc, "/jr3/wrench", q);
  ASSERT_GT(reader, 0);
  EXPECT_TRUE(wait_for([&] { return state() == State::Normal; }));
  bridge.stop();
}
