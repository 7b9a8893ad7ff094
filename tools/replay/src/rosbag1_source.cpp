#include "safecass/replay/rosbag1_source.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>

#include "safecass/ros_common/cdr.hpp"
#include "safecass/ros_common/message_source.hpp"

namespace safecass::replay {

namespace {

// Format 2.0 (wiki.ros.org/Bags/Format/2.0): the line "#ROSBAG V2.0", then records, each a 4-byte
// header length, the header's fields (each a 4-byte length, then name=value), a 4-byte data length
// and the data. All numbers little endian.
constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06,
                       kConnection = 0x07;
/// The largest uncompressed chunk a bag may declare (rosbag writes chunks of 768 KiB by default, and
/// a message larger than that as a chunk of its own).
constexpr std::uint32_t kMaxChunk = 1u << 30;
constexpr std::size_t kIndexEntry = 12;  // uint32 sec, uint32 nsec, uint32 offset in the chunk

/// The little-endian number in `bytes` (at most 8 of them).
std::uint64_t little(std::string_view bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = bytes.size(); i-- > 0;) v = v << 8 | static_cast<std::uint8_t>(bytes[i]);
  return v;
}

/// A record's header fields.
class Fields {
public:
  /// The fields of `header`, or why it is not one.
  [[nodiscard]] static Expected<Fields> parse(std::string_view header) {
    Fields f;
    for (std::size_t pos = 0; pos < header.size();) {
      if (header.size() - pos < 4) return fail(ErrorCode::Parse, "a header field's length is cut off");
      const std::uint64_t n = little(header.substr(pos, 4));
      pos += 4;
      if (n > header.size() - pos)
        return fail(ErrorCode::Parse, "a header field of " + std::to_string(n) + " bytes runs past its header");
      const std::string_view field = header.substr(pos, n);
      pos += n;
      const std::size_t eq = field.find('=');
      if (eq == std::string_view::npos) return fail(ErrorCode::Parse, "a header field without '='");
      f.fields_[std::string(field.substr(0, eq))] = std::string(field.substr(eq + 1));
    }
    return f;
  }
  /// The field `name` as a number of `n` bytes, if it is one.
  std::optional<std::uint64_t> number(const char* name, std::size_t n) const {
    const auto f = fields_.find(name);
    if (f == fields_.end() || f->second.size() != n) return std::nullopt;
    return little(f->second);
  }
  /// The field `name`, or empty.
  std::string text(const char* name) const {
    const auto f = fields_.find(name);
    return f == fields_.end() ? std::string() : f->second;
  }

private:
  std::map<std::string, std::string, std::less<>> fields_;
};

class Rosbag1Source final : public ros_common::MessageSource {
public:
  using MessageSource::MessageSource;

  /// Walks the bag's records: every one must fit in the file, the bag header must come first, and
  /// the places it and the chunk information records name must be where such records start.
  /// Collects the connections, the chunks and the index records. Errors: Io, Parse.
  [[nodiscard]] Expected<void> open() {
    file_.open(path(), std::ios::binary);
    if (!file_) return fail(ErrorCode::Io, path() + ": cannot read");
    file_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(file_.tellg());
    file_.seekg(0);
    std::string magic(kMagic.size(), '\0');
    if (!file_.read(magic.data(), static_cast<std::streamsize>(magic.size())) || magic != kMagic)
      return fail(ErrorCode::Parse, path() + ": not a ROS bag of format 2.0 (its first line is not \"#ROSBAG V2.0\")");
    std::optional<std::uint64_t> index_pos;
    std::vector<std::uint64_t> starts;                                // of every record, in order
    std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_refs;  // (chunk information record, its chunk_pos)
    for (std::uint64_t at = kMagic.size(); at < size_;) {
      starts.push_back(at);
      std::uint32_t header_len = 0;
      if (!number(at, header_len)) return damaged(at, "a record's header length is cut off");
      if (header_len > size_ - at - 4)
        return damaged(at, "a record header of " + std::to_string(header_len) + " bytes runs past the end of the file");
      std::string header(header_len, '\0');
      if (!file_.read(header.data(), header_len)) return damaged(at, "a record header cannot be read");
      auto fields = Fields::parse(header);
      if (!fields) return damaged(at, fields.error().message);
      const std::optional<std::uint64_t> op = fields->number("op", 1);
      if (!op) return damaged(at, "a record without its one-byte op field");
      std::uint32_t data_len = 0;
      if (!number(at + 4 + header_len, data_len)) return damaged(at, "a record's data length is cut off");
      const std::uint64_t data_at = at + 8 + header_len;
      if (data_len > size_ - data_at)
        return damaged(at, "record data of " + std::to_string(data_len) + " bytes run past the end of the file");
      if ((at == kMagic.size()) != (*op == kBagHeader)) return damaged(at, "the bag header is not the first record");
      if (auto r = take(*op, *fields, at, data_at, data_len, index_pos, chunk_refs); !r) return r;
      at = data_at + data_len;
    }
    if (!index_pos) return damaged(kMagic.size(), "no bag header record");
    if (*index_pos == 0)
      return fail(ErrorCode::Parse, path() +
                                        ": the bag has no index (a recording that was cut short?): `rosbag reindex " +
                                        path() + "` writes it");
    if (!std::binary_search(starts.begin(), starts.end(), *index_pos))
      return damaged(kMagic.size(),
                     "the index position " + std::to_string(*index_pos) + " is not where a record starts");
    for (const auto& ref : chunk_refs) {
      const auto chunk = std::lower_bound(chunks_.begin(), chunks_.end(), ref.second,
                                          [](const Chunk& c, std::uint64_t at) { return c.at < at; });  // in file order
      if (chunk == chunks_.end() || chunk->at != ref.second)
        return damaged(ref.first, "the chunk position " + std::to_string(ref.second) + " is not where a chunk starts");
    }
    return {};
  }

private:
  struct Chunk {
    std::uint64_t at, data_at;
    std::uint32_t data_len, size;
    std::string compression;
  };
  struct Connection {
    std::string topic, type;
  };
  struct Index {  // an index data record: where the messages of one connection are in one chunk
    std::size_t chunk;
    std::uint32_t connection;
    std::uint64_t data_at;
    std::uint32_t count;
  };
  struct Entry {  // a message to replay
    std::int64_t time;
    std::size_t chunk;
    std::uint32_t offset, connection;
  };

  /// What the record of `op` at `at` tells, checked.
  [[nodiscard]] Expected<void> take(std::uint64_t op, const Fields& fields, std::uint64_t at, std::uint64_t data_at,
                                    std::uint32_t data_len, std::optional<std::uint64_t>& index_pos,
                                    std::vector<std::pair<std::uint64_t, std::uint64_t>>& chunk_refs) {
    switch (op) {
      case kBagHeader:
        index_pos = fields.number("index_pos", 8);
        if (!index_pos) return damaged(at, "the bag header has no 8-byte index_pos");
        return {};
      case kChunk: {
        const std::string compression = fields.text("compression");
        const std::optional<std::uint64_t> declared = fields.number("size", 4);
        if (!declared) return damaged(at, "a chunk without its 4-byte size");
        const bool known = compression == "none" || compression == "bz2" || compression == "lz4";
        if (!known || (compression == "none" ? *declared != data_len : *declared > kMaxChunk))
          return damaged(at, "a chunk of " + std::to_string(data_len) + " bytes compressed '" + compression +
                                 "' declares " + std::to_string(*declared) +
                                 " bytes (none: its own size; bz2 or lz4: at most " + std::to_string(kMaxChunk) + ")");
        chunks_.push_back(Chunk{at, data_at, data_len, static_cast<std::uint32_t>(*declared), compression});
        return {};
      }
      case kIndexData: {
        const std::optional<std::uint64_t> version = fields.number("ver", 4), connection = fields.number("conn", 4),
                                           count = fields.number("count", 4);
        if (!version || *version != 1 || !connection || !count)
          return damaged(at, "an index record without version 1, its connection or its count");
        if (chunks_.empty()) return damaged(at, "an index record before any chunk");
        if (*count * kIndexEntry != data_len)
          return damaged(at, "an index record of " + std::to_string(*count) + " messages holds " +
                                 std::to_string(data_len) + " bytes");
        indexes_.push_back(Index{chunks_.size() - 1, static_cast<std::uint32_t>(*connection), data_at,
                                 static_cast<std::uint32_t>(*count)});
        return {};
      }
      case kConnection: {
        const std::optional<std::uint64_t> id = fields.number("conn", 4);
        std::string data(data_len, '\0');
        file_.seekg(static_cast<std::streamoff>(data_at));
        if (!id || !file_.read(data.data(), data_len)) return damaged(at, "a connection record without its conn");
        auto described = Fields::parse(data);  // the connection header: topic, type, md5sum, ...
        if (!described) return damaged(at, "a connection's header: " + described.error().message);
        connections_[static_cast<std::uint32_t>(*id)] = Connection{fields.text("topic"), described->text("type")};
        return {};
      }
      case kChunkInfo: {
        const std::optional<std::uint64_t> chunk_pos = fields.number("chunk_pos", 8);
        if (!chunk_pos) return damaged(at, "a chunk information record without its 8-byte chunk_pos");
        chunk_refs.emplace_back(at, *chunk_pos);
        return {};
      }
      default: return {};  // message data outside a chunk: not read (rosbag writes none)
    }
  }

  /// The messages of `topics`, from the index records, in time order; the bag's first message time.
  [[nodiscard]] Expected<void> select(const std::vector<std::string>& topics) override {
    bool any = false;
    std::string entries;
    for (const Index& index : indexes_) {
      const auto c = connections_.find(index.connection);
      if (c == connections_.end())
        return damaged(index.data_at, "an index record of connection " + std::to_string(index.connection) +
                                          ", which the bag does not describe");
      const bool selected = std::find(topics.begin(), topics.end(), c->second.topic) != topics.end();
      entries.resize(std::size_t{index.count} * kIndexEntry);
      file_.seekg(static_cast<std::streamoff>(index.data_at));
      if (!file_.read(entries.data(), static_cast<std::streamsize>(entries.size())))
        return damaged(index.data_at, "an index record cannot be read");
      for (std::size_t i = 0; i < index.count; ++i) {
        const std::string_view e = std::string_view(entries).substr(i * kIndexEntry, kIndexEntry);
        const auto time = static_cast<std::int64_t>(little(e.substr(0, 4)) * 1000000000 + little(e.substr(4, 4)));
        begin_ = any ? std::min(begin_, time) : time;
        any = true;
        if (selected)
          entries_.push_back(
              Entry{time, index.chunk, static_cast<std::uint32_t>(little(e.substr(8, 4))), index.connection});
      }
    }
    std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.time < b.time; });
    return {};
  }

  Read read() override {
    if (next_ == entries_.size()) return Read::End;
    ++index_;
    const Entry& e = entries_[next_++];
    return load(e.chunk) && record(e) ? Read::Message : Read::Error;
  }

  /// The message data record at the entry's offset in the loaded chunk (op 2, of the entry's
  /// connection), fed. False after fail_message().
  bool record(const Entry& e) {
    const Connection& c = connections_.at(e.connection);
    const std::string_view chunk(buffer_);
    const auto damaged_chunk = [&](const std::string& what) {
      return fail_message(c.topic, "the chunk at byte " + std::to_string(chunks_[e.chunk].at) + ", offset " +
                                       std::to_string(e.offset) + ": " + what + " (the bag is damaged)");
    };
    if (e.offset > chunk.size() || chunk.size() - e.offset < 4) return damaged_chunk("no message record there");
    const std::uint64_t header_len = little(chunk.substr(e.offset, 4));
    const std::size_t header_at = e.offset + 4;
    if (header_len > chunk.size() - header_at || chunk.size() - header_at - header_len < 4)
      return damaged_chunk("a message record runs past the chunk");
    auto fields = Fields::parse(chunk.substr(header_at, header_len));
    if (!fields) return damaged_chunk(fields.error().message);
    if (fields->number("op", 1) != kMessageData || fields->number("conn", 4) != e.connection)
      return damaged_chunk("not a message of connection " + std::to_string(e.connection));
    const std::size_t data_at = header_at + header_len + 4;
    const std::uint64_t data_len = little(chunk.substr(header_at + header_len, 4));
    if (data_len > chunk.size() - data_at) return damaged_chunk("a message runs past the chunk");
    return message(c, e, chunk.substr(data_at, data_len));
  }

  /// The numbers of message `data` of `c`, fed at the entry's time.
  bool message(const Connection& c, const Entry& e, std::string_view data) {
    const Topic* t = topic(c.topic);
    const std::string expected(ros_common::to_string(t->mapping.type));
    const auto type = ros_common::parse_message_type(c.type);
    if (!type || *type != t->mapping.type)
      return fail_message(c.topic, "a " + c.type + " message; the mapping says " + expected);
    std::string why;
    if (!ros_common::decode_ros1(t->mapping.type, reinterpret_cast<const std::uint8_t*>(data.data()), data.size(),
                                 decoded_, why))
      return fail_message(c.topic, "cannot be read as " + expected + ": " + why);
    return feed(*t, decoded_.numbers, Time{e.time - begin_});
  }

  /// The uncompressed content of chunk `i` in buffer_. False after fail_log().
  bool load(std::size_t i) {
    if (loaded_ == i) return true;
    loaded_.reset();
    const Chunk& c = chunks_[i];
    std::string data(c.data_len, '\0');
    file_.seekg(static_cast<std::streamoff>(c.data_at));
    if (!file_.read(data.data(), c.data_len))
      return fail_log("the chunk at byte " + std::to_string(c.at) + " cannot be read");
    std::string why;
    if (c.compression == "none") {
      buffer_ = std::move(data);
    } else if (!(c.compression == "bz2" ? bunzip(data, c.size, why) : unlz4(data, c.size, why))) {
      return fail_log("the chunk at byte " + std::to_string(c.at) + " does not decompress (" + c.compression +
                      "): " + why + " (the bag is damaged)");
    }
    loaded_ = i;
    return true;
  }

  /// `data` bzip2-decompressed into buffer_, which must be exactly `size` bytes. The buffer grows
  /// with what the data decompresses to, never beyond `size` and one byte to see more.
  bool bunzip(std::string& data, std::uint32_t size, std::string& why) {
    bz_stream s{};
    if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) return (why = "out of memory", false);
    s.next_in = data.data();
    s.avail_in = static_cast<unsigned>(data.size());
    const std::size_t capacity = std::size_t{size} + 1;
    buffer_.assign(std::min<std::size_t>(capacity, 1u << 20), '\0');
    int rc = BZ_OK;
    std::size_t out = 0;
    while (rc == BZ_OK && out < capacity) {
      if (out == buffer_.size()) buffer_.resize(std::min(capacity, buffer_.size() * 2));
      s.next_out = buffer_.data() + out;
      s.avail_out = static_cast<unsigned>(buffer_.size() - out);
      rc = BZ2_bzDecompress(&s);
      out = buffer_.size() - s.avail_out;
      if (rc == BZ_OK && s.avail_in == 0 && s.avail_out != 0) break;  // the data ends before the stream
    }
    BZ2_bzDecompressEnd(&s);
    if (out > size) return (why = "more than its declared " + std::to_string(size) + " bytes", false);
    if (rc != BZ_STREAM_END)
      return (why = rc == BZ_OK ? "the stream is cut off" : "bzip2 error " + std::to_string(rc), false);
    if (out != size) return (why = std::to_string(out) + " bytes, not its declared " + std::to_string(size), false);
    buffer_.resize(out);
    return true;
  }

  /// As bunzip(), for an LZ4 frame.
  bool unlz4(const std::string& data, std::uint32_t size, std::string& why) {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return (why = "out of memory", false);
    const std::size_t capacity = std::size_t{size} + 1;
    buffer_.assign(std::min<std::size_t>(capacity, 1u << 20), '\0');
    std::size_t in = 0, out = 0, hint = 1;
    while (hint != 0 && in < data.size() && out < capacity) {
      if (out == buffer_.size()) buffer_.resize(std::min(capacity, buffer_.size() * 2));
      std::size_t produced = buffer_.size() - out, consumed = data.size() - in;
      hint = LZ4F_decompress(ctx, buffer_.data() + out, &produced, data.data() + in, &consumed, nullptr);
      if (LZ4F_isError(hint)) {
        why = std::string("lz4: ") + LZ4F_getErrorName(hint);
        break;
      }
      in += consumed;
      out += produced;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (!why.empty()) return false;
    if (out > size) return (why = "more than its declared " + std::to_string(size) + " bytes", false);
    if (hint != 0) return (why = "the frame is cut off", false);
    if (out != size) return (why = std::to_string(out) + " bytes, not its declared " + std::to_string(size), false);
    buffer_.resize(out);
    return true;
  }

  /// The 4-byte number at `at` of the file.
  bool number(std::uint64_t at, std::uint32_t& v) {
    char b[4];
    if (size_ - at < 4) return false;
    file_.seekg(static_cast<std::streamoff>(at));
    if (!file_.read(b, 4)) return false;
    v = static_cast<std::uint32_t>(little(std::string_view(b, 4)));
    return true;
  }

  tl::unexpected<Error> damaged(std::uint64_t at, const std::string& what) const {
    return fail(ErrorCode::Parse,
                path() + ": byte " + std::to_string(at) + ": " + what + " (the bag is damaged or truncated)");
  }

  std::ifstream file_;
  std::uint64_t size_ = 0;
  std::vector<Chunk> chunks_;
  std::map<std::uint32_t, Connection> connections_;
  std::vector<Index> indexes_;
  std::vector<Entry> entries_;
  std::size_t next_ = 0;
  std::int64_t begin_ = 0;
  std::optional<std::size_t> loaded_;
  std::string buffer_;
  ros_common::DecodedMessage decoded_;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_rosbag1(const std::string& bag, const std::string& mapping) {
  return ros_common::open_message_source<Rosbag1Source>(bag, mapping);
}

}  // namespace safecass::replay
