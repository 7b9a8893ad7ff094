// A CSV log as a replay source: streamed line by line, one buffer whatever the file's size.

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>

#include "safecass/replay/source.hpp"

namespace safecass::replay {

namespace {

constexpr std::size_t kBuffer = 256 * 1024;
constexpr std::size_t kMaxLine = 1 << 20;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// A double, the whole cell; false when malformed or not finite.
bool parse_number(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(out);
}

class CsvSource final : public InputSource {
public:
  CsvSource(int fd, std::string path) : fd_(fd), path_(std::move(path)), buffer_(kBuffer) {}
  ~CsvSource() override { ::close(fd_); }

  [[nodiscard]] Expected<void> bind(Monitor& monitor) override {
    std::string_view line;
    if (!read_line(line)) {
      if (!error_.empty()) return fail(ErrorCode::Io, error_);
      return fail(ErrorCode::Parse,
                  path_ + ":1: the file is empty: it needs a header naming a time column and signals");
    }
    // Header cells, with their columns (1-based characters).
    struct Cell {
      std::string text;
      int column;
    };
    std::vector<Cell> cells;
    for (std::size_t at = 0;;) {
      const std::size_t comma = line.find(',', at);
      const std::string_view raw =
          line.substr(at, comma == std::string_view::npos ? std::string_view::npos : comma - at);
      const std::size_t lead =
          raw.size() -
          raw.substr(raw.find_first_not_of(" \t") == std::string_view::npos ? raw.size() : raw.find_first_not_of(" \t"))
              .size();
      cells.push_back(Cell{std::string(trim(raw)), static_cast<int>(at + lead + 1)});
      if (comma == std::string_view::npos) break;
      at = comma + 1;
    }
    const auto where = [this](int column) {
      return path_ + ":" + std::to_string(line_no_) + ":" + std::to_string(column) + ": ";
    };
    columns_ = cells.size();
    time_column_ = -1;
    std::map<std::string, int> seen;
    struct Element {
      std::size_t index;
      std::size_t column;
      int at;
    };
    std::map<std::string, std::vector<Element>> by_signal;  // name → elements
    std::vector<std::string> order;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Cell& c = cells[i];
      if (c.text.empty())
        return fail(ErrorCode::Parse, where(c.column) + "column " + std::to_string(i + 1) + " has no name");
      if (auto [it, fresh] = seen.emplace(c.text, c.column); !fresh) {
        return fail(ErrorCode::Parse, where(c.column) + "column '" + c.text + "' appears twice (first at column " +
                                          std::to_string(it->second) + ")");
      }
      if (c.text == "time" || c.text == "t") {
        if (time_column_ >= 0) return fail(ErrorCode::Parse, where(c.column) + "a second time column '" + c.text + "'");
        time_column_ = static_cast<int>(i);
        continue;
      }
      std::string name = c.text;
      std::size_t index = 0;
      bool indexed = false;
      if (const std::size_t open = name.find('['); open != std::string::npos) {
        const std::string_view digits = std::string_view(name).substr(open + 1, name.size() - open - 2);
        const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), index);
        if (name.back() != ']' || digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size()) {
          return fail(ErrorCode::Parse,
                      where(c.column) + "column '" + c.text + "' is not Component.signal or Component.signal[i]");
        }
        name.resize(open);
        indexed = true;
      }
      if (name.find('.') == std::string::npos) {
        return fail(
            ErrorCode::Parse,
            where(c.column) + "column '" + c.text +
                "' is not a signal (Component.signal or Component.signal[i]) nor the time column ('time' or 't')");
      }
      if (by_signal.count(name) == 0) order.push_back(name);
      auto& elements = by_signal[name];
      if (!indexed && !elements.empty())
        return fail(ErrorCode::Parse, where(c.column) + "column '" + c.text + "' mixes a scalar and indexed columns");
      elements.push_back(Element{index, i, c.column});
    }
    if (time_column_ < 0) {
      return fail(ErrorCode::Parse,
                  path_ + ":" + std::to_string(line_no_) +
                      ": missing column 'time' (the time of each row in seconds; also accepted: 't')");
    }
    cell_group_.assign(columns_, -1);
    cell_element_.assign(columns_, 0);
    for (const std::string& name : order) {
      const auto& elements = by_signal[name];
      auto s = find_input_signal(monitor, name);
      if (!s) return fail(ErrorCode::Parse, where(elements.front().at) + s.error().message);
      const std::size_t size = (*s)->size();
      std::vector<bool> have(size, false);
      for (const Element& e : elements) {
        if (e.index >= size) {
          return fail(ErrorCode::Parse, where(e.at) + "column '" + cells[e.column].text + "': signal '" + name +
                                            "' has size " + std::to_string(size) + " (indices 0.." +
                                            std::to_string(size - 1) + ")");
        }
        have[e.index] = true;
        cell_group_[e.column] = static_cast<int>(groups_.size());
        cell_element_[e.column] = e.index;
      }
      for (std::size_t k = 0; k < size; ++k) {
        if (!have[k]) {
          return fail(ErrorCode::Parse, path_ + ":" + std::to_string(line_no_) + ": missing column '" + name + "[" +
                                            std::to_string(k) + "]': signal '" + name + "' has size " +
                                            std::to_string(size) + ", each element needs a column");
        }
      }
      groups_.push_back(Group{*s, name, size, values_.size(), 0});
      values_.resize(values_.size() + size);
    }
    present_.assign(groups_.size(), 0);
    return {};
  }

  InputItem next() override {
    InputItem item;
    if (failed_) {
      item.kind = InputItem::Kind::Error;
      return item;
    }
    for (;;) {
      while (emit_ < groups_.size()) {
        const std::size_t g = emit_++;
        if (present_[g] != groups_[g].size) continue;
        ++samples_;
        item.kind = InputItem::Kind::Sample;
        item.time = row_time_;
        item.signal = groups_[g].signal;
        item.values = values_.data() + groups_[g].offset;
        return item;
      }
      if (!read_row()) {
        item.kind = failed_ ? InputItem::Kind::Error : InputItem::Kind::End;
        return item;
      }
      emit_ = 0;
    }
  }

  const std::string& error() const override { return error_; }
  std::uint64_t samples() const override { return samples_; }
  std::string where() const override { return path_ + ":" + std::to_string(line_no_); }

private:
  struct Group {
    Signal* signal;
    std::string name;
    std::size_t size;
    std::size_t offset;
    std::size_t unused;
  };

  bool fail_line(int column, const std::string& reason) {
    failed_ = true;
    error_ = path_ + ":" + std::to_string(line_no_) + (column > 0 ? ":" + std::to_string(column) : "") + ": " + reason;
    return false;
  }

  /// The next non-empty, non-comment line (without its newline); false at the end or on error.
  bool read_line(std::string_view& line) {
    for (;;) {
      const char* start = buffer_.data() + pos_;
      const void* nl = std::memchr(start, '\n', end_ - pos_);
      if (nl == nullptr) {
        if (eof_) {
          if (pos_ == end_) return false;
          // The last line without a newline.
          line = std::string_view(start, end_ - pos_);
          pos_ = end_;
        } else {
          if (end_ - pos_ >= kMaxLine) {
            ++line_no_;
            return fail_line(0, "line longer than 1 MiB");
          }
          if (!refill()) return false;
          continue;
        }
      } else {
        const auto n = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
        line = std::string_view(start, n);
        pos_ += n + 1;
      }
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (trim(line).empty() || line.front() == '#') continue;
      return true;
    }
  }

  bool refill() {
    if (pos_ > 0) {
      std::memmove(buffer_.data(), buffer_.data() + pos_, end_ - pos_);
      end_ -= pos_;
      pos_ = 0;
    }
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
    for (;;) {
      const ssize_t got = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) {
        failed_ = true;
        error_ = path_ + ": read error: " + std::strerror(errno);
        return false;
      }
      if (got == 0) eof_ = true;
      end_ += static_cast<std::size_t>(got);
      return true;
    }
  }

  bool read_row() {
    std::string_view line;
    if (!read_line(line)) return false;
    std::fill(present_.begin(), present_.end(), 0);
    std::size_t column = 0;
    double t = 0;
    bool have_time = false;
    for (std::size_t at = 0;; ++column) {
      const std::size_t comma = line.find(',', at);
      const std::size_t stop = comma == std::string_view::npos ? line.size() : comma;
      if (column >= columns_) {
        return fail_line(0, "the row has more cells than the header's " + std::to_string(columns_) + " columns");
      }
      const std::string_view cell = trim(line.substr(at, stop - at));
      if (!cell.empty()) {
        double v = 0;
        if (!parse_number(cell, v)) {
          const std::string what =
              static_cast<int>(column) == time_column_ ? "time" : "column " + std::to_string(column + 1);
          return fail_line(static_cast<int>(at + 1), "malformed number '" + std::string(cell) + "' in " + what +
                                                         " (a finite decimal number is expected)");
        }
        if (static_cast<int>(column) == time_column_) {
          t = v;
          have_time = true;
        } else {
          const int g = cell_group_[column];
          values_[groups_[static_cast<std::size_t>(g)].offset + cell_element_[column]] = v;
          ++present_[static_cast<std::size_t>(g)];
        }
      }
      if (comma == std::string_view::npos) break;
      at = comma + 1;
    }
    if (column + 1 != columns_) {
      return fail_line(0, "the row has " + std::to_string(column + 1) + " cells, the header " +
                              std::to_string(columns_) + " columns");
    }
    if (!have_time) return fail_line(0, "the row has no time");
    // A time the replay's clock holds (nanoseconds in 64 bits): field data in seconds since the Unix
    // epoch fits, with room; 1e72 s does not convert at all.
    if (!readable_seconds(t)) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "time %.9g s is out of range (at most 4e9 s in magnitude)", t);
      return fail_line(0, buf);
    }
    const Time time = seconds_to_time(t);
    if (have_row_ && time < row_time_) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "time %.9g s is before the previous row's %.9g s (time must not decrease)", t,
                    to_seconds(row_time_));
      return fail_line(0, buf);
    }
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      if (present_[g] != 0 && present_[g] != groups_[g].size) {
        return fail_line(0, "signal '" + groups_[g].name + "' has " + std::to_string(present_[g]) + " of its " +
                                std::to_string(groups_[g].size) + " values in this row (all or none)");
      }
    }
    have_row_ = true;
    row_time_ = time;
    return true;
  }

  int fd_;
  std::string path_;
  std::vector<char> buffer_;
  std::size_t pos_ = 0;
  std::size_t end_ = 0;
  bool eof_ = false;
  bool failed_ = false;
  std::string error_;
  int line_no_ = 0;
  std::size_t columns_ = 0;
  int time_column_ = -1;
  std::vector<int> cell_group_;
  std::vector<std::size_t> cell_element_;
  std::vector<Group> groups_;
  std::vector<double> values_;
  std::vector<std::size_t> present_;
  std::size_t emit_ = 0;
  bool have_row_ = false;
  Time row_time_{};
  std::uint64_t samples_ = 0;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_csv(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::Io, "cannot read CSV log '" + path + "': " + std::strerror(errno));
  return std::unique_ptr<InputSource>(new CsvSource(fd, path));
}

}  // namespace safecass::replay
