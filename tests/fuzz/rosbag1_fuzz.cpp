// libFuzzer target for the replay's ROS 1 bag reader (replay::open_rosbag1, format 2.0): any bytes,
// as a .bag file replayed into examples/robodoc with the ros_robodoc example's mapping: the
// records' lengths and places, the index, the chunks (none, bzip2, LZ4), the connections and each
// message's ROS 1 serialisation. Beyond "no crash, no sanitizer report", it traps when a promise
// of fuzz_source.hpp is broken (a refusal says where and why; samples are of bound signals, in
// time order). Its seeds (the ros1 bags of tests/fuzz/seeds) were written by rosbag's own C++ writer:
// uncompressed, bz2 and lz4 chunks, a message of the wrong type, a short joint state.

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_source.hpp"
#include "safecass/replay/rosbag1_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string path = fuzz::write_input(data, size, ".bag");
  if (path.empty()) return 0;
  fuzz::drain(replay::open_rosbag1(path, SAFECASS_SOURCE_DIR "/examples/ros_robodoc/mapping.json"), path,
              fuzz::system_of("examples/robodoc/robodoc.json").monitor(), fuzz::Values::Any);
  return 0;
}
