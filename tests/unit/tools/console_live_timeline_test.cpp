// The timeline of a live coordinator (`safecass timeline --ice`): its records carry the root cause
// without the root's time, and the page says only what it knows.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "safecass/timeline/timeline.hpp"

namespace safecass::tools {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(LiveTimeline, ARootCauseWithoutItsTimeIsShownWithoutAMadeUpTime) {
  const std::string live =
      "{\"seq\":1,\"t\":5000.25,\"kind\":\"transition\",\"component\":\"JR3\",\"machine\":\"JR3.s_A\",\"event\":"
      "\"EVT_FORCE_ERROR\",\"from\":\"Normal\",\"to\":\"Error\",\"root\":{\"event\":\"EVT_FORCE_ERROR\",\"origin\":"
      "\"JR3.s_A\"}}\n";
  const timeline::HistoryParse parsed = timeline::parse_history(live);
  ASSERT_TRUE(parsed.errors.empty()) << parsed.errors.front().message;
  ASSERT_EQ(parsed.records.size(), 1u);
  EXPECT_TRUE(parsed.records[0].entry.root.has_value());
  EXPECT_FALSE(parsed.records[0].root_time_known);
  const std::string model = timeline::timeline_model_json(parsed.records);
  EXPECT_THAT(model, HasSubstr("root cause JR3.s_A:EVT_FORCE_ERROR"));
  EXPECT_THAT(model, Not(HasSubstr("root cause JR3.s_A:EVT_FORCE_ERROR at ")));

  const std::string recorded =
      "{\"seq\":1,\"t\":0.25,\"kind\":\"transition\",\"component\":\"JR3\",\"machine\":\"JR3.s_A\",\"event\":"
      "\"EVT_FORCE_ERROR\",\"from\":\"Normal\",\"to\":\"Error\",\"root\":{\"event\":\"EVT_FORCE_ERROR\",\"origin\":"
      "\"JR3.s_A\",\"t\":0.25}}\n";
  const timeline::HistoryParse with_time = timeline::parse_history(recorded);
  ASSERT_TRUE(with_time.errors.empty());
  EXPECT_TRUE(with_time.records[0].root_time_known);
  EXPECT_THAT(timeline::timeline_model_json(with_time.records),
              HasSubstr("root cause JR3.s_A:EVT_FORCE_ERROR at 0.25 s"));
}

}  // namespace
}  // namespace safecass::tools
