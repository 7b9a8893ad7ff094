// An application outside the SAFECASS tree. It loads the gripper's safety specification, runs the
// gripper's monitoring task in simulated time, pushes force samples, and every cycle lets
// dispatch() choose its normal, warning or error handler from the gripper's state. The application
// never compares the force with a limit itself: the specification does.
//
// Usage: gripper_consumer SPEC
// Exit code: 0 when the handlers ran in the expected order, 1 otherwise, 2 when SPEC is invalid.

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "safecass/native/runtime.hpp"
#include "safecass/spec/instance.hpp"

using namespace safecass;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gripper_consumer SPEC\n");
    return 2;
  }
  SimulatedClock clock;
  spec::InstanceOptions options;
  options.name = "gripper_cell";
  options.clock = &clock;
  spec::Diagnostics notes;
  auto opened = spec::open_instance(argv[1], builtin_filters(), options, &notes);
  spec::print(notes, stderr);
  if (!opened) {
    spec::print(opened.error(), stderr);
    return 2;
  }
  Coordinator& co = (*opened)->coordinator();
  Monitor& monitor = (*opened)->monitor();
  const auto gripper = co.structure().find_component("GRIPPER");
  Signal* force = monitor.signals().find("GRIPPER.Force");
  if (!gripper || force == nullptr) {
    std::fprintf(stderr, "%s: no component GRIPPER with signal Force\n", argv[1]);
    return 2;
  }
  native::Runtime runtime(monitor);
  if (auto task = runtime.add_task(*gripper, std::chrono::milliseconds(1)); !task) {
    std::fprintf(stderr, "%s\n", task.error().message.c_str());
    return 2;
  }

  // The grip force rises to 70 N and falls back; the handler chosen each cycle is recorded when
  // it changes.
  std::vector<std::string> handlers;
  auto note = [&handlers](const std::string& h) {
    if (handlers.empty() || handlers.back() != h) handlers.push_back(h);
  };
  for (int ms = 0; ms <= 280; ++ms) {
    const Time now = std::chrono::milliseconds(ms);
    clock.set(now);
    force->push(now, ms <= 140 ? ms * 0.5 : (280 - ms) * 0.5);  // 0 -> 70 N -> 0
    runtime.step(now);
    co.dispatch(
        *gripper, [&] { note("normal"); }, [&](const Event& e) { note("warning " + e.name); },
        [&](const Event& e) { note("error " + e.name); });
  }

  const std::vector<std::string> expected = {"normal", "warning EVT_GRIP_HIGH", "error EVT_GRIP_CRUSH",
                                             "warning EVT_GRIP_HIGH", "normal"};
  for (const std::string& h : handlers) std::printf("%s\n", h.c_str());
  if (handlers != expected) {
    std::fprintf(stderr, "gripper_consumer: unexpected handler sequence\n");
    return 1;
  }
  std::printf("gripper_consumer: handlers ran as the specification says\n");
  return 0;
}
