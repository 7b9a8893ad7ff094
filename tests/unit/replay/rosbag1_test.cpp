// The replay's ROS 1 bag reader (tools/replay/src/rosbag1_source.cpp) on bags written by rosbag's
// own C++ writer (the ros1 bags of tests/fuzz/seeds): every compression replays the same samples, and a
// damaged bag is refused with where and why, before anything it states is trusted (the fuzz
// target rosbag1 found the first two with librosbag, which the reader replaced).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "safecass/filters/registry.hpp"
#include "safecass/replay/rosbag1_source.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::replay {
namespace {

using ::testing::HasSubstr;

const std::string kSeeds = std::string(SAFECASS_SOURCE_DIR) + "/tests/fuzz/seeds/";
const std::string kMapping = std::string(SAFECASS_SOURCE_DIR) + "/examples/ros_robodoc/mapping.json";

std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::uint32_t u32_at(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

void put_u32(std::string& b, std::size_t at, std::uint32_t v) { std::memcpy(b.data() + at, &v, 4); }

/// Where a record of a bag is: its header length's place, op, header fields' values and data.
struct Record {
  std::size_t at = 0;
  std::uint8_t op = 0;
  std::map<std::string, std::size_t> value_at;  // a field's value, by name
  std::size_t data_at = 0;
};

/// The records of `bag`, in file order (a well-formed bag: the test's own walk, to know where to damage it).
std::vector<Record> records(const std::string& bag) {
  std::vector<Record> out;
  for (std::size_t at = 13; at < bag.size();) {
    Record r;
    r.at = at;
    const std::uint32_t header_len = u32_at(bag, at);
    for (std::size_t pos = at + 4; pos < at + 4 + header_len;) {
      const std::uint32_t n = u32_at(bag, pos);
      const std::string field = bag.substr(pos + 4, n);
      const std::size_t eq = field.find('=');
      r.value_at[field.substr(0, eq)] = pos + 4 + eq + 1;
      if (field.substr(0, eq) == "op") r.op = static_cast<std::uint8_t>(field[eq + 1]);
      pos += 4 + n;
    }
    r.data_at = at + 8 + header_len;
    out.push_back(r);
    at = r.data_at + u32_at(bag, at + 4 + header_len);
  }
  return out;
}

Record first(const std::vector<Record>& rs, std::uint8_t op) {
  for (const Record& r : rs) {
    if (r.op == op) return r;
  }
  throw std::runtime_error("no record of that op");
}

std::string write_bag(const std::string& name, const std::string& bytes) {
  const std::string path = ::testing::TempDir() + "safecass_rosbag1_" + name + ".bag";
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// What replaying the bag at `path` yields: each sample as "time signal values", then the end or
/// "error: " and the error (which says where).
std::vector<std::string> replay(const std::string& path) {
  auto instance =
      spec::open_instance(std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json", builtin_filters());
  EXPECT_TRUE(instance.has_value());
  auto source = open_rosbag1(path, kMapping);
  if (!source) return {"refused: " + source.error().message};
  InputSource& s = **source;
  if (auto bound = s.bind((*instance)->monitor()); !bound) return {"unbound: " + bound.error().message};
  std::vector<std::string> out;
  for (;;) {
    const InputItem item = s.next();
    if (item.kind == InputItem::Kind::End) return out;
    if (item.kind == InputItem::Kind::Error) {
      out.push_back("error: " + s.error());
      return out;
    }
    std::string line = std::to_string(item.time.count()) + " " + item.signal->name();
    for (std::size_t k = 0; k < item.signal->size(); ++k) line += " " + std::to_string(item.values[k]);
    out.push_back(line);
  }
}

TEST(Rosbag1, EveryCompressionOfTheSameBagReplaysTheSameSamplesInTimeOrder) {
  const std::vector<std::string> plain = replay(kSeeds + "ros1_plain.bag");
  ASSERT_EQ(plain.size(), 36u);  // 12 wrench messages, each feeding JR3.Fx, Fy and Fz
  EXPECT_EQ(plain.front(), "0 JR3.Fx 0.000000");
  EXPECT_EQ(plain.back(), "22000000 JR3.Fz 60.000000");
  EXPECT_EQ(replay(kSeeds + "ros1_bz2.bag"), plain);
  EXPECT_EQ(replay(kSeeds + "ros1_lz4.bag"), plain);
}

TEST(Rosbag1, ARecordHeaderLongerThanTheFileIsRefusedBeforeAnythingIsAllocated) {
  // Found by the fuzz target with librosbag, which allocated the 4 GiB it was told before reading.
  std::string bag = read_bytes(kSeeds + "ros1_plain.bag");
  const Record connection = first(records(bag), 0x07);
  put_u32(bag, connection.at, 0xFFFFFF00u);
  const std::string path = write_bag("long_header", bag);
  EXPECT_EQ(replay(path), std::vector<std::string>{"refused: " + path + ": byte " + std::to_string(connection.at) +
                                                   ": a record header of 4294967040 bytes runs past the end of the "
                                                   "file (the bag is damaged or truncated)"});
}

TEST(Rosbag1, AnIndexEntryPointingOutsideItsChunkIsRefusedWithItsMessage) {
  // Found by the fuzz target with librosbag, which read the message at any offset it was told (SEGV).
  std::string bag = read_bytes(kSeeds + "ros1_plain.bag");
  const std::vector<Record> rs = records(bag);
  const Record index = first(rs, 0x04);
  put_u32(bag, index.data_at + 8, 0x7FFFFFF0u);  // the first entry's offset in its chunk
  const std::string path = write_bag("index_outside", bag);
  const std::vector<std::string> out = replay(path);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back(), "error: " + path + ": message 1 (/jr3/wrench): the chunk at byte " +
                            std::to_string(first(rs, 0x05).at) +
                            ", offset 2147483632: no message record there (the bag is damaged)");
}

TEST(Rosbag1, AChunkThatDecompressesToOtherThanItDeclaresIsRefused) {
  for (const char* compression : {"bz2", "lz4"}) {
    std::string bag = read_bytes(kSeeds + "ros1_" + compression + ".bag");
    const Record chunk = first(records(bag), 0x05);
    const std::uint32_t declared = u32_at(bag, chunk.value_at.at("size"));
    put_u32(bag, chunk.value_at.at("size"), declared + 100);
    const std::string path = write_bag(std::string("chunk_size_") + compression, bag);
    const std::vector<std::string> out = replay(path);
    ASSERT_EQ(out.size(), 1u) << compression;
    EXPECT_THAT(out.back(),
                HasSubstr("does not decompress (" + std::string(compression) + "): " + std::to_string(declared) +
                          " bytes, not its declared " + std::to_string(declared + 100) + " (the bag is damaged)"));
  }
}

TEST(Rosbag1, ABagWithoutAnIndexIsRefusedWithTheCommandThatWritesOne) {
  std::string bag = read_bytes(kSeeds + "ros1_plain.bag");
  const Record header = first(records(bag), 0x03);
  put_u32(bag, header.value_at.at("index_pos"), 0);
  put_u32(bag, header.value_at.at("index_pos") + 4, 0);
  const std::string path = write_bag("unindexed", bag);
  EXPECT_EQ(replay(path), std::vector<std::string>{"refused: " + path +
                                                   ": the bag has no index (a recording that was cut short?): "
                                                   "`rosbag reindex " +
                                                   path + "` writes it"});
}

TEST(Rosbag1, AMessageOfTheWrongTypeOnAMappedTopicIsRefusedWithItsIndex) {
  const std::vector<std::string> out = replay(kSeeds + "ros1_wrong_type.bag");
  ASSERT_FALSE(out.empty());
  EXPECT_THAT(out.back(),
              HasSubstr("message 7 (/jr3/wrench): cannot be read as geometry_msgs/WrenchStamped: byte 8: "));
}

}  // namespace
}  // namespace safecass::replay
