// libFuzzer target for what a console reads from a live coordinator without a Slice type of its
// own: a named read's JSON answer (introspect::read_text, local_query.hpp), as Control::read
// returns it. Each input is read as the answer of every named read ("state summary", "analyze
// now"). Beyond "no crash, no sanitizer report", it traps when a promise is broken: an answer is
// either shown as text or refused with a Parse error that names the read, and an answer that reads
// back writes the same value again (read, write, read gives equal values).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"

namespace {

using namespace safecass;
using namespace safecass::introspect;

/// The promises of read `name`, whose answer's value `From` reads and `To` writes.
template <class T, Expected<T> (*From)(std::string_view), std::string (*To)(const T&)>
void check(std::string_view name, std::string_view answer) {
  auto text = read_text(name, answer);
  if (!text && (text.error().code != ErrorCode::Parse || text.error().message.find(name) != 0)) __builtin_trap();
  auto value = From(answer);
  if (value.has_value() != text.has_value()) __builtin_trap();
  if (value) {
    auto again = From(To(*value));
    if (!again || !(*again == *value)) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view answer(reinterpret_cast<const char*>(data), size);
  check<StateSummary, state_summary_from_json, state_summary_json>("state summary", answer);
  check<CoverageNow, coverage_now_from_json, coverage_now_json>("analyze now", answer);
  return 0;
}
