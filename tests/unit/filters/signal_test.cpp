#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "safecass/filters/signal.hpp"

namespace safecass {
namespace {

TEST(HistoryBuffer, ReadsBackWhatWasPushedWithTimeAndInjectionMark) {
  Signal s("C.force", 0, 3, 8);
  const double a[] = {1, 2, 3};
  const double b[] = {4, 5, 6};
  s.push(Time{10}, a);
  s.inject(Time{20}, b);
  SignalCursor cursor(&s);
  SampleView v;
  ASSERT_TRUE(cursor.next(v));
  EXPECT_EQ(v.time, Time{10});
  EXPECT_FALSE(v.injected);
  EXPECT_EQ((std::vector<double>(v.data, v.data + v.size)), (std::vector<double>{1, 2, 3}));
  ASSERT_TRUE(cursor.next(v));
  EXPECT_TRUE(v.injected);
  EXPECT_DOUBLE_EQ(v[2], 6);
  EXPECT_FALSE(cursor.next(v));
}

TEST(HistoryBuffer, CapacityIsRoundedUpToAPowerOfTwo) {
  HistoryBuffer b(1, 1000);
  EXPECT_EQ(b.capacity(), 1024u);
}

TEST(HistoryBuffer, SlowReaderSkipsOverwrittenSamplesAndCountsThem) {
  Signal s("C.x", 0, 1, 4);
  SignalCursor cursor(&s);
  for (int i = 0; i < 10; ++i) s.push(Time{i}, static_cast<double>(i));
  std::vector<double> seen;
  SampleView v;
  while (cursor.next(v)) seen.push_back(v.scalar());
  EXPECT_EQ(seen, (std::vector<double>{6, 7, 8, 9}));
  EXPECT_EQ(cursor.missed(), 6u);
}

TEST(HistoryBuffer, LatestReturnsTheNewestSampleAndFalseWhenEmpty) {
  Signal s("C.x", 0, 1, 4);
  Time t{};
  double v = 0;
  EXPECT_FALSE(s.latest(t, &v));
  s.push(Time{5}, 1.5);
  s.push(Time{6}, 2.5);
  ASSERT_TRUE(s.latest(t, &v));
  EXPECT_EQ(t, Time{6});
  EXPECT_DOUBLE_EQ(v, 2.5);
}

// One writer, several readers, no locks: every reader sees every sample, in order, intact
// (each sample's elements are equal, so a torn read would show).
TEST(HistoryBuffer, ConcurrentReadersSeeEverySampleInOrderAndNeverTorn) {
  constexpr int kSamples = 20000;
  Signal s("C.v", 0, 4, 1 << 16);
  std::atomic<bool> go{false};
  std::vector<std::thread> readers;
  std::vector<int> errors(3, 0);
  std::vector<int> counts(3, 0);
  for (int r = 0; r < 3; ++r) {
    readers.emplace_back([&, r] {
      SignalCursor cursor(&s);
      while (!go.load()) std::this_thread::yield();
      double expected = 0;
      SampleView v;
      while (expected < kSamples) {
        if (!cursor.next(v)) {
          std::this_thread::yield();
          continue;
        }
        for (std::size_t i = 0; i < 4; ++i) errors[r] += v[i] != expected ? 1 : 0;
        ++counts[r];
        expected += 1;
      }
    });
  }
  go = true;
  for (int i = 0; i < kSamples; ++i) {
    const double d = i;
    const double sample[] = {d, d, d, d};
    s.push(Time{i}, sample);
  }
  for (auto& t : readers) t.join();
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(errors[r], 0);
    EXPECT_EQ(counts[r], kSamples);
  }
}

TEST(SignalRegistry, RejectsMalformedNamesZeroSizeAndSizeConflicts) {
  SignalRegistry reg;
  EXPECT_FALSE(reg.add("nodot", 0, 1));
  EXPECT_FALSE(reg.add("C.x", 0, 0));
  ASSERT_TRUE(reg.add("C.x", 0, 3));
  auto again = reg.add("C.x", 0, 3);
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, reg.find("C.x"));
  auto conflict = reg.add("C.x", 0, 1);
  ASSERT_FALSE(conflict);
  EXPECT_NE(conflict.error().message.find("size 3"), std::string::npos);
  EXPECT_EQ(reg.all().size(), 1u);
}

}  // namespace
}  // namespace safecass
