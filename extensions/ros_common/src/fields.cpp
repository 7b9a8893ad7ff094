#include "safecass/ros_common/fields.hpp"

#include <cctype>
#include <vector>

namespace safecass::ros_common {

std::string_view to_string(MessageType type) noexcept {
  switch (type) {
    case MessageType::Float64: return "std_msgs/Float64";
    case MessageType::WrenchStamped: return "geometry_msgs/WrenchStamped";
    case MessageType::JointState: return "sensor_msgs/JointState";
  }
  return "?";
}

[[nodiscard]] Expected<MessageType> parse_message_type(std::string_view name) {
  // ROS 2 names the same message "pkg/msg/Type".
  std::string plain(name);
  if (const std::size_t at = plain.find("/msg/"); at != std::string::npos) plain.erase(at, 4);
  for (MessageType t : {MessageType::Float64, MessageType::WrenchStamped, MessageType::JointState}) {
    if (plain == to_string(t)) return t;
  }
  return fail(ErrorCode::NotFound, "unsupported message type '" + std::string(name) +
                                       "' (supported: std_msgs/Float64, geometry_msgs/WrenchStamped, "
                                       "sensor_msgs/JointState)");
}

std::size_t FieldPath::width() const noexcept {
  if (index >= 0) return 1;
  switch (field) {
    case Field::Data: return 1;
    case Field::Wrench: return 6;
    case Field::Force:
    case Field::Torque: return 3;
    case Field::Position:
    case Field::Velocity:
    case Field::Effort: break;
  }
  return 0;
}

bool extract(const FieldPath& path, const MessageNumbers& msg, double* out, std::size_t width, std::string& error) {
  switch (path.type) {
    case MessageType::Float64:
      if (width != 1) break;
      out[0] = msg.data;
      return true;
    case MessageType::WrenchStamped: {
      if (width != path.width()) break;
      std::size_t first = path.field == FieldPath::Field::Torque ? 3 : 0;
      if (path.index >= 0) first += static_cast<std::size_t>(path.index);
      for (std::size_t i = 0; i < width; ++i) out[i] = msg.wrench[first + i];
      return true;
    }
    case MessageType::JointState: {
      const double* array = msg.position;
      std::size_t size = msg.position_size;
      const char* name = "position";
      if (path.field == FieldPath::Field::Velocity) {
        array = msg.velocity;
        size = msg.velocity_size;
        name = "velocity";
      } else if (path.field == FieldPath::Field::Effort) {
        array = msg.effort;
        size = msg.effort_size;
        name = "effort";
      }
      if (path.index >= 0) {
        if (width != 1 || static_cast<std::size_t>(path.index) >= size) {
          error =
              std::string(name) + " has " + std::to_string(size) + " elements, no [" + std::to_string(path.index) + "]";
          return false;
        }
        out[0] = array[static_cast<std::size_t>(path.index)];
        return true;
      }
      if (size != width) {
        error = std::string(name) + " has " + std::to_string(size) + " elements, the signal expects " +
                std::to_string(width);
        return false;
      }
      for (std::size_t i = 0; i < width; ++i) out[i] = array[i];
      return true;
    }
  }
  error = "path '" + path.text + "' does not read " + std::to_string(width) + " doubles of a " +
          std::string(to_string(path.type));
  return false;
}

std::string_view to_string(DiagnosticLevel level) noexcept {
  switch (level) {
    case DiagnosticLevel::Ok: return "OK";
    case DiagnosticLevel::Warn: return "WARN";
    case DiagnosticLevel::Error: return "ERROR";
    case DiagnosticLevel::Stale: break;
  }
  return "STALE";
}

namespace {

/// Splits "name[3]" into "name" and 3; "name" gives -1. False when the brackets are malformed.
bool split_index(std::string_view part, std::string_view& name, int& index) {
  index = -1;
  name = part;
  const std::size_t open = part.find('[');
  if (open == std::string_view::npos) return part.find(']') == std::string_view::npos;
  if (part.back() != ']' || open + 2 > part.size() - 1) return false;
  name = part.substr(0, open);
  const std::string_view digits = part.substr(open + 1, part.size() - open - 2);
  if (digits.empty() || digits.size() > 6) return false;
  long value = 0;
  for (char c : digits) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    value = value * 10 + (c - '0');
  }
  index = static_cast<int>(value);
  return true;
}

}  // namespace

[[nodiscard]] Expected<FieldPath> parse_field_path(MessageType type, std::string_view path) {
  const std::string where = "field path '" + std::string(path) + "' of " + std::string(to_string(type));
  auto bad = [&](const std::string& why) { return fail(ErrorCode::InvalidArgument, where + ": " + why); };
  FieldPath out;
  out.type = type;
  out.text = std::string(path);

  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = path.find('.', start);
    parts.push_back(path.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  for (std::string_view p : parts) {
    if (p.empty()) return bad("empty part (expected names separated by single dots)");
  }

  switch (type) {
    case MessageType::Float64:
      if (parts.size() != 1 || parts[0] != "data") return bad("expected 'data'");
      out.field = FieldPath::Field::Data;
      return out;

    case MessageType::WrenchStamped: {
      std::string_view name;
      int index = -1;
      if (parts[0] != "wrench") {
        return bad("unknown field '" + std::string(parts[0]) +
                   "' (expected wrench, wrench.force, wrench.torque, "
                   "wrench.force.x ...)");
      }
      if (parts.size() == 1) {
        out.field = FieldPath::Field::Wrench;
        return out;
      }
      if (parts.size() > 3) return bad("too deep (at most wrench.force.x)");
      if (!split_index(parts[1], name, index)) return bad("malformed index in '" + std::string(parts[1]) + "'");
      if (name == "force") {
        out.field = FieldPath::Field::Force;
      } else if (name == "torque") {
        out.field = FieldPath::Field::Torque;
      } else {
        return bad("unknown field '" + std::string(name) + "' of wrench (expected force, torque)");
      }
      if (index > 2) return bad("index " + std::to_string(index) + " out of range (a vector has 3 elements)");
      out.index = index;
      if (parts.size() == 3) {
        if (index >= 0) return bad("an element has no field '" + std::string(parts[2]) + "'");
        if (parts[2] == "x") {
          out.index = 0;
        } else if (parts[2] == "y") {
          out.index = 1;
        } else if (parts[2] == "z") {
          out.index = 2;
        } else {
          return bad("unknown field '" + std::string(parts[2]) + "' of a vector (expected x, y, z)");
        }
      }
      return out;
    }

    case MessageType::JointState: {
      std::string_view name;
      int index = -1;
      if (parts.size() != 1) return bad("JointState fields have no members (expected position, velocity, effort)");
      if (!split_index(parts[0], name, index)) return bad("malformed index in '" + std::string(parts[0]) + "'");
      if (name == "position") {
        out.field = FieldPath::Field::Position;
      } else if (name == "velocity") {
        out.field = FieldPath::Field::Velocity;
      } else if (name == "effort") {
        out.field = FieldPath::Field::Effort;
      } else if (name == "name" || name == "header") {
        return bad("field '" + std::string(name) + "' is not numeric (expected position, velocity, effort)");
      } else {
        return bad("unknown field '" + std::string(name) + "' (expected position, velocity, effort)");
      }
      out.index = index;
      return out;
    }
  }
  return bad("unsupported message type");
}

}  // namespace safecass::ros_common
