// Writes a ROS 2 bag (rosbag2's sqlite3 store) of the dds_robodoc example's force topic, for the
// rosbag2 replay tests (rosbag2_replay_test.sh). Each message is the CDR that Cyclone DDS puts on
// the wire for it (a writer and a reader in this process, dds_takecdr()), as `ros2 bag record`
// stores it. write_rosbag2 OUT.db3 good|wrong_type|bad_cdr|short_joint_state
//   good:              /jr3/wrench at 500 Hz for 1.2 s: the force rises from 5 N to 40 N
//                      (0.2 .. 0.6 s) and falls back (0.6 .. 1.0 s); /servo/joints at 50 Hz (SERVO.CycleTime 0.1 ms)
//   wrong_type:        the same, with /jr3/wrench's topic declared as std_msgs/msg/Float64
//   bad_cdr:           the same, with message 100 on /jr3/wrench cut to 20 bytes
//   short_joint_state: the same, with a /servo/joints whose position array is empty

#include <sqlite3.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <dds/ddsi/ddsi_serdata.h>

#include "ros2_msgs.h"
#include "safecass/dds/ros2.hpp"

namespace {

namespace ros2 = safecass::dds;

/// The CDR bytes of samples of one type, as Cyclone DDS serialises them.
class Serialiser {
public:
  Serialiser(dds_entity_t participant, const dds_topic_descriptor_t& type, const char* name) {
    const dds_entity_t topic = dds_create_topic(participant, &type, name, nullptr, nullptr);
    dds_qos_t* q = ros2::qos();
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    writer_ = dds_create_writer(participant, topic, q, nullptr);
    reader_ = dds_create_reader(participant, topic, q, nullptr);
    dds_delete_qos(q);
  }
  std::vector<unsigned char> operator()(const void* sample) {
    dds_write(writer_, sample);
    ddsi_serdata* data = nullptr;
    dds_sample_info_t info;
    while (dds_takecdr(reader_, &data, 1, &info, DDS_ANY_STATE) != 1) std::this_thread::yield();
    std::vector<unsigned char> bytes(ddsi_serdata_size(data));
    ddsi_serdata_to_ser(data, 0, bytes.size(), bytes.data());
    ddsi_serdata_unref(data);
    return bytes;
  }

private:
  dds_entity_t writer_ = 0, reader_ = 0;
};

bool exec(sqlite3* db, const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) == SQLITE_OK) return true;
  std::fprintf(stderr, "write_rosbag2: %s\n", error);
  sqlite3_free(error);
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_rosbag2 OUT.db3 good|wrong_type|bad_cdr|short_joint_state\n");
    return 2;
  }
  const std::string variant = argv[2];
  dds_create_domain(3,
                    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
                    "</Interfaces><AllowMulticast>false</AllowMulticast></General></Domain></CycloneDDS>");
  const dds_entity_t pp = dds_create_participant(3, nullptr, nullptr);
  Serialiser wrench_cdr(pp, geometry_msgs_msg_dds__WrenchStamped__desc, "rt/jr3/wrench");
  Serialiser joints_cdr(pp, sensor_msgs_msg_dds__JointState__desc, "rt/servo/joints");

  sqlite3* db = nullptr;
  std::remove(argv[1]);
  if (sqlite3_open(argv[1], &db) != SQLITE_OK) return 1;
  // rosbag2's schema (ros2/rosbag2, its sqlite3 storage plugin): only the tables and columns read.
  if (!exec(db,
            "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
            "INSERT INTO schema VALUES (3, 'humble');"
            "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);"
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
            "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
            "data BLOB NOT NULL);"
            "BEGIN;"))
    return 1;
  const std::string wrench_type = variant == "wrong_type" ? "std_msgs/msg/Float64" : "geometry_msgs/msg/WrenchStamped";
  if (!exec(db, ("INSERT INTO topics VALUES (1, '/jr3/wrench', '" + wrench_type +
                 "', 'cdr', '');"
                 "INSERT INTO topics VALUES (2, '/servo/joints', 'sensor_msgs/msg/JointState', 'cdr', '');")
                    .c_str()))
    return 1;
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &insert, nullptr);
  auto add = [&](int topic, long long stamp, const std::vector<unsigned char>& bytes) {
    sqlite3_bind_int(insert, 1, topic);
    sqlite3_bind_int64(insert, 2, stamp);
    sqlite3_bind_blob(insert, 3, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT);
    sqlite3_step(insert);
    sqlite3_reset(insert);
  };
  const long long begin = 1700000000LL * 1000000000LL;
  char frame[] = "jr3", joint[] = "joint_1";
  char* names[] = {joint};
  int wrench = 0;
  for (int i = 0; i <= 600; ++i) {  // every 2 ms
    const double t = i * 0.002;
    const long long stamp = begin + static_cast<long long>(i) * 2000000LL;
    double fz = 5.0;
    if (t >= 0.2 && t < 0.6) fz = 5.0 + 35.0 * (t - 0.2) / 0.4;
    if (t >= 0.6 && t < 1.0) fz = 40.0 - 35.0 * (t - 0.6) / 0.4;
    geometry_msgs_msg_dds__WrenchStamped_ w{};
    w.header_.stamp_ = {static_cast<std::int32_t>(stamp / 1000000000), static_cast<std::uint32_t>(stamp % 1000000000)};
    w.header_.frame_id_ = frame;
    w.wrench_.force_ = {0.1, -0.1, fz};
    w.wrench_.torque_ = {0.0, 0.0, 0.01 * fz};
    std::vector<unsigned char> bytes = wrench_cdr(&w);
    if (variant == "bad_cdr" && ++wrench == 100) bytes.resize(20);
    add(1, stamp, bytes);
    if (i % 10 == 0) {
      double position[1] = {0.0001};  // SERVO.CycleTime: 10 % of its 1 ms period
      sensor_msgs_msg_dds__JointState_ js{};
      js.header_.frame_id_ = frame;
      js.name_ = {1, 1, names, false};
      const std::uint32_t n = variant == "short_joint_state" && i == 300 ? 0u : 1u;
      js.position_ = {n, n, position, false};
      add(2, stamp, joints_cdr(&js));
    }
  }
  sqlite3_finalize(insert);
  const bool ok = exec(db, "COMMIT;");
  sqlite3_close(db);
  dds_delete(pp);
  return ok ? 0 : 1;
}
