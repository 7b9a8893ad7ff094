// libFuzzer target for the replay's CSV reader (replay::open_csv, docs/tools.md "Replay"): any
// bytes, as a CSV log replayed into tests/data/replay/arm.json. Beyond "no crash, no sanitizer
// report", it traps when a promise is broken: a log that is refused says where (the file, and a
// line once rows are read) and why; a sample is of a bound input signal with finite values, and
// its time never goes back.

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/replay/source.hpp"
#include "safecass/spec/instance.hpp"

namespace {

safecass::spec::Instance& arm() {
  static const std::unique_ptr<safecass::spec::Instance> instance = [] {
    auto opened = safecass::spec::open_instance(std::string(SAFECASS_SOURCE_DIR) + "/tests/data/replay/arm.json",
                                                safecass::builtin_filters());
    if (!opened) __builtin_trap();
    return std::move(*opened);
  }();
  return *instance;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("safecass-csv-fuzz-" + std::to_string(::getpid()) + ".csv")).string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    const bool written = std::fwrite(data, 1, size, f) == size;
    if (std::fclose(f) != 0 || !written) return 0;
  }
  auto source = replay::open_csv(path);
  if (!source) {
    if (source.error().message.find(path) == std::string::npos) __builtin_trap();
    return 0;
  }
  InputSource& s = **source;
  if (auto bound = s.bind(arm().monitor()); !bound) {
    if (bound.error().message.empty()) __builtin_trap();
    return 0;
  }
  // Times never decrease; they may start below zero (field data with a pre-trigger window).
  std::optional<Time> last;
  for (int n = 0; n < 100000; ++n) {
    const InputItem item = s.next();
    if (item.kind == InputItem::Kind::End) return 0;
    if (item.kind == InputItem::Kind::Error) {
      if (s.error().empty() || s.where().find(path) != 0) __builtin_trap();
      return 0;
    }
    if (item.kind != InputItem::Kind::Sample || item.signal == nullptr || item.values == nullptr) __builtin_trap();
    if (last && item.time < *last) __builtin_trap();
    last = item.time;
    for (std::size_t k = 0; k < item.signal->size(); ++k) {
      if (!std::isfinite(item.values[k])) __builtin_trap();
    }
  }
  return 0;
}
