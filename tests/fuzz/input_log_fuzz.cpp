// libFuzzer target for the inputs recording reader (record/input_log.hpp, docs/record-format.md):
// any bytes, as a recording file. Beyond "no crash, no sanitizer report", it traps when a promise
// is broken: an error names the file and says why, nothing is read after the end or an error; and
// a round trip: what was read, written again with the writer's put_* functions, reads back as the
// same items (kinds, signals, times, values bit for bit, actions, losses, the end).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "safecass/record/input_log.hpp"

namespace {

using safecass::InputLogReader;

/// One item as the reader gave it, in a form two readers can compare.
struct Item {
  InputLogReader::Item kind;
  std::string signal;
  std::int64_t time = 0;
  std::vector<std::uint64_t> bits;  ///< the values, bit for bit (NaN == NaN)
  std::string action;               ///< an action re-encoded by put_action
  std::uint64_t lost = 0;
  bool operator==(const Item&) const = default;
};

std::string path_for(const char* what) {
  return (std::filesystem::temp_directory_path() /
          ("safecass-input-log-fuzz-" + std::to_string(::getpid()) + "-" + what + ".inputs"))
      .string();
}

bool write_file(const std::string& path, const void* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

/// Declares, in id order as the format wants, every signal the reader knows and `out` does not yet.
void declare(const InputLogReader& r, std::string& out, std::size_t& declared) {
  for (; declared < r.signal_count(); ++declared) {
    const auto id = static_cast<std::uint16_t>(declared);
    safecass::input_log::put_signal(out, id, static_cast<std::uint16_t>(r.signal_width(id)), r.signal_name(id));
  }
}

/// Every item of the file at `path` (at most `limit`), and the recording written again into `out`.
std::vector<Item> read_all(const std::string& path, std::string* out, bool& error) {
  using namespace safecass;
  std::vector<Item> items;
  auto reader = InputLogReader::open(path);
  if (!reader) {
    if (reader.error().message.empty()) __builtin_trap();
    error = true;
    return items;
  }
  InputLogReader& r = **reader;
  if (out != nullptr) input_log::put_header(*out, r.header());
  std::size_t declared = 0;
  std::optional<std::int64_t> last_time;  // of the last time record written
  for (std::size_t n = 0; n < 100000; ++n) {
    const InputLogReader::Item kind = r.next();
    Item item;
    item.kind = kind;
    if (kind == InputLogReader::Item::Sample) {
      item.signal = r.signal_name(r.signal());
      item.time = r.time().count();
      for (std::size_t k = 0; k < r.width(); ++k) {
        std::uint64_t b = 0;
        std::memcpy(&b, &r.values()[k], sizeof b);
        item.bits.push_back(b);
      }
      if (out != nullptr) {
        declare(r, *out, declared);
        if (last_time != item.time) input_log::put_time(*out, r.time());
        last_time = item.time;
        input_log::put_sample(*out, r.signal(), r.values(), r.width());
      }
    } else if (kind == InputLogReader::Item::Action) {
      item.time = r.mark_time().count();
      input_log::put_action(item.action, r.action(), r.mark_time());
      if (out != nullptr) *out += item.action;
    } else if (kind == InputLogReader::Item::Loss) {
      item.time = r.mark_time().count();
      item.signal = r.loss_signal() == 0xffff ? std::string("*") : r.signal_name(r.loss_signal());
      item.lost = r.lost();
      if (out != nullptr) {
        declare(r, *out, declared);
        input_log::put_loss(*out, r.mark_time(), r.loss_signal(), r.lost());
      }
    } else if (kind == InputLogReader::Item::End) {
      item.time = r.mark_time().count();
      if (out != nullptr) input_log::put_end(*out, r.mark_time());
    } else if (kind == InputLogReader::Item::Error) {
      if (r.error().find(path) != 0) __builtin_trap();  // "PATH: record N (byte B): reason"
      error = true;
      if (r.next() != InputLogReader::Item::Error && r.next() != InputLogReader::Item::Eof) __builtin_trap();
      return items;
    }
    if (kind == InputLogReader::Item::Eof) {
      if (r.next() != InputLogReader::Item::Eof) __builtin_trap();
      return items;
    }
    items.push_back(std::move(item));
  }
  return items;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string first = path_for("in");
  static const std::string second = path_for("again");
  if (!write_file(first, data, size)) return 0;
  std::string rewritten;
  bool error = false;
  const std::vector<Item> items = read_all(first, &rewritten, error);
  if (error && items.empty()) return 0;
  if (!write_file(second, rewritten.data(), rewritten.size())) return 0;
  bool error_again = false;
  const std::vector<Item> again = read_all(second, nullptr, error_again);
  if (error_again || again != items) __builtin_trap();
  return 0;
}
