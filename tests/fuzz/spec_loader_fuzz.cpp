// libFuzzer target for the specification loader: any bytes, as a top-level spec file.
// Beyond "no crash, no sanitizer report", it checks the loader's promises and traps when one is
// broken: every diagnostic of the input points inside it, the model is present exactly when
// there is no error, and a model without errors instantiates.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_text.hpp"
#include "safecass/spec/spec.hpp"

namespace {

const safecass::FilterRegistry& registry() {
  static const safecass::FilterRegistry r = [] {
    safecass::FilterRegistry x;
    safecass::register_builtin_filters(x);
    return x;
  }();
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz-input.json";
  const spec::LoadResult r = spec::load_system_from_text(text, name, registry());
  if (r.system.has_value() != r.ok()) __builtin_trap();
  for (const spec::Diagnostic& d : r.diagnostics) {
    if (d.message.empty()) __builtin_trap();
    if (d.where.file == name && !inside(text, d.where.line, d.where.column)) __builtin_trap();
  }
  if (r.system) {
    Coordinator coordinator("fuzz");
    Monitor monitor(coordinator, registry(), 4);
    if (!spec::instantiate(*r.system, coordinator, monitor)) __builtin_trap();
  }
  return 0;
}
