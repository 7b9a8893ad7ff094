// The research ROBODOC case study (paper §V-B) as a small in-process system.
//
// The safety features are specifications (the JSON files beside this one); the mechanisms come
// from the library. This program adds what only the application knows: CONTROL's loop, split
// into run_normal / run_warning / run_error and chosen every cycle by dispatch() on CONTROL's
// extended state, and SERVO's loop. A scenario (story.json) drives the sensors in simulated time.
//
// Usage: robodoc_demo [SCENARIO] [HISTORY_FILE]

#include <cstdio>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"

using namespace safecass;

namespace {

std::string secs(Time t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%6.3f s", to_seconds(t));
  return buf;
}

/// CONTROL's control loop, as in the paper: one handler per extended state.
class ControlTask {
public:
  explicit ControlTask(Coordinator& co) : co_(co), id_(*co.structure().find_component("CONTROL")) {}

  void operator()(Time now) {
    co_.dispatch(
        id_, [&] { run_normal(now); }, [&](const Event& e) { run_warning(now, e); },
        [&](const Event& e) { run_error(now, e); });
  }

private:
  void run_normal(Time now) {
    // Read the force (no error check needed: SAFECASS propagates JR3's faults to us), compute
    // the next goal, send it to SERVO.
    say(now, "run_normal: cutting along the planned path");
  }
  void run_warning(Time now, const Event& e) { say(now, "run_warning (" + e.name + "): cutting at reduced feed rate"); }
  void run_error(Time now, const Event& e) {
    // The error handlers for each event of the specification.
    if (e.name == "EVT_CONTROL_FORCE_FREEZE") {
      say(now, "run_error (EVT_CONTROL_FORCE_FREEZE): excessive-force handling, motion frozen");
    } else {
      say(now, "run_error (" + e.name + "): motion frozen, holding position");
    }
  }
  void say(Time now, const std::string& mode) {
    if (mode == mode_) return;
    mode_ = mode;
    std::printf("%s  CONTROL loop -> %s\n", secs(now).c_str(), mode.c_str());
  }

  Coordinator& co_;
  ComponentId id_;
  std::string mode_;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string scenario_path = argc > 1 ? argv[1] : "examples/robodoc/story.json";
  const std::string history_path = argc > 2 ? argv[2] : "";

  const FilterRegistry& registry = builtin_filters();
  auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{scenario_path, ""}, registry);
  if (!opened) {
    spec::print(opened.error(), stderr);
    return 2;
  }
  runner::ScenarioRunner& run = **opened;
  Coordinator& co = run.coordinator();
  ControlTask control(co);
  (void)run.runtime().set_body(*co.structure().find_component("CONTROL"), [&control](Time now) { control(now); });

  std::printf("ROBODOC, simulated: JR3 force sensor and bone motion monitor -> CONTROL -> SERVO, pendant.\n");
  std::printf("Safety features: force warning 25 N and limit 30 N on JR3, bone motion 1 mm on BMM (latched),\n");
  std::printf("a 50 ms watchdog on the force driver, a tracking-error warning on CONTROL.\n\n");

  // The story: every change of a component's extended state, with the reason.
  co.subscribe([&co](const Record& r) {
    if (r.kind == RecordKind::Reset && r.from != State::Normal) {
      std::printf("%s  %s reset by %s\n", secs(r.time).c_str(), co.structure().address_of(r.machine).c_str(),
                  std::string(r.text).c_str());
    }
    if (r.kind != RecordKind::ComponentTransition) return;
    const std::string name(co.structure().component_name(r.component));
    std::printf("%s  %-8s %s -> %s", secs(r.time).c_str(), name.c_str(), std::string(to_string(r.from)).c_str(),
                std::string(to_string(r.to)).c_str());
    if (r.to > r.from && r.root.event != kNoEvent) {
      std::printf("   because %s:%s", co.structure().address_of(r.root.origin).c_str(),
                  co.structure().event(r.root.event).name.c_str());
      if (r.root.sample.filter != kNoName) {
        std::printf(" (filter %s judged %s: %.2f)", std::string(co.structure().name_of(r.root.sample.filter)).c_str(),
                    std::string(co.structure().name_of(r.root.sample.signal)).c_str(), r.root.sample.value);
      }
      const std::string& hazard = co.structure().event(r.root.event).hazard;
      if (!hazard.empty()) std::printf(" [hazard %s]", hazard.c_str());
    }
    std::printf("\n");
    if (name == "SERVO" && r.to == State::Error) {
      // Why are the servos stopped? explain() gives each root cause and the path it took.
      for (const Explanation& e : co.explain(Address{Address::Kind::Component, r.component})) {
        std::printf("           explain(SERVO): %s:%s via", e.root.origin.c_str(), e.root.event.c_str());
        for (const std::string& hop : e.path) std::printf(" %s%s", hop == e.path.front() ? "" : "-> ", hop.c_str());
        std::printf("\n");
      }
    }
  });

  runner::RunOptions options;
  options.quiet = true;
  options.record_path = history_path;
  const runner::RunResult result = run.run(options);

  std::printf("\nScenario %s: %d expectations checked, %zu failed.\n", run.scenario().path.c_str(), result.checks,
              result.failures.size());
  for (const std::string& f : result.failures) std::printf("  %s\n", f.c_str());
  if (!history_path.empty())
    std::printf("The whole history (every event, transition, reset) is in %s\n", history_path.c_str());
  if (result.inputs) {
    std::printf("What the system was fed is in %s (safecass replay feeds it through a changed spec)\n",
                result.inputs->path.c_str());
  }
  // Nothing lost silently: a recording with a write error or dropped records is said and fails the run.
  if (result.inputs) {
    for (const std::string& loss : describe_losses(*result.inputs))
      std::fprintf(stderr, "robodoc_demo: %s\n", loss.c_str());
  }
  if (result.record) {
    for (const std::string& loss : describe_losses(*result.record))
      std::fprintf(stderr, "robodoc_demo: %s\n", loss.c_str());
  }
  if (!result.history_complete()) return 2;
  return result.passed() ? 0 : 1;
}
