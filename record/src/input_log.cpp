#include "safecass/record/input_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <optional>
#include <type_traits>
#include <variant>

namespace safecass {

static_assert(std::endian::native == std::endian::little,
              "the input recording format is little-endian; a big-endian host needs byte swaps here");

namespace input_log {

namespace {
template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}
void put_text(std::string& out, std::string_view s) {
  put<std::uint16_t>(out, static_cast<std::uint16_t>(s.size() > 0xffff ? 0xffff : s.size()));
  out.append(s.substr(0, 0xffff));
}
/// A header value: no spaces or newlines (they separate the fields).
std::string word(std::string_view s) {
  std::string out(s.empty() ? "-" : s);
  for (char& c : out) {
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') c = '_';
  }
  return out;
}
}  // namespace

void put_header(std::string& out, const InputLogHeader& h) {
  out += std::string(kMagic) + " " + std::to_string(h.version) + " period_ns=" + std::to_string(h.period.count()) +
         " start_ns=" + std::to_string(h.start.count()) + " clock=" + word(h.clock) + " system=" + word(h.system) +
         "\n";
}

void put_signal(std::string& out, std::uint16_t id, std::uint16_t width, std::string_view name) {
  out += static_cast<char>(kSignal);
  put(out, id);
  put(out, width);
  put_text(out, name);
}

void put_time(std::string& out, Time t) {
  out += static_cast<char>(kTime);
  put<std::int64_t>(out, t.count());
}

void put_action(std::string& out, const introspect::Action& action, Time t) {
  // The format's layout: kind, then three texts (a, b, c) and the values (docs/record-format.md).
  InputActionKind kind = InputActionKind::Generate;
  std::string_view a, b, c;
  const std::vector<std::vector<double>>* values = nullptr;
  const bool written = std::visit(
      [&](const auto& x) {
        using X = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<X, introspect::PushSample>) {
          return false;
        } else if constexpr (std::is_same_v<X, introspect::GenerateEvent>) {
          kind = InputActionKind::Generate;
          a = x.event;
          b = x.target;
        } else if constexpr (std::is_same_v<X, introspect::BroadcastEvent>) {
          kind = InputActionKind::Broadcast;
          a = x.event;
        } else if constexpr (std::is_same_v<X, introspect::ResetState>) {
          kind = InputActionKind::Reset;
          a = x.target;
          b = x.who;
          c = x.why;
        } else if constexpr (std::is_same_v<X, introspect::InjectShallow>) {
          kind = InputActionKind::InjectShallow;
          a = x.filter;
          values = &x.samples;
        } else {
          static_assert(std::is_same_v<X, introspect::InjectDeep>, "an Action alternative without its record");
          kind = InputActionKind::InjectDeep;
          a = x.signal;
          values = &x.samples;
        }
        return true;
      },
      action);
  if (!written) return;
  std::string payload;
  put_text(payload, a);
  put_text(payload, b);
  put_text(payload, c);
  put<std::uint32_t>(payload, values == nullptr ? 0u : static_cast<std::uint32_t>(values->size()));
  if (values != nullptr) {
    for (const auto& v : *values) {
      put<std::uint16_t>(payload, static_cast<std::uint16_t>(v.size()));
      for (double x : v) put(payload, x);
    }
  }
  out += static_cast<char>(kAction);
  out += static_cast<char>(kind);
  put<std::int64_t>(out, t.count());
  put<std::uint32_t>(out, static_cast<std::uint32_t>(payload.size()));
  out += payload;
}

void put_loss(std::string& out, Time t, std::uint16_t id, std::uint64_t count) {
  out += static_cast<char>(kLoss);
  put<std::int64_t>(out, t.count());
  put(out, id);
  put(out, count);
}

void put_end(std::string& out, Time t) {
  out += static_cast<char>(kEnd);
  put<std::int64_t>(out, t.count());
}

}  // namespace input_log

namespace {
constexpr std::size_t kBufferBytes = 256 * 1024;
constexpr std::size_t kMaxHeader = 4096;
constexpr std::uint32_t kMaxPayload = 16u << 20;

template <class T>
T get(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

bool parse_i64(std::string_view s, std::int64_t& out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
}  // namespace

Expected<std::unique_ptr<InputLogReader>> InputLogReader::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::Io, "cannot read recording '" + path + "': " + std::strerror(errno));
  std::unique_ptr<InputLogReader> r(new InputLogReader());
  r->fd_ = fd;
  r->path_ = path;
  r->buffer_.resize(kBufferBytes);
  // The header: one text line.
  std::size_t nl = 0;
  for (;;) {
    const char* b = r->buffer_.data() + r->pos_;
    const void* found = std::memchr(b, '\n', r->end_ - r->pos_);
    if (found != nullptr) {
      nl = static_cast<std::size_t>(static_cast<const char*>(found) - r->buffer_.data());
      break;
    }
    if (r->end_ >= kMaxHeader || !r->need(r->end_ - r->pos_ + 1)) {
      return fail(ErrorCode::Parse, path + ":1: not a SAFECASS input recording (no header line \"" +
                                        std::string(input_log::kMagic) + " 1 ...\")");
    }
  }
  const std::string line(r->buffer_.data(), nl);
  r->pos_ = nl + 1;
  std::vector<std::string_view> fields;
  for (std::size_t at = 0; at < line.size();) {
    const std::size_t sp = line.find(' ', at);
    const std::size_t stop = sp == std::string::npos ? line.size() : sp;
    if (stop > at) fields.emplace_back(line.data() + at, stop - at);
    at = stop + 1;
  }
  if (fields.size() < 2 || fields[0] != input_log::kMagic) {
    return fail(ErrorCode::Parse, path + ":1: not a SAFECASS input recording (the first line must start with \"" +
                                      std::string(input_log::kMagic) + " 1\")");
  }
  if (fields[1] != "1") {
    return fail(ErrorCode::Parse, path + ":1: recording format version " + std::string(fields[1]) +
                                      " is not supported (this safecass reads version 1)");
  }
  for (std::size_t i = 2; i < fields.size(); ++i) {
    const std::size_t eq = fields[i].find('=');
    if (eq == std::string_view::npos) continue;  // tolerated: later versions may add flags
    const std::string_view key = fields[i].substr(0, eq);
    const std::string_view value = fields[i].substr(eq + 1);
    std::int64_t n = 0;
    if (key == "period_ns" || key == "start_ns") {
      if (!parse_i64(value, n) || (key == "period_ns" && n < 0)) {
        return fail(ErrorCode::Parse,
                    path + ":1: header field " + std::string(key) + " is not a number: '" + std::string(value) + "'");
      }
      (key == "period_ns" ? r->header_.period : r->header_.start) = Time{n};
    } else if (key == "clock") {
      r->header_.clock = std::string(value);
    } else if (key == "system") {
      r->header_.system = value == "-" ? std::string() : std::string(value);
    }
  }
  return r;
}

InputLogReader::~InputLogReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool InputLogReader::need(std::size_t n) {
  if (end_ - pos_ >= n) return true;
  if (eof_) return false;
  // Keep the unread tail, refill after it.
  if (pos_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + pos_, end_ - pos_);
    consumed_ += pos_;
    end_ -= pos_;
    pos_ = 0;
  }
  if (n > buffer_.size()) buffer_.resize(n);
  while (end_ - pos_ < n) {
    const ssize_t got = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
    if (got < 0) {
      if (errno == EINTR) continue;
      eof_ = true;
      error_ = path_ + ": read error: " + std::strerror(errno);
      return false;
    }
    if (got == 0) {
      eof_ = true;
      return false;
    }
    end_ += static_cast<std::size_t>(got);
  }
  return true;
}

InputLogReader::Item InputLogReader::fail_at(std::string reason) {
  failed_ = true;
  error_ = path_ + ": record " + std::to_string(index_ + 1) + " (byte " + std::to_string(offset()) + "): " + reason;
  return Item::Error;
}

namespace {

/// The action of an action record's payload (`size` bytes at `p`); nullopt when it is malformed.
std::optional<introspect::Action> decode_action(InputActionKind kind, const char* p, std::size_t size) {
  const char* stop = p + size;
  const auto text = [&](std::string& out) {
    if (stop - p < 2) return false;
    const auto n = get<std::uint16_t>(p);
    p += 2;
    if (stop - p < n) return false;
    out.assign(p, n);
    p += n;
    return true;
  };
  std::string a, b, c;
  if (!text(a) || !text(b) || !text(c) || stop - p < 4) return std::nullopt;
  const auto count = get<std::uint32_t>(p);
  p += 4;
  std::vector<std::vector<double>> values;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (stop - p < 2) return std::nullopt;
    const auto w = get<std::uint16_t>(p);
    p += 2;
    if (stop - p < 8 * static_cast<std::ptrdiff_t>(w)) return std::nullopt;
    std::vector<double> v(w);
    if (w != 0) std::memcpy(v.data(), p, std::size_t{8} * w);  // an empty vector's data() may be null
    p += std::size_t{8} * w;
    values.push_back(std::move(v));
  }
  if (p != stop) return std::nullopt;
  switch (kind) {
    case InputActionKind::Generate: return introspect::GenerateEvent{std::move(a), std::move(b)};
    case InputActionKind::Broadcast: return introspect::BroadcastEvent{std::move(a)};
    case InputActionKind::Reset: return introspect::ResetState{std::move(a), std::move(b), std::move(c)};
    case InputActionKind::InjectShallow: return introspect::InjectShallow{std::move(a), std::move(values)};
    case InputActionKind::InjectDeep: return introspect::InjectDeep{std::move(a), std::move(values)};
  }
  return std::nullopt;
}

}  // namespace

bool InputLogReader::declare_signal(std::uint16_t len) {
  const auto refuse = [this](std::string reason) {
    fail_at(std::move(reason));
    return false;
  };
  const auto id = get<std::uint16_t>(buffer_.data() + pos_ + 1);
  const auto width = get<std::uint16_t>(buffer_.data() + pos_ + 3);
  std::string name(buffer_.data() + pos_ + 7, len);
  if (width == 0) return refuse("signal " + name + " is declared with width 0");
  if (id > input_log::kMaxSignals) return refuse("signal id " + std::to_string(id) + " is out of range");
  if (id < names_.size()) {
    if (names_[id] != name || widths_[id] != width) {
      return refuse("signal id " + std::to_string(id) + " is declared again as " + name + " (it was " + names_[id] +
                    ")");
    }
    return true;
  }
  if (id != names_.size())
    return refuse("signal id " + std::to_string(id) + " is declared before id " + std::to_string(names_.size()));
  names_.push_back(std::move(name));
  widths_.push_back(width);
  last_time_.push_back(Time::min());
  if (aligned_.size() < width) aligned_.resize(width);
  return true;
}

InputLogReader::Item InputLogReader::next() {
  if (failed_) return Item::Error;
  for (;;) {
    if (!need(1)) {
      if (!error_.empty()) return fail_at(error_);
      return Item::Eof;
    }
    const std::uint8_t tag = static_cast<std::uint8_t>(buffer_[pos_]);
    // The record's whole size is known from its first bytes; a file ending before it is torn.
    const auto whole = [this](std::size_t n) {
      if (need(n)) return true;
      if (error_.empty()) truncated_ = true;
      return false;
    };
    switch (tag) {
      case input_log::kSample: {
        if (!whole(3)) return error_.empty() ? Item::Eof : fail_at(error_);
        const auto id = get<std::uint16_t>(buffer_.data() + pos_ + 1);
        if (id >= widths_.size())
          return fail_at("sample of signal id " + std::to_string(id) + ", which was never declared");
        const std::size_t width = widths_[id];
        if (!whole(3 + 8 * width)) return error_.empty() ? Item::Eof : fail_at(error_);
        if (!have_time_) return fail_at("sample before the first time record");
        if (time_ < last_time_[id]) {
          return fail_at("time goes back for signal " + names_[id] + ": " + std::to_string(to_seconds(time_)) +
                         " s after " + std::to_string(to_seconds(last_time_[id])) + " s");
        }
        last_time_[id] = time_;
        std::memcpy(aligned_.data(), buffer_.data() + pos_ + 3, 8 * width);
        values_ = aligned_.data();
        signal_ = id;
        pos_ += 3 + 8 * width;
        ++index_;
        return Item::Sample;
      }
      case input_log::kTime: {
        if (!whole(9)) return error_.empty() ? Item::Eof : fail_at(error_);
        time_ = Time{get<std::int64_t>(buffer_.data() + pos_ + 1)};
        have_time_ = true;
        pos_ += 9;
        ++index_;
        continue;
      }
      case input_log::kSignal: {
        if (!whole(7)) return error_.empty() ? Item::Eof : fail_at(error_);
        const auto len = get<std::uint16_t>(buffer_.data() + pos_ + 5);
        if (!whole(7u + len)) return error_.empty() ? Item::Eof : fail_at(error_);
        if (!declare_signal(len)) return Item::Error;
        pos_ += 7u + len;
        ++index_;
        continue;
      }
      case input_log::kAction: {
        if (!whole(14)) return error_.empty() ? Item::Eof : fail_at(error_);
        const auto kind = static_cast<std::uint8_t>(buffer_[pos_ + 1]);
        const Time t{get<std::int64_t>(buffer_.data() + pos_ + 2)};
        const auto size = get<std::uint32_t>(buffer_.data() + pos_ + 10);
        if (kind < 1 || kind > 5) return fail_at("unknown action kind " + std::to_string(kind));
        if (size > kMaxPayload) return fail_at("action of " + std::to_string(size) + " bytes (at most 16 MiB)");
        if (!whole(14u + size)) return error_.empty() ? Item::Eof : fail_at(error_);
        auto action = decode_action(static_cast<InputActionKind>(kind), buffer_.data() + pos_ + 14, size);
        if (!action) return fail_at("malformed action payload");
        action_ = std::move(*action);
        mark_time_ = t;
        pos_ += 14u + size;
        ++index_;
        return Item::Action;
      }
      case input_log::kLoss: {
        if (!whole(19)) return error_.empty() ? Item::Eof : fail_at(error_);
        mark_time_ = Time{get<std::int64_t>(buffer_.data() + pos_ + 1)};
        loss_signal_ = get<std::uint16_t>(buffer_.data() + pos_ + 9);
        if (loss_signal_ != 0xffff && loss_signal_ >= widths_.size()) {
          return fail_at("loss of signal id " + std::to_string(loss_signal_) + ", which was never declared");
        }
        lost_ = get<std::uint64_t>(buffer_.data() + pos_ + 11);
        pos_ += 19;
        ++index_;
        return Item::Loss;
      }
      case input_log::kEnd: {
        if (!whole(9)) return error_.empty() ? Item::Eof : fail_at(error_);
        mark_time_ = Time{get<std::int64_t>(buffer_.data() + pos_ + 1)};
        pos_ += 9;
        ++index_;
        return Item::End;
      }
      default: {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02x", tag);
        return fail_at(std::string("unknown record tag ") + hex);
      }
    }
  }
}

}  // namespace safecass
