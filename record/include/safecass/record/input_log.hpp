#pragma once
/// @file input_log.hpp
/// The input recording format (docs/record-format.md): the samples a system is fed and the
/// operator's actions (generate, broadcast, reset, injections), in the recording's own clock, as a
/// compact binary stream after a one-line text header. Written by InputRecorder
/// (input_recorder.hpp), read by InputLogReader and replayed by `safecass replay`.
///
/// The reader streams: it holds one buffer (256 KiB) whatever the file's size. A file that ends
/// inside a record (a killed recorder) is accepted up to its last whole record and says so
/// (truncated()); anything else malformed is an error naming the file, the record's index and
/// byte offset, and the reason.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/introspect/action.hpp"

namespace safecass {

/// The first line of a recording: "SAFECASS-INPUTS 1 period_ns=N start_ns=N clock=C system=S\n".
struct InputLogHeader {
  int version = 1;
  Time period{};                    ///< the tick period of the run that recorded it (0: unknown)
  Time start{};                     ///< the recording clock's time when recording started
  std::string clock = "simulated";  ///< "simulated" or "steady"/"ros": where the times come from
  std::string system;               ///< the recorded system's name (informative)
};

/// The kinds of an action record: every introspect::Action but PushSample (samples are sample
/// records). Values are the format's.
enum class InputActionKind : std::uint8_t {
  Generate = 1,       ///< text a = event, b = target address
  Broadcast = 2,      ///< a = event
  Reset = 3,          ///< a = target address, b = who, c = why
  InjectShallow = 4,  ///< a = filter, values
  InjectDeep = 5,     ///< a = signal, values
};

/// Record tags (one byte each); the layouts are in docs/record-format.md.
namespace input_log {
inline constexpr std::string_view kMagic = "SAFECASS-INPUTS";
inline constexpr std::uint8_t kSignal = 0x01;  ///< u16 id, u16 width, u16 name length, name
inline constexpr std::uint8_t kTime = 0x02;    ///< i64 ns: the time of the samples that follow
inline constexpr std::uint8_t kSample = 0x03;  ///< u16 id, width f64
inline constexpr std::uint8_t kAction = 0x04;  ///< u8 kind, i64 ns, u32 payload length, payload
inline constexpr std::uint8_t kLoss = 0x05;    ///< i64 ns, u16 id (0xffff: any), u64 samples lost
inline constexpr std::uint8_t kEnd = 0x06;     ///< i64 ns: the last tick of the run; a clean close
inline constexpr std::uint16_t kAnySignal = 0xffff;
inline constexpr std::size_t kMaxSignals = 0xfffe;

/// Appends the header line.
void put_header(std::string& out, const InputLogHeader& header);
void put_signal(std::string& out, std::uint16_t id, std::uint16_t width, std::string_view name);
void put_time(std::string& out, Time t);
/// A sample of signal `id` (`width` doubles), at the time of the last kTime record.
inline void put_sample(std::string& out, std::uint16_t id, const double* values, std::size_t width) {
  const std::size_t at = out.size();
  out.resize(at + 3 + 8 * width);
  char* p = out.data() + at;
  p[0] = static_cast<char>(kSample);
  p[1] = static_cast<char>(id & 0xff);
  p[2] = static_cast<char>(id >> 8);
  // Little-endian doubles (the format's byte order; the build checks the host's).
  std::memcpy(p + 3, values, 8 * width);
}
/// An action record at time `t`. A PushSample writes nothing: a sample is a sample record.
void put_action(std::string& out, const introspect::Action& action, Time t);
void put_loss(std::string& out, Time t, std::uint16_t id, std::uint64_t count);
void put_end(std::string& out, Time t);
}  // namespace input_log

/// Reads a recording, one item at a time, in constant memory.
class InputLogReader {
public:
  enum class Item : std::uint8_t {
    Sample,  ///< signal(), time(), values()
    Action,  ///< action(), at mark_time()
    Loss,    ///< the recorder lost samples here: mark_time(), loss_signal(), lost()
    End,     ///< the recorder closed cleanly; mark_time() is the run's last tick
    Eof,     ///< no more items (see truncated())
    Error,   ///< malformed: error() says where and why; no more items
  };

  /// Opens `path` and reads its header. Errors: Io (cannot read), Parse (not a recording, with
  /// the reason).
  [[nodiscard]] static Expected<std::unique_ptr<InputLogReader>> open(const std::string& path);
  ~InputLogReader();
  InputLogReader(const InputLogReader&) = delete;
  InputLogReader& operator=(const InputLogReader&) = delete;

  const InputLogHeader& header() const noexcept { return header_; }
  Item next();

  std::uint16_t signal() const noexcept { return signal_; }
  Time time() const noexcept { return time_; }
  const double* values() const noexcept { return values_; }
  std::size_t width() const noexcept { return widths_[signal_]; }
  const introspect::Action& action() const noexcept { return action_; }
  /// The time of the last Action, Loss or End item.
  Time mark_time() const noexcept { return mark_time_; }
  std::uint16_t loss_signal() const noexcept { return loss_signal_; }
  std::uint64_t lost() const noexcept { return lost_; }

  /// The signals declared so far: id → name and width.
  std::size_t signal_count() const noexcept { return names_.size(); }
  const std::string& signal_name(std::uint16_t id) const noexcept { return names_[id]; }
  std::size_t signal_width(std::uint16_t id) const noexcept { return widths_[id]; }

  /// "PATH: record N (byte B): reason" after Item::Error.
  const std::string& error() const noexcept { return error_; }
  /// The file ended inside a record (a killed recorder): everything before it was read.
  bool truncated() const noexcept { return truncated_; }
  /// Items read so far (records, every kind) and the byte offset of the next one.
  std::uint64_t record_index() const noexcept { return index_; }
  std::uint64_t offset() const noexcept { return consumed_ + pos_; }
  const std::string& path() const noexcept { return path_; }

private:
  InputLogReader() = default;
  /// Makes `n` bytes available at pos_; false at the end of the file.
  bool need(std::size_t n);
  Item fail_at(std::string reason);
  /// Reads the signal record at pos_ (its name is `len` bytes); false (after fail_at) when it is refused.
  bool declare_signal(std::uint16_t len);

  int fd_ = -1;
  std::string path_;
  InputLogHeader header_;
  std::vector<char> buffer_;
  std::size_t pos_ = 0;
  std::size_t end_ = 0;
  std::uint64_t consumed_ = 0;  ///< bytes of the file before buffer_[0]
  bool eof_ = false;
  bool truncated_ = false;
  bool failed_ = false;
  std::uint64_t index_ = 0;
  std::vector<std::string> names_;
  std::vector<std::uint16_t> widths_;
  std::vector<Time> last_time_;  ///< per signal: its samples' time never goes back
  std::uint16_t signal_ = 0;
  Time time_{};
  Time mark_time_{};
  bool have_time_ = false;
  const double* values_ = nullptr;
  std::vector<double> aligned_;
  introspect::Action action_;
  std::uint16_t loss_signal_ = 0;
  std::uint64_t lost_ = 0;
  std::string error_;
};

}  // namespace safecass
