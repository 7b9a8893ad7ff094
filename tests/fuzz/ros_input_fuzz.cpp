// libFuzzer target for what the ROS extensions read from outside: the CDR of a message in a ROS 2
// bag (ros_common::decode_cdr) and the ROS mapping file (ros_common::load_mapping_from_text). The
// first byte picks the reader. Beyond "no crash, no sanitizer report", it traps when a promise is
// broken: a refused message says where ("byte N: ..."), a decoded JointState's arrays are what
// its numbers point at, and a mapping is present exactly when there is no error.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "safecass/ros_common/cdr.hpp"
#include "safecass/ros_common/mapping.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass::ros_common;
  if (size == 0) return 0;
  const std::uint8_t pick = data[0] % 4;
  ++data;
  --size;
  if (pick < 3) {
    const MessageType type = pick == 0   ? MessageType::Float64
                             : pick == 1 ? MessageType::WrenchStamped
                                         : MessageType::JointState;
    DecodedMessage m;
    std::string error;
    if (decode_cdr(type, data, size, m, error)) {
      if (m.numbers.position_size != m.position.size() || m.numbers.velocity_size != m.velocity.size() ||
          m.numbers.effort_size != m.effort.size())
        __builtin_trap();
    } else if (error.rfind("byte ", 0) != 0) {
      __builtin_trap();
    }
    return 0;
  }
  const MappingLoad load =
      load_mapping_from_text(std::string_view(reinterpret_cast<const char*>(data), size), "m.json");
  bool errors = false;
  for (const auto& d : load.diagnostics) errors = errors || d.severity == safecass::spec::Diagnostic::Severity::Error;
  if (errors == load.mapping.has_value()) __builtin_trap();
  return 0;
}
