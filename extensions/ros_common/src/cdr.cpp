#include "safecass/ros_common/cdr.hpp"

#include <cstring>

namespace safecass::ros_common {

namespace {

constexpr std::size_t kHeader = 4;

/// Reads members in order, as CDR (aligned, after the encapsulation header) or as ROS 1 packs them
/// (no header, no alignment, little endian); the first failure is kept and every later read fails.
class CdrReader {
public:
  enum class Encoding : std::uint8_t { Cdr, Ros1 };

  CdrReader(Encoding encoding, const std::uint8_t* data, std::size_t size, std::string& error)
      : encoding_(encoding), data_(data), size_(size), error_(error) {}

  bool header() {
    if (encoding_ == Encoding::Ros1) return true;
    if (size_ < kHeader) return fail(0, "fewer than the 4 bytes of the CDR encapsulation header");
    // 00 00: CDR big endian; 00 01: CDR little endian (plain CDR, not XCDR2 or parameter lists).
    if (data_[0] != 0 || data_[1] > 1)
      return fail(0, "encapsulation " + hex(data_[0]) + " " + hex(data_[1]) + " is not plain CDR (00 00 or 00 01)");
    little_ = data_[1] == 1;
    at_ = kHeader;
    return true;
  }
  /// std_msgs/Header: (ROS 1: uint32 seq,) the stamp's int32 sec and uint32 nanosec, string frame_id.
  bool message_header() {
    std::uint32_t seq = 0, nanosec = 0;
    std::int32_t sec = 0;
    return (encoding_ == Encoding::Cdr || u32(seq)) && i32(sec) && u32(nanosec) && skip_string();
  }
  bool u32(std::uint32_t& v) { return scalar(v); }
  bool i32(std::int32_t& v) { return scalar(v); }
  bool f64(double& v) { return scalar(v); }
  bool skip_string() {
    std::uint32_t n = 0;
    if (!u32(n)) return false;
    if (n > size_ - at_)
      return fail(at_ - 4, "a string of " + std::to_string(n) + " bytes runs past the end (" + std::to_string(size_) +
                               " bytes)");
    at_ += n;
    return true;
  }
  bool doubles(std::vector<double>& out) {
    std::uint32_t n = 0;
    if (!u32(n)) return false;
    if (n == 0) {
      out.clear();
      return true;
    }
    align(8);
    if (at_ > size_ || n > (size_ - at_) / 8) {
      return fail(at_, "a sequence of " + std::to_string(n) + " doubles runs past the end (" + std::to_string(size_) +
                           " bytes)");
    }
    out.resize(n);
    for (double& d : out) f64(d);
    return ok_;
  }
  bool skip_strings() {
    std::uint32_t n = 0;
    if (!u32(n)) return false;
    // Each string takes at least its 4-byte length: a count the buffer cannot hold is refused first.
    if (n > (size_ - at_) / 4) {
      return fail(at_ - 4, "a sequence of " + std::to_string(n) + " strings runs past the end (" +
                               std::to_string(size_) + " bytes)");
    }
    for (std::uint32_t i = 0; i < n && ok_; ++i) skip_string();
    return ok_;
  }

private:
  static std::string hex(std::uint8_t b) {
    static const char digits[] = "0123456789abcdef";
    return std::string{digits[b >> 4], digits[b & 15]};
  }
  void align(std::size_t n) {
    if (encoding_ == Encoding::Cdr) at_ = kHeader + (at_ - kHeader + n - 1) / n * n;
  }
  template <class T>
  bool scalar(T& v) {
    if (!ok_) return false;
    align(sizeof(T));
    if (at_ > size_ || size_ - at_ < sizeof(T)) {
      return fail(at_, "a " + std::to_string(sizeof(T)) + "-byte value runs past the end (" + std::to_string(size_) +
                           " bytes)");
    }
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, data_ + at_, sizeof(T));
    if (!little_) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    std::memcpy(&v, b, sizeof(T));  // this host is little endian (x86-64, ARM64)
    at_ += sizeof(T);
    return true;
  }
  bool fail(std::size_t where, const std::string& what) {
    if (ok_) error_ = "byte " + std::to_string(where) + ": " + what;
    ok_ = false;
    return false;
  }

  Encoding encoding_;
  const std::uint8_t* data_;
  std::size_t size_;
  std::string& error_;
  std::size_t at_ = 0;
  bool little_ = true;
  bool ok_ = true;
};

/// The numbers of a `type` message that `r` reads.
bool decode(CdrReader& r, MessageType type, DecodedMessage& out, std::string& error) {
  if (!r.header()) return false;
  out.numbers = MessageNumbers{};
  auto header = [&r] { return r.message_header(); };
  switch (type) {
    case MessageType::Float64: return r.f64(out.numbers.data);
    case MessageType::WrenchStamped: {
      if (!header()) return false;
      for (double& v : out.numbers.wrench) {
        if (!r.f64(v)) return false;
      }
      return true;
    }
    case MessageType::JointState: {
      if (!header() || !r.skip_strings() || !r.doubles(out.position) || !r.doubles(out.velocity) ||
          !r.doubles(out.effort))
        return false;
      out.numbers.position = out.position.data();
      out.numbers.position_size = out.position.size();
      out.numbers.velocity = out.velocity.data();
      out.numbers.velocity_size = out.velocity.size();
      out.numbers.effort = out.effort.data();
      out.numbers.effort_size = out.effort.size();
      return true;
    }
  }
  error = "unsupported message type";
  return false;
}

}  // namespace

bool decode_cdr(MessageType type, const std::uint8_t* data, std::size_t size, DecodedMessage& out, std::string& error) {
  CdrReader r(CdrReader::Encoding::Cdr, data, size, error);
  return decode(r, type, out, error);
}

bool decode_ros1(MessageType type, const std::uint8_t* data, std::size_t size, DecodedMessage& out,
                 std::string& error) {
  CdrReader r(CdrReader::Encoding::Ros1, data, size, error);
  return decode(r, type, out, error);
}

}  // namespace safecass::ros_common
