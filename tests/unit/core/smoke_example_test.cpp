#include <gtest/gtest.h>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

TEST(CoreExample, ForceErrorPropagatesToTheClientAndClearsWithItsRoot) {
  SimulatedClock clock;
  Coordinator co("robot", &clock);
  const ComponentId jr3 = *co.add_component("JR3");
  const ComponentId control = *co.add_component("CONTROL");
  ASSERT_TRUE(co.add_provided(jr3, "ForceData"));
  ASSERT_TRUE(co.add_required(control, "ForceData"));
  ASSERT_TRUE(co.connect("CONTROL.ForceData", "JR3.ForceData"));
  ASSERT_TRUE(co.add_event(EventDef{"EVT_FORCE_ERROR", 50, {Transition::N2E, Transition::W2E}, "", false, "H-3", ""}));
  ASSERT_TRUE(co.add_event(EventDef{"/EVT_FORCE_ERROR", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""}));
  ASSERT_TRUE(generate(co, "EVT_FORCE_ERROR", "JR3.s_A"));
  EXPECT_EQ(co.extended(control).state, State::Error);
  const auto why = explain(co, "CONTROL");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  EXPECT_EQ((*why)[0].root.event, "EVT_FORCE_ERROR");
  EXPECT_EQ((*why)[0].root.origin, "JR3.s_A");
  ASSERT_TRUE(generate(co, "/EVT_FORCE_ERROR", "JR3.s_A"));
  EXPECT_EQ(co.extended(control).state, State::Normal);
}

}  // namespace
}  // namespace safecass
