// libFuzzer target for what a console reads from a live coordinator without a Slice type of its
// own: a named read's JSON answer (introspect::read_text, local_query.hpp), as Control::read
// returns it. Beyond "no crash, no sanitizer report", it traps when a promise is broken: an answer
// is either shown as text or refused with a Parse error that names the read, and an answer that
// reads back writes the same value again (state summary: read, write, read gives equal values).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  using namespace safecass::introspect;
  const std::string_view answer(reinterpret_cast<const char*>(data), size);
  auto text = read_text("state summary", answer);
  if (!text && (text.error().code != ErrorCode::Parse || text.error().message.find("state summary") != 0)) {
    __builtin_trap();
  }
  auto value = state_summary_from_json(answer);
  if (value.has_value() != text.has_value()) __builtin_trap();
  if (value) {
    auto again = state_summary_from_json(state_summary_json(*value));
    if (!again || !(*again == *value)) __builtin_trap();
  }
  return 0;
}
