// libFuzzer target for the history line reader (introspect::history_entry_from_json, the one reader
// of what history_json writes: the timeline, trace, `import safecass`). Any bytes, as one line of
// a history file. Beyond "no crash, no sanitizer report", a round trip: a line that reads is
// written and read again, and from then on writing and reading changes nothing (the first read may
// round a time to the file's microseconds).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "safecass/introspect/format.hpp"
#include "safecass/json/read.hpp"

namespace {

[[nodiscard]] safecass::Expected<safecass::introspect::HistoryEntry> read_line(std::string_view line) {
  const safecass::json::JsonParse parsed = safecass::json::parse_json(line, 8);
  if (!parsed.value) return safecass::fail(safecass::ErrorCode::Parse, "not JSON");
  return safecass::introspect::history_entry_from_json(*parsed.value);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  auto first = read_line(line);
  if (!first) {
    if (first.error().message.empty()) __builtin_trap();
    return 0;
  }
  const std::string written = introspect::history_json(*first);
  auto second = read_line(written);
  if (!second) __builtin_trap();  // what the writer wrote, the reader reads
  const std::string again = introspect::history_json(*second);
  // Compared as written, not with ==: a root's value may be NaN (a non-finite sample judged), and
  // NaN equals nothing.
  auto third = read_line(again);
  if (!third || introspect::history_json(*third) != again) __builtin_trap();
  return 0;
}
