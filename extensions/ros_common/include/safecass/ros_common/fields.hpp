#pragma once
/// @file fields.hpp
/// Which numbers of a ROS message feed a signal (a *field path*), and how GCM states map to
/// diagnostic levels and back. Plain C++17, no ROS header: the paths are checked when the mapping
/// is loaded, long before a message arrives.
///
/// Field paths, by message type (`[i]` picks one element of a vector or array):
///
/// | message type                  | path                                   | doubles |
/// |-------------------------------|----------------------------------------|---------|
/// | `std_msgs/Float64`            | `data`                                 | 1       |
/// | `geometry_msgs/WrenchStamped` | `wrench` (force x y z, torque x y z)   | 6       |
/// |                               | `wrench.force`, `wrench.torque`        | 3       |
/// |                               | `wrench.force.x` … `wrench.torque.z`, `wrench.force[2]` | 1 |
/// | `sensor_msgs/JointState`      | `position`, `velocity`, `effort`       | the signal's size |
/// |                               | `position[2]`, `velocity[0]`, …        | 1       |

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"

namespace safecass::ros_common {

/// The message types the bridge can read numbers from.
enum class MessageType : std::uint8_t { Float64, WrenchStamped, JointState };

/// "std_msgs/Float64", "geometry_msgs/WrenchStamped", "sensor_msgs/JointState".
std::string_view to_string(MessageType type) noexcept;
/// Parses a ROS message type name, as ROS 1 writes it ("std_msgs/Float64") or ROS 2
/// ("std_msgs/msg/Float64"). Errors: NotFound (names the supported types).
[[nodiscard]] Expected<MessageType> parse_message_type(std::string_view name);

/// A parsed field path: which part of a message, and which element of it.
struct FieldPath {
  enum class Field : std::uint8_t { Data, Wrench, Force, Torque, Position, Velocity, Effort };
  MessageType type = MessageType::Float64;
  Field field = Field::Data;
  /// -1: the whole field; otherwise one element (x, y, z are 0, 1, 2).
  int index = -1;
  std::string text;  ///< the path as written

  /// Doubles the path yields; 0 for a whole JointState array (its length is the signal's size).
  std::size_t width() const noexcept;
};

/// Parses `path` for messages of `type`. Errors: InvalidArgument, with a message that names the
/// path, the part that is wrong and what would be accepted.
[[nodiscard]] Expected<FieldPath> parse_field_path(MessageType type, std::string_view path);

/// The numbers of one message as field paths see them, whatever the framework's message type:
/// each framework fills it from its own message (no copy of the arrays) and extract() does the rest.
struct MessageNumbers {
  double data = 0.0;                      ///< std_msgs/Float64
  double wrench[6] = {0, 0, 0, 0, 0, 0};  ///< force x y z, torque x y z
  const double* position = nullptr;       ///< sensor_msgs/JointState arrays
  std::size_t position_size = 0;
  const double* velocity = nullptr;
  std::size_t velocity_size = 0;
  const double* effort = nullptr;
  std::size_t effort_size = 0;
};

/// Writes `width` doubles of `msg` at `path` into `out`. False, with `error` set, when the message
/// does not have them (a JointState array shorter than needed). Never throws; allocates only to
/// write the error.
bool extract(const FieldPath& path, const MessageNumbers& msg, double* out, std::size_t width, std::string& error);

/// The four levels of `diagnostic_msgs/DiagnosticStatus`, with the same byte values.
enum class DiagnosticLevel : std::uint8_t { Ok = 0, Warn = 1, Error = 2, Stale = 3 };

/// Normal → OK, Warning → WARN, Error → ERROR.
constexpr DiagnosticLevel to_diagnostic_level(State state) noexcept {
  switch (state) {
    case State::Normal: return DiagnosticLevel::Ok;
    case State::Warning: return DiagnosticLevel::Warn;
    case State::Error: break;
  }
  return DiagnosticLevel::Error;
}

/// The level of a received status byte; nullopt for a byte that is not a level (bad input).
constexpr std::optional<DiagnosticLevel> diagnostic_level_from_byte(int byte) noexcept {
  if (byte < 0 || byte > 3) return std::nullopt;
  return static_cast<DiagnosticLevel>(byte);
}

/// "OK", "WARN", "ERROR", "STALE".
std::string_view to_string(DiagnosticLevel level) noexcept;

}  // namespace safecass::ros_common
