// Registers the Frozen filter next to the built-ins and drives it in simulated time.
#include <cstdio>

#include "frozen_filter.hpp"

int main() {
  SimulatedClock clock;
  Coordinator co("example", &clock);
  FilterRegistry registry;
  register_builtin_filters(registry);
  if (!registry.add<Frozen>("Frozen")) return 2;
  Monitor monitor(co, registry);
  const ComponentId encoder = *co.add_component("ENCODER");
  (void)co.add_event(EventDef{"EVT_FROZEN", 60, {Transition::N2E}, "", false, "", "encoder stopped updating"});
  (void)co.add_event(EventDef{"/EVT_FROZEN", 60, {Transition::E2N}, "", false, "", ""});
  Signal* angle = *monitor.add_signal("ENCODER.angle");
  FilterConfig config{
      "frozen_angle",
      "Frozen",
      FilterTarget{MachineKind::Application, "ENCODER", ""},
      ExecutionMode::Active,
      DetectionMode::Edge,
      true,
      Params{{"input_signal", std::string("angle")}, {"samples", 3.0}, {"event_onset", std::string("EVT_FROZEN")}}};
  if (auto f = monitor.add_filter(config); !f) {
    std::fprintf(stderr, "%s\n", f.error().message.c_str());
    return 2;
  }
  const double samples[] = {0.10, 0.20, 0.30, 0.30, 0.30, 0.40};
  for (int i = 0; i < 6; ++i) {
    clock.set(std::chrono::milliseconds(i));
    angle->push(clock.now(), samples[i]);
    monitor.run_active(encoder, clock.now());
    std::printf("t=%d ms angle=%.2f ENCODER %s\n", i, samples[i],
                std::string(to_string(co.extended(encoder).state)).c_str());
  }
  // Frozen at samples 3-5 (Error), moving again at sample 6 (Normal).
  return co.extended(encoder).state == State::Normal &&
                 co.history(co.structure().application_machine(encoder)).size() >= 2
             ? 0
             : 1;
}
