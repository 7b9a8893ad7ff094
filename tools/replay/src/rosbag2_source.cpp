#include "safecass/replay/rosbag2_source.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "safecass/ros_common/cdr.hpp"
#include "safecass/ros_common/message_source.hpp"

namespace safecass::replay {

namespace {

class Rosbag2Source final : public ros_common::MessageSource {
public:
  using MessageSource::MessageSource;
  ~Rosbag2Source() override { close(); }
  Rosbag2Source(const Rosbag2Source&) = delete;
  Rosbag2Source& operator=(const Rosbag2Source&) = delete;

  /// The .db3 files of the bag, in name order. Errors: Io.
  [[nodiscard]] Expected<void> open() {
    std::error_code ec;
    if (std::filesystem::is_directory(path(), ec)) {
      for (const auto& entry : std::filesystem::directory_iterator(path(), ec)) {
        if (entry.path().extension() == ".db3") files_.push_back(entry.path().string());
      }
      std::sort(files_.begin(), files_.end());
      if (files_.empty()) return fail(ErrorCode::Io, path() + ": a ROS 2 bag directory with no .db3 file");
    } else {
      files_.push_back(path());
    }
    // Each file must be a rosbag2 store now, not half-way through the replay; the split files of a
    // bag are read in the order of their first message (their names need not sort: bag_10 < bag_2).
    std::vector<std::pair<std::int64_t, std::string>> firsts;
    for (const std::string& f : files_) {
      if (auto r = open_file(f, {}); !r) return r;
      sqlite3_stmt* first = nullptr;
      std::int64_t stamp = 0;
      if (sqlite3_prepare_v2(db_, "SELECT MIN(timestamp) FROM messages", -1, &first, nullptr) == SQLITE_OK &&
          sqlite3_step(first) == SQLITE_ROW)
        stamp = sqlite3_column_int64(first, 0);
      sqlite3_finalize(first);
      firsts.emplace_back(stamp, f);
      close();
    }
    std::stable_sort(firsts.begin(), firsts.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < firsts.size(); ++i) files_[i] = firsts[i].second;
    return {};
  }

private:
  [[nodiscard]] Expected<void> select(const std::vector<std::string>& topics) override {
    topics_ = topics;
    return {};
  }

  /// Opens `file` and, with `topics`, prepares the query of their messages in time order.
  [[nodiscard]] Expected<void> open_file(const std::string& file, const std::vector<std::string>& topics) {
    close();
    if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string why = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
      close();
      return fail(ErrorCode::Io, file + ": cannot open: " + why);
    }
    std::string sql =
        "SELECT m.timestamp, t.name, t.type, t.serialization_format, m.data FROM messages m "
        "JOIN topics t ON m.topic_id = t.id";
    if (!topics.empty()) {
      sql += " WHERE t.name IN (";
      for (std::size_t i = 0; i < topics.size(); ++i) sql += i == 0 ? "?" : ", ?";
      sql += ")";
    }
    sql += " ORDER BY m.timestamp, m.id";
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &query_, nullptr) != SQLITE_OK) {
      const std::string why = sqlite3_errmsg(db_);
      close();
      return fail(ErrorCode::Parse,
                  file + ": not a ROS 2 bag (rosbag2 sqlite3 store with 'messages' and 'topics'): " + why);
    }
    for (std::size_t i = 0; i < topics.size(); ++i)
      sqlite3_bind_text(query_, static_cast<int>(i + 1), topics[i].c_str(), -1, SQLITE_TRANSIENT);
    return {};
  }

  void close() noexcept {
    if (query_ != nullptr) sqlite3_finalize(query_);
    if (db_ != nullptr) sqlite3_close(db_);
    query_ = nullptr;
    db_ = nullptr;
  }

  Read read() override {
    for (;;) {
      if (query_ == nullptr) {
        if (next_file_ == files_.size()) return Read::End;
        if (auto r = open_file(files_[next_file_], topics_); !r) {
          fail_log(r.error().message);
          return Read::Error;
        }
        ++next_file_;
      }
      const int rc = sqlite3_step(query_);
      if (rc == SQLITE_DONE) {
        close();
        continue;
      }
      ++index_;
      if (rc != SQLITE_ROW) {
        fail_log("the bag is truncated or damaged (sqlite: " + std::string(sqlite3_errmsg(db_)) + ")");
        return Read::Error;
      }
      return read_row() ? Read::Message : Read::Error;
    }
  }

  bool read_row() {
    const auto text = [this](int column) {
      const unsigned char* t = sqlite3_column_text(query_, column);
      return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
    };
    const std::int64_t stamp = sqlite3_column_int64(query_, 0);
    const std::string name = text(1), type = text(2), format = text(3);
    const Topic* t = topic(name);
    if (t == nullptr) return true;
    if (!first_) first_ = stamp;
    const auto parsed = ros_common::parse_message_type(type);
    if (!parsed || *parsed != t->mapping.type) {
      return fail_message(
          name, "a " + type + " message; the mapping says " + std::string(ros_common::to_string(t->mapping.type)));
    }
    if (format != "cdr") return fail_message(name, "serialised as '" + format + "'; only 'cdr' is read");
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(query_, 4));
    const auto size = static_cast<std::size_t>(sqlite3_column_bytes(query_, 4));
    std::string why;
    if (!ros_common::decode_cdr(t->mapping.type, data, size, decoded_, why))
      return fail_message(name, "not a " + type + " in CDR: " + why);
    std::int64_t since = 0;
    if (__builtin_sub_overflow(stamp, *first_, &since) || since < 0)
      return fail_message(name, "its time stamp " + std::to_string(stamp) + " ns is before the bag's first message");
    return feed(*t, decoded_.numbers, Time{since});
  }

  std::vector<std::string> files_;
  std::size_t next_file_ = 0;
  std::vector<std::string> topics_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* query_ = nullptr;
  std::optional<std::int64_t> first_;
  ros_common::DecodedMessage decoded_;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_rosbag2(const std::string& bag, const std::string& mapping) {
  return ros_common::open_message_source<Rosbag2Source>(bag, mapping);
}

}  // namespace safecass::replay
