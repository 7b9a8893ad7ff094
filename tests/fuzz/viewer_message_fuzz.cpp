// libFuzzer target for the viewer's WebSocket messages (viewer::Protocol::handle, docs/tools.md
// "Viewer"): any bytes, as one message of a page to a write-enabled viewer of robodoc run in this
// process. Beyond "no crash, no sanitizer report", it traps when a promise is broken: every reply
// is one JSON object, a reply or an error; and a message answered with an error changes nothing
// (the view, every address's state, is the same before and after).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "safecass/json/read.hpp"
#include "safecass/viewer/in_process_source.hpp"
#include "safecass/viewer/protocol.hpp"

namespace {

safecass::viewer::Protocol& robodoc_viewer() {
  static std::unique_ptr<safecass::viewer::InProcessSource> source = [] {
    safecass::viewer::InProcessOptions options;
    options.system = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";
    options.log = nullptr;
    auto opened = safecass::viewer::InProcessSource::open(options);
    if (!opened) __builtin_trap();
    return std::move(*opened);
  }();
  static safecass::viewer::Protocol protocol(*source, {.allow_write = true, .token = "fuzz-token"});
  return protocol;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  viewer::Protocol& p = robodoc_viewer();
  const std::string before = p.view_json();
  const std::string reply = p.handle(std::string_view(reinterpret_cast<const char*>(data), size));
  const json::JsonParse parsed = json::parse_json(reply, 16);
  if (!parsed.value || !parsed.value->is_object()) __builtin_trap();
  const json::JsonValue* type = parsed.value->find("type");
  if (type == nullptr || !type->is_string()) __builtin_trap();
  if (type->string == "error" && p.view_json() != before) __builtin_trap();
  if (type->string != "error" && type->string != "reply") __builtin_trap();
  return 0;
}
