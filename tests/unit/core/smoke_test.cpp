#include <gtest/gtest.h>
#include "safecass/core/coordinator.hpp"
using namespace safecass;
TEST(Smoke, ForceErrorPropagates) {
  SimulatedClock clock;
  Coordinator co("robot", &clock);
  auto jr3 = *co.add_component("JR3");
  auto control = *co.add_component("CONTROL");
  ASSERT_TRUE(co.add_provided(jr3, "ForceData"));
  ASSERT_TRUE(co.add_required(control, "ForceData"));
  ASSERT_TRUE(co.connect("CONTROL.ForceData", "JR3.ForceData"));
  EventDef on{"EVT_FORCE_ERROR", 50, {Transition::N2E, Transition::W2E}, "", false, "H-3", ""};
  EventDef off{"/EVT_FORCE_ERROR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""};
  ASSERT_TRUE(co.add_event(on));
  ASSERT_TRUE(co.add_event(off));
  ASSERT_TRUE(co.generate("EVT_FORCE_ERROR", "JR3.s_A"));
  EXPECT_EQ(co.extended_state(control), State::Error);
  auto ex = co.explain("CONTROL");
  ASSERT_TRUE(ex);
  for (auto& e : *ex) std::cout << to_string(e) << "\n";
  ASSERT_TRUE(co.generate("/EVT_FORCE_ERROR", "JR3.s_A"));
  EXPECT_EQ(co.extended_state(control), State::Normal);
}
