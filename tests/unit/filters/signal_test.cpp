#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "safecass/filters/signal.hpp"

namespace safecass {
namespace {

TEST(HistoryBuffer, ReadsBackWhatWasPushedWithTimeAndInjectionMark) {
  Signal s("C.force", ComponentId{0}, 3, 8);
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

TEST(SignalCursor, AKeptSampleStaysReadableWhileLaterSamplesAreReadUntilTheNextKeep) {
  Signal s("C.v", ComponentId{0}, 2, 8);
  const double a[] = {1, 2};
  const double b[] = {3, 4};
  const double c[] = {5, 6};
  s.push(Time{1}, a);
  s.push(Time{2}, b);
  s.push(Time{3}, c);
  SignalCursor cursor(&s);
  EXPECT_EQ(cursor.kept(), nullptr);
  SampleView v;
  ASSERT_TRUE(cursor.next(v));
  cursor.keep();
  ASSERT_TRUE(cursor.next(v));  // read, not kept: the kept sample is untouched
  ASSERT_TRUE(cursor.next(v));
  ASSERT_NE(cursor.kept(), nullptr);
  EXPECT_EQ((std::vector<double>(cursor.kept(), cursor.kept() + 2)), (std::vector<double>{1, 2}));
  cursor.keep();
  EXPECT_EQ((std::vector<double>(cursor.kept(), cursor.kept() + 2)), (std::vector<double>{5, 6}));
  const double staged[] = {7, 8};
  EXPECT_EQ((std::vector<double>(cursor.stage(staged), cursor.stage(staged) + 2)), (std::vector<double>{7, 8}));
  EXPECT_EQ((std::vector<double>(cursor.kept(), cursor.kept() + 2)), (std::vector<double>{5, 6}));
  cursor.forget();
  EXPECT_EQ(cursor.kept(), nullptr);
}

// A scalar's two samples live inside the cursor (not on the heap): a cursor that moves, as in a
// growing vector of cursors, must still hold its kept sample and go on reading where it stopped.
TEST(SignalCursor, AMovedCursorKeepsItsKeptSampleAndGoesOnReadingWhereItStopped) {
  for (std::size_t width : {std::size_t{1}, std::size_t{3}}) {
    Signal s("C.v", ComponentId{0}, width, 8);
    for (int k = 1; k <= 3; ++k) {
      const std::vector<double> sample(width, static_cast<double>(k));
      s.push(Time{k}, sample.data());
    }
    SignalCursor first(&s);
    SampleView v;
    ASSERT_TRUE(first.next(v));
    first.keep();                // sample 1
    ASSERT_TRUE(first.next(v));  // sample 2, read but not kept
    SignalCursor moved(std::move(first));
    ASSERT_NE(moved.kept(), nullptr) << width;
    EXPECT_EQ(std::vector<double>(moved.kept(), moved.kept() + width), std::vector<double>(width, 1.0)) << width;
    ASSERT_TRUE(moved.next(v)) << width;
    EXPECT_EQ(std::vector<double>(v.data, v.data + v.size), std::vector<double>(width, 3.0)) << width;
    moved.keep();
    SignalCursor assigned;
    assigned = std::move(moved);
    EXPECT_EQ(std::vector<double>(assigned.kept(), assigned.kept() + width), std::vector<double>(width, 3.0)) << width;
    EXPECT_FALSE(assigned.next(v)) << "every sample was read: " << width;
  }
}

TEST(HistoryBuffer, RingIsRoundedUpToAPowerOfTwoAndAllButTheSlotBeingWrittenAreReadable) {
  HistoryBuffer b(1, 1000);
  EXPECT_EQ(b.capacity(), 1023u);
}

TEST(HistoryBuffer, SlowReaderSkipsOverwrittenSamplesAndCountsThem) {
  Signal s("C.x", ComponentId{0}, 1, 4);
  SignalCursor cursor(&s);
  for (int i = 0; i < 10; ++i) s.push(Time{i}, static_cast<double>(i));
  std::vector<double> seen;
  SampleView v;
  while (cursor.next(v)) seen.push_back(v.scalar());
  EXPECT_EQ(seen, (std::vector<double>{7, 8, 9})) << "a ring of 4 keeps the newest 3 readable";
  EXPECT_EQ(cursor.missed(), 7u);
}

TEST(HistoryBuffer, LatestReturnsTheNewestSampleAndFalseWhenEmpty) {
  Signal s("C.x", ComponentId{0}, 1, 4);
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
  Signal s("C.v", ComponentId{0}, 4, 1 << 16);
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

TEST(HistoryBuffer, InjectedSamplesAreReadInTheOrderTheyWereWrittenAmongTheWriterSamples) {
  Signal s("C.x", ComponentId{0}, 1, 16);
  s.inject(Time{1}, std::vector<double>{100}.data());  // before any written sample
  s.push(Time{2}, 1.0);
  s.push(Time{3}, 2.0);
  s.inject(Time{3}, std::vector<double>{200}.data());
  s.inject(Time{3}, std::vector<double>{300}.data());
  s.push(Time{4}, 3.0);
  SignalCursor cursor(&s);
  std::vector<std::pair<double, bool>> seen;
  SampleView v;
  while (cursor.next(v)) seen.emplace_back(v.scalar(), v.injected);
  EXPECT_EQ(seen, (std::vector<std::pair<double, bool>>{
                      {100, true}, {1, false}, {2, false}, {200, true}, {300, true}, {3, false}}));
  EXPECT_EQ(s.count(), 6u);
}

TEST(HistoryBuffer, LatestIsTheNewestSampleWhetherWrittenOrInjected) {
  Signal s("C.x", ComponentId{0}, 1, 16);
  Time t{};
  double v = 0;
  bool injected = false;
  s.push(Time{1}, 1.0);
  s.inject(Time{2}, std::vector<double>{9}.data());
  ASSERT_TRUE(s.latest(t, &v, &injected));
  EXPECT_DOUBLE_EQ(v, 9);
  EXPECT_TRUE(injected);
  s.push(Time{3}, 2.0);
  ASSERT_TRUE(s.latest(t, &v, &injected));
  EXPECT_DOUBLE_EQ(v, 2);
  EXPECT_FALSE(injected);
}

TEST(HistoryBuffer, SkipToEndSkipsInjectedSamplesToo) {
  Signal s("C.x", ComponentId{0}, 1, 16);
  SignalCursor cursor(&s);
  s.push(Time{1}, 1.0);
  s.inject(Time{1}, std::vector<double>{5}.data());
  cursor.skip_to_end();
  SampleView v;
  EXPECT_FALSE(cursor.next(v));
  s.push(Time{2}, 2.0);
  ASSERT_TRUE(cursor.next(v));
  EXPECT_DOUBLE_EQ(v.scalar(), 2);
}

// Deep injection from a tool thread while the signal's writer pushes: no lock on the writer, and
// every reader still sees every sample of both, each exactly once, the writer's in order.
TEST(HistoryBuffer, InjectionFromAnotherThreadNeverRacesTheWriter) {
  constexpr int kWritten = 20000;
  constexpr int kInjected = 2000;
  Signal s("C.v", ComponentId{0}, 2, 1 << 16);
  std::atomic<bool> go{false};
  int written_seen = 0;
  int injected_seen = 0;
  int errors = 0;
  std::thread reader([&] {
    SignalCursor cursor(&s);
    while (!go.load()) std::this_thread::yield();
    double expected = 0;
    SampleView v;
    while (written_seen < kWritten || injected_seen < kInjected) {
      if (!cursor.next(v)) {
        std::this_thread::yield();
        continue;
      }
      errors += v[0] != v[1] ? 1 : 0;  // torn
      if (v.injected) {
        errors += v[0] < 0 ? 0 : 1;
        ++injected_seen;
      } else {
        errors += v[0] != expected ? 1 : 0;
        expected += 1;
        ++written_seen;
      }
    }
    errors += static_cast<int>(cursor.missed());
  });
  std::thread injector([&] {
    while (!go.load()) std::this_thread::yield();
    for (int i = 0; i < kInjected; ++i) {
      const double d = -1.0 - i;
      const double sample[] = {d, d};
      s.inject(Time{i}, sample);
    }
  });
  go = true;
  for (int i = 0; i < kWritten; ++i) {
    const double d = i;
    const double sample[] = {d, d};
    s.push(Time{i}, sample);
  }
  injector.join();
  reader.join();
  EXPECT_EQ(errors, 0);
  EXPECT_EQ(written_seen, kWritten);
  EXPECT_EQ(injected_seen, kInjected);
}

TEST(SignalRegistry, RejectsMalformedNamesZeroSizeAndSizeConflicts) {
  SignalRegistry reg;
  EXPECT_FALSE(reg.add("nodot", ComponentId{0}, 1));
  EXPECT_FALSE(reg.add("C.x", ComponentId{0}, 0));
  ASSERT_TRUE(reg.add("C.x", ComponentId{0}, 3));
  auto again = reg.add("C.x", ComponentId{0}, 3);
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, reg.find("C.x"));
  auto conflict = reg.add("C.x", ComponentId{0}, 1);
  ASSERT_FALSE(conflict);
  EXPECT_NE(conflict.error().message.find("size 3"), std::string::npos);
  EXPECT_EQ(reg.all().size(), 1u);
}

// The registry keeps its signals and their rings in arenas (docs/filters.md, "Memory layout"):
// each signal on a cache line of its own, each ring whole, across the arenas' blocks.
TEST(SignalRegistry, SignalsInItsArenasStartOnACacheLineAndEachRingKeepsItsOwnSamples) {
  SignalRegistry reg(64);
  std::vector<Signal*> signals;
  for (int i = 0; i < 600; ++i) {  // more than one block of each arena
    auto s = reg.add("C.s" + std::to_string(i), ComponentId{0}, 1 + static_cast<std::size_t>(i % 3));
    ASSERT_TRUE(s);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(*s) % 64, 0u);
    signals.push_back(*s);
  }
  for (std::size_t i = 0; i < signals.size(); ++i) {
    std::vector<double> v(signals[i]->size(), static_cast<double>(i));
    for (int k = 0; k < 100; ++k) signals[i]->push(Time{k}, v.data());  // wraps each ring
  }
  for (std::size_t i = 0; i < signals.size(); ++i) {
    EXPECT_EQ(reg.find(signals[i]->name()), signals[i]);
    for (std::uint64_t k = 100 - signals[i]->buffer().capacity(); k < 100; ++k) {
      Time t{};
      std::vector<double> out(signals[i]->size(), -1.0);
      ASSERT_TRUE(signals[i]->buffer().read(k, t, out.data()));
      EXPECT_EQ(t, Time{static_cast<Time::rep>(k)});
      EXPECT_EQ(out, std::vector<double>(signals[i]->size(), static_cast<double>(i))) << signals[i]->name();
    }
  }
}

TEST(SignalRegistry, TruncateForgetsTheLaterSignalsAndTheirNamesCanBeCreatedAgain) {
  SignalRegistry reg(16);
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(reg.add("C.a" + std::to_string(i), ComponentId{0}, 1));
  Signal* kept = reg.find("C.a7");
  kept->push(Time{1}, 7.0);
  const Signal* first_b = nullptr;
  for (int round = 0; round < 3; ++round) {  // a configuration step that fails, again and again
    for (int i = 0; i < 500; ++i) ASSERT_TRUE(reg.add("C.b" + std::to_string(i), ComponentId{0}, 2));
    // The arenas went back: each round's signals take the memory of the round before.
    if (round == 0) first_b = reg.find("C.b0");
    EXPECT_EQ(reg.find("C.b0"), first_b);
    reg.truncate(300);
    EXPECT_EQ(reg.all().size(), 300u);
    EXPECT_EQ(reg.find("C.b0"), nullptr);
    EXPECT_EQ(reg.find("C.b499"), nullptr);
  }
  auto again = reg.add("C.b0", ComponentId{0}, 1);  // another size than before: a new signal
  ASSERT_TRUE(again);
  EXPECT_EQ((*again)->size(), 1u);
  EXPECT_EQ((*again)->buffer().end(), 0u);
  EXPECT_EQ(reg.find("C.a7"), kept);
  Time t{};
  double x = 0.0;
  ASSERT_TRUE(kept->latest(t, &x));
  EXPECT_EQ(x, 7.0);
}

}  // namespace
}  // namespace safecass
