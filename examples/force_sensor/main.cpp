// The paper's simple example (Fig. 9/10) as a program: the spec defines the safety feature, the
// native runtime runs FORCE_SENSOR's task in simulated time, and the application only writes the
// measured force. No `if (force > limit)` in application code.
//
// Usage: force_sensor_example [SPEC]

#include <cstdio>

#include "safecass/native/system.hpp"

using namespace safecass;

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "examples/force_sensor/force_sensor.json";
  const FilterRegistry& registry = builtin_filters();
  // One factory builds the system: coordinator, monitor, filters, and a 1 ms task per component.
  native::SystemOptions options;
  options.component_period = std::chrono::milliseconds(1);
  auto opened = native::open_system(path, registry, options);
  if (!opened) {
    spec::print(opened.error(), stderr);
    return 2;
  }
  native::System& system = **opened;
  SimulatedClock& clock = *system.simulated_clock();
  Coordinator& co = system.coordinator();
  native::Runtime& runtime = system.runtime();
  const ComponentId sensor = *co.structure().find_component("FORCE_SENSOR");
  Signal* force = system.monitor().signals().find("FORCE_SENSOR.Force");

  co.subscribe([&co](const Record& r) {
    if (r.kind == RecordKind::ComponentTransition) {
      std::printf("t=%.3f s  FORCE_SENSOR %s -> %s (%s)\n", to_seconds(r.time), std::string(to_string(r.from)).c_str(),
                  std::string(to_string(r.to)).c_str(), co.structure().event(r.event).name.c_str());
    }
  });
  int transitions_expected_seen = 0;
  for (int ms = 0; ms <= 600; ++ms) {
    const Time now = std::chrono::milliseconds(ms);
    clock.set(now);
    const double f = ms < 300 ? ms * 0.12 : (600 - ms) * 0.12;  // 0 -> 36 N -> 0
    force->push(now, f);
    runtime.step(now);
    if (ms == 300 && co.extended(sensor).state == State::Error) ++transitions_expected_seen;
  }
  const bool ok = transitions_expected_seen == 1 && co.extended(sensor).state == State::Normal;
  std::printf("%s\n", ok ? "force limit detected at 30 N and cleared below 28 N" : "unexpected behaviour");
  return ok ? 0 : 1;
}
