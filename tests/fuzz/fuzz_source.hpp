#pragma once
// What the fuzz targets of the replay's logs share (csv, rosbag1, rosbag2): the input written to a
// file of this process (the readers take a path), the system a log replays into, and the promises
// every input source keeps while it is drained: a log that is refused says where (the file, and a
// message or line once it is read) and why; a sample is of a bound input signal and its time never
// goes back; a CSV log's values are finite (a bag may carry a sensor's NaN: the monitor turns it
// into EVT_INVALID_SAMPLE, docs/filters.md).

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "safecass/filters/registry.hpp"
#include "safecass/record/input_source.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::fuzz {

/// The path of this process's input file, ending with `suffix`, holding `data`; empty when it
/// cannot be written.
inline std::string write_input(const std::uint8_t* data, std::size_t size, std::string_view suffix) {
  std::string path =
      (std::filesystem::temp_directory_path() / ("safecass-fuzz-" + std::to_string(::getpid()) + std::string(suffix)))
          .string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return {};
  const bool written = std::fwrite(data, 1, size, f) == size;
  if (std::fclose(f) != 0 || !written) return {};
  return path;
}

/// The system of `file` (relative to the source root), opened once per process.
inline spec::Instance& system_of(const char* file) {
  static const std::unique_ptr<spec::Instance> instance = [file] {
    auto opened = spec::open_instance(std::string(SAFECASS_SOURCE_DIR) + "/" + file, builtin_filters());
    if (!opened) __builtin_trap();
    return std::move(*opened);
  }();
  return *instance;
}

enum class Values : std::uint8_t { Finite, Any };

/// Binds the source that opening `path` gave into `monitor` and reads it to its end or its first
/// error (at most 100,000 items), trapping when a promise above is broken.
inline void drain(Expected<std::unique_ptr<InputSource>> opened, const std::string& path, Monitor& monitor,
                  Values values) {
  if (!opened) {
    if (opened.error().message.find(path) == std::string::npos) __builtin_trap();
    return;
  }
  InputSource& s = **opened;
  if (auto bound = s.bind(monitor); !bound) {
    if (bound.error().message.empty()) __builtin_trap();
    return;
  }
  // Times never decrease; they may start below zero (field data with a pre-trigger window).
  std::optional<Time> last;
  for (int n = 0; n < 100000; ++n) {
    const InputItem item = s.next();
    if (item.kind == InputItem::Kind::End) return;
    if (item.kind == InputItem::Kind::Error) {
      if (s.error().empty() || s.where().find(path) != 0) __builtin_trap();
      return;
    }
    if (item.kind != InputItem::Kind::Sample || item.signal == nullptr || item.values == nullptr) __builtin_trap();
    if (last && item.time < *last) __builtin_trap();
    last = item.time;
    for (std::size_t k = 0; values == Values::Finite && k < item.signal->size(); ++k) {
      if (!std::isfinite(item.values[k])) __builtin_trap();
    }
  }
}

}  // namespace safecass::fuzz
