#include "filter_fixture.hpp"

namespace safecass::test {
namespace {

using ThresholdExample = FilterFixture;

TEST_F(ThresholdExample, EdgeThresholdRaisesOnceAndClearsOnReturn) {
  Signal* x = signal("x");
  Filter* f = make("Threshold",
                   {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}});
  feed(x, f, 0.001, 5);
  feed(x, f, 0.002, 11);
  feed(x, f, 0.003, 12);
  EXPECT_EQ(app_state(), State::Error);
  feed(x, f, 0.004, 9);
  EXPECT_EQ(app_state(), State::Normal);
  EXPECT_EQ(events_, (std::vector<std::string>{"EVT_X", "/EVT_X"}));
  EXPECT_DOUBLE_EQ(values_[0], 11);
}

}  // namespace
}  // namespace safecass::test
