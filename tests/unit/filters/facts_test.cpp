// A filter's run-time facts (docs/filters.md, "Run-time facts"): enabled, injected, the newest
// sample judged and the runs so far, the same whether the filter runs as an object or in a bank
// (the bank's differential test compares them over random systems too: bank_test.cpp).

#include <atomic>
#include <limits>
#include <thread>

#include "filter_fixture.hpp"

namespace safecass::test {
namespace {

/// The facts as one line, for comparisons whose failure says what differs.
std::string text(const FilterFacts& f) {
  return std::string(f.enabled ? "enabled" : "disabled") + (f.injected ? " injected" : "") +
         " last=" + (f.last_sample ? std::to_string(f.last_sample->count()) : "-") +
         " runs=" + std::to_string(f.evaluations);
}
std::string text(bool enabled, bool injected, std::optional<Time> last, std::uint64_t runs) {
  return text(FilterFacts{enabled, injected, last, runs});
}

class FilterFactsTest : public FilterFixture, public ::testing::WithParamInterface<bool> {
protected:
  FilterFactsTest() : monitor_(co_, registry_, Monitor::kDefaultSignalHistory, GetParam()) {
    input_ = *monitor_.add_signal("C.x");
    FilterConfig c;
    c.type = "Threshold";
    c.name = "limit";
    c.target.component = "C";
    c.params = {{"input_signal", std::string("x")}, {"threshold", 10.0}, {"event_onset", std::string("EVT_X")}};
    filter_ = *monitor_.add_filter(std::move(c));
    EXPECT_EQ(monitor_.banked_count(), GetParam() ? 1U : 0U);
  }

  /// Writes `value` at `ms` (when there is one) and runs the component's filters.
  void cycle(std::int64_t ms, std::optional<double> value = std::nullopt) {
    const Time t = std::chrono::milliseconds(ms);
    if (value) input_->push(t, *value);
    clock_.set(t);
    monitor_.run_active(component_, t);
  }

  Monitor monitor_;  // hides the fixture's: this one banks or not, as the parameter says
  Signal* input_ = nullptr;
  Filter* filter_ = nullptr;
};

TEST_P(FilterFactsTest, AFilterThatHasJudgedNoSampleHasNoLastSampleAndEachRunIsAnEvaluation) {
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::nullopt, 0));
  cycle(1);
  cycle(2);
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::nullopt, 2));
  cycle(3, 1.0);
  cycle(4, 2.0);
  cycle(5);
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::chrono::milliseconds(4), 5));
}

TEST_P(FilterFactsTest, ARunWhileDisabledIsNoEvaluationAndItsSamplesAreNotJudged) {
  cycle(1, 1.0);
  filter_->set_enabled(false);
  cycle(2, 2.0);
  cycle(3, 3.0);
  EXPECT_EQ(text(filter_->facts()), text(false, false, std::chrono::milliseconds(1), 1));
  filter_->set_enabled(true);
  cycle(4);  // the samples it missed while disabled are dropped, not judged
  cycle(5, 5.0);
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::chrono::milliseconds(5), 3));
}

TEST_P(FilterFactsTest, AQueuedShallowInjectionMarksTheFilterInjectedUntilRealityIsJudgedAgain) {
  cycle(1, 1.0);
  ASSERT_TRUE(monitor_.inject_shallow("limit", {{20.0}, {20.0}}));
  EXPECT_TRUE(filter_->facts().injected) << "queued";
  cycle(2, 2.0);
  EXPECT_TRUE(filter_->facts().injected) << "one injected sample judged, one queued";
  cycle(3);
  EXPECT_TRUE(filter_->facts().injected) << "the last injected sample is the newest judged";
  cycle(4);  // the end of the injection: the real newest sample is judged again, at the run's time
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::chrono::milliseconds(4), 4));
}

TEST_P(FilterFactsTest, ADeepInjectionMarksTheFilterInjectedUntilANewerRealSampleIsJudged) {
  cycle(1, 1.0);
  ASSERT_TRUE(monitor_.inject_deep("C.x", {{2.0}}, std::chrono::milliseconds(2)));
  cycle(2);
  EXPECT_EQ(text(filter_->facts()), text(true, true, std::chrono::milliseconds(2), 2));
  cycle(3, 3.0);
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::chrono::milliseconds(3), 3));
}

TEST_P(FilterFactsTest, ANonFiniteSampleIsJudgedAndIsTheNewestSample) {
  cycle(1, 1.0);
  cycle(2, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(filter_->facts().last_sample, std::chrono::milliseconds(2));
  cycle(3, 3.0);
  EXPECT_EQ(text(filter_->facts()), text(true, false, std::chrono::milliseconds(3), 3));
}

TEST_P(FilterFactsTest, AnotherThreadReadsFactsThatNeverGoBackWhileTheFilterRunsEntersAndLeavesItsBank) {
  // The filter is disabled and enabled again now and then (it leaves its bank and comes back):
  // a reader on another thread sees its runs and its newest sample only ever grow.
  std::atomic<bool> done{false};
  std::atomic<int> backwards{0};
  std::thread reader([&] {
    std::uint64_t runs = 0;
    std::int64_t last = std::numeric_limits<std::int64_t>::min();
    while (!done.load()) {
      const FilterFacts f = filter_->facts();
      const std::int64_t t = f.last_sample ? f.last_sample->count() : std::numeric_limits<std::int64_t>::min();
      if (f.evaluations < runs || t < last) backwards.fetch_add(1);
      runs = f.evaluations;
      last = t;
    }
  });
  for (std::int64_t ms = 1; ms <= 2990; ++ms) {
    if (ms % 50 == 0) filter_->set_enabled(ms % 100 != 0);
    cycle(ms, 1.0);
  }
  done.store(true);
  reader.join();
  EXPECT_EQ(backwards.load(), 0);
  EXPECT_EQ(filter_->facts().last_sample, std::chrono::milliseconds(2990));
}

INSTANTIATE_TEST_SUITE_P(ObjectAndBank, FilterFactsTest, ::testing::Values(false, true),
                         [](const auto& p) { return p.param ? "InABank" : "AsAnObject"; });

}  // namespace
}  // namespace safecass::test
