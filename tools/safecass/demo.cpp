// `safecass demo`: the core model at work on a three-component robot, in simulated time.
// JR3 (force sensor) provides ForceData to CONTROL, which provides Command to SERVO. The force
// crosses its limit, the error propagates JR3 → CONTROL → SERVO, CONTROL's loop switches to its
// error handler (dispatch), and everything recovers when the force drops again.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "commands.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"
#include "safecass/introspect/format.hpp"

namespace safecass::tools {

namespace {

template <class T>
T must(Expected<T> r) {
  if (!r) {
    std::fprintf(stderr, "demo: %s\n", r.error().message.c_str());
    std::exit(2);
  }
  return *r;
}

}  // namespace

int run_demo() {
  SimulatedClock clock;
  Coordinator co("robot", &clock);

  const ComponentId jr3 = must(co.add_component("JR3"));
  const ComponentId control = must(co.add_component("CONTROL"));
  const ComponentId servo = must(co.add_component("SERVO"));
  must(co.add_provided(jr3, "ForceData"));
  must(co.add_required(control, "ForceData"));
  must(co.add_provided(control, "Command"));
  must(co.add_required(servo, "Command"));
  must(co.connect("CONTROL.ForceData", "JR3.ForceData"));
  must(co.connect("SERVO.Command", "CONTROL.Command"));

  EventDef force{
      "EVT_FORCE_ERROR", 50, {Transition::N2E, Transition::W2E}, "", false, "H-3", "force on the tool above its limit"};
  EventDef force_clear{"/EVT_FORCE_ERROR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""};
  EventDef high{"EVT_FORCE_HIGH", 30, {Transition::N2W}, "", false, "H-3", "force approaching its limit"};
  EventDef high_clear{"/EVT_FORCE_HIGH", 30, {Transition::W2N}, "", false, "", ""};
  const EventId force_on = must(co.add_event(force));
  const EventId force_off = must(co.add_event(force_clear));
  const EventId high_on = must(co.add_event(high));
  const EventId high_off = must(co.add_event(high_clear));

  const MachineId jr3_app = co.structure().application_machine(jr3);
  const NameId filter = co.intern("force_limit");
  const NameId signal = co.intern("JR3.ForceNorm");

  std::printf("SAFECASS core demo: JR3 (force sensor) -> CONTROL -> SERVO, simulated time, 1 ms period\n");
  std::printf("Force limit 30 N (error), 25 N (warning). The force ramps 0 -> 40 N and back.\n\n");

  co.subscribe([&co](const Record& r) {
    if (r.kind == RecordKind::Transition) {
      std::printf("  t=%.3f s  %-24s %s -> %s  (%s)\n", to_seconds(r.time),
                  co.structure().address_of(r.machine).c_str(), std::string(to_string(r.from)).c_str(),
                  std::string(to_string(r.to)).c_str(), co.structure().event(r.event).name.c_str());
    }
  });

  std::string last_mode;
  bool explained = false;
  for (int tick = 0; tick <= 800; ++tick) {
    clock.set(Time{std::chrono::milliseconds(tick)});
    const double t = tick * 1e-3;
    const double f = t < 0.4 ? 100.0 * t : 100.0 * (0.8 - t);  // triangle, peak 40 N at 0.4 s
    SampleCause cause{filter, signal, f, clock.now(), false};
    // The detection half, written by hand here; the filters module does this from a spec.
    if (f > 30.0)
      co.generate(force_on, jr3_app, cause);
    else
      co.generate(force_off, jr3_app, cause);
    if (f > 25.0)
      co.generate(high_on, jr3_app, cause);
    else
      co.generate(high_off, jr3_app, cause);

    // CONTROL's loop, split as in the paper: one handler per extended state.
    std::string mode;
    co.dispatch(
        control, [&] { mode = "run_normal: sending the next goal to SERVO"; },
        [&](const Event& e) { mode = "run_warning (" + e.name + "): moving slowly"; },
        [&](const Event& e) { mode = "run_error (" + e.name + "): motion frozen"; });
    if (mode != last_mode) {
      std::printf("  t=%.3f s  CONTROL loop: %s\n", t, mode.c_str());
      last_mode = mode;
    }
    if (!explained && co.extended(servo).state == State::Error) {
      explained = true;
      std::printf("\n  Why is SERVO in Error? explain(\"SERVO\"):\n");
      const std::vector<Explanation> why = must(explain(co, "SERVO"));
      for (const Explanation& e : why)
        std::printf("    %s\n", introspect::explanation_text(e, introspect::TimeFormat{}).c_str());
      std::printf("\n");
    }
  }
  const bool recovered = co.coordinator_state() == State::Normal;
  std::printf("\nSystem state at the end: %s\n", std::string(to_string(co.coordinator_state())).c_str());
  return recovered && explained ? 0 : 1;
}

}  // namespace safecass::tools
