// libFuzzer target for the replay's CSV reader (replay::open_csv, docs/tools.md "Replay"): any
// bytes, as a CSV log replayed into tests/data/replay/arm.json. Beyond "no crash, no sanitizer
// report", it traps when a promise of fuzz_source.hpp is broken (a refusal says where and why;
// samples are finite, of bound signals, in time order).

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_source.hpp"
#include "safecass/replay/source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace safecass;
  const std::string path = fuzz::write_input(data, size, ".csv");
  if (path.empty()) return 0;
  fuzz::drain(replay::open_csv(path), path, fuzz::system_of("tests/data/replay/arm.json").monitor(),
              fuzz::Values::Finite);
  return 0;
}
