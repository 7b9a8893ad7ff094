// libFuzzer target for the replay's ROS 2 bag reader (replay::open_rosbag2, rosbag2's sqlite3
// store): any bytes, as a .db3 file replayed into examples/robodoc with the dds_robodoc example's
// mapping. SQLite reads the file; the reader's own code is what follows: the schema it needs, each
// row's topic, type, serialisation format, time stamp and CDR bytes. Beyond "no crash, no sanitizer
// report", it traps when a promise of fuzz_source.hpp is broken (a refusal says where and why;
// samples are of bound signals, in time order).
//
// SAFECASS_FUZZ_WRITE_SEEDS=DIR writes the seed corpus (small bags of 512-byte pages: a good one, a
// topic of the wrong type, a cut CDR message, a message serialised otherwise, times out of order)
// into DIR and exits.

#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz_source.hpp"
#include "safecass/replay/rosbag2_source.hpp"

namespace {

/// The CDR (little endian) of a geometry_msgs/msg/WrenchStamped whose force is (0, 0, fz).
std::vector<std::uint8_t> wrench_cdr(std::int32_t sec, double fz) {
  std::vector<std::uint8_t> b = {0, 1, 0, 0};
  const auto put = [&b](const void* v, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(v);
    b.insert(b.end(), p, p + n);
  };
  const std::uint32_t nanosec = 0, frame = 4;
  put(&sec, 4);
  put(&nanosec, 4);
  put(&frame, 4);
  put("jr3", 4);
  while ((b.size() - 4) % 8 != 0) b.push_back(0);
  const double wrench[6] = {0.0, 0.0, fz, 0.0, 0.0, 0.0};
  put(wrench, sizeof wrench);
  return b;
}

/// A bag of `variant` in `file`: ten messages on /jr3/wrench, the force rising from 5 to 50 N.
void write_seed(const std::string& file, const std::string& variant) {
  std::filesystem::remove(file);
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) std::abort();
  const std::string type = variant == "wrong_type" ? "std_msgs/msg/Float64" : "geometry_msgs/msg/WrenchStamped";
  const std::string format = variant == "json" ? "json" : "cdr";
  const std::string schema =
      "PRAGMA page_size=512;"
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
      "data BLOB NOT NULL);"
      "INSERT INTO topics VALUES (1, '/jr3/wrench', '" +
      type + "', '" + format + "', '');INSERT INTO topics VALUES (2, '/other', 'std_msgs/msg/Float64', 'cdr', '');";
  if (sqlite3_exec(db, schema.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) std::abort();
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &insert, nullptr);
  for (int i = 0; i < 10; ++i) {
    std::vector<std::uint8_t> data = wrench_cdr(1700000000 + i, 5.0 * (i + 1));
    if (variant == "bad_cdr" && i == 5) data.resize(20);
    const std::int64_t stamp = 1700000000000000000LL + (variant == "out_of_order" ? 9 - i : i) * 2000000LL;
    sqlite3_bind_int(insert, 1, i == 7 ? 2 : 1);
    sqlite3_bind_int64(insert, 2, stamp);
    sqlite3_bind_blob(insert, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    sqlite3_step(insert);
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
  sqlite3_close(db);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("SAFECASS_FUZZ_WRITE_SEEDS")) {
    for (const char* variant : {"good", "wrong_type", "bad_cdr", "json", "out_of_order"})
      write_seed(std::string(dir) + "/rosbag2_" + variant + ".db3", variant);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string path = fuzz::write_input(data, size, ".db3");
  if (path.empty()) return 0;
  fuzz::drain(replay::open_rosbag2(path, SAFECASS_SOURCE_DIR "/examples/dds_robodoc/mapping.json"), path,
              fuzz::system_of("examples/robodoc/robodoc.json").monitor(), fuzz::Values::Any);
  return 0;
}
