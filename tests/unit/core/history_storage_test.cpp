// The history keeps records in a compact stored form (docs/semantics.md §8.3): what history()
// returns must be exactly what the observer stream published, field for field, whatever the ring
// has overwritten, and however records share their root causes.

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"

namespace safecass {
namespace {

using test::kFromError;
using test::kFromWarning;
using test::kToError;
using test::kToWarning;

/// Every field of two records, the texts by content, the sample value bit for bit.
void expect_same(const Record& a, const Record& b, std::size_t i) {
  SCOPED_TRACE("record " + std::to_string(i) + " (seq " + std::to_string(a.seq) + ")");
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.outcome, b.outcome);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.component, b.component);
  EXPECT_EQ(a.machine, b.machine);
  EXPECT_EQ(a.event, b.event);
  EXPECT_EQ(a.from, b.from);
  EXPECT_EQ(a.to, b.to);
  EXPECT_EQ(a.level, b.level);
  EXPECT_EQ(a.severity, b.severity);
  EXPECT_EQ(a.mirror, b.mirror);
  EXPECT_EQ(a.via, b.via);
  EXPECT_EQ(a.root.event, b.root.event);
  EXPECT_EQ(a.root.origin, b.root.origin);
  EXPECT_EQ(a.root.time, b.root.time);
  EXPECT_EQ(a.root.sample.filter, b.root.sample.filter);
  EXPECT_EQ(a.root.sample.signal, b.root.sample.signal);
  // Bit for bit, so that a NaN value stored and read back counts as equal.
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a.root.sample.value), std::bit_cast<std::uint64_t>(b.root.sample.value));
  EXPECT_EQ(a.root.sample.sample_time, b.root.sample.sample_time);
  EXPECT_EQ(a.root.sample.injected, b.root.sample.injected);
  EXPECT_EQ(a.root.remote, b.root.remote);
  EXPECT_EQ(a.root.remote_origin, b.root.remote_origin);
  EXPECT_EQ(std::string(a.text), std::string(b.text));
}

/// A chain A ← B ← C ← D (each X.in connected to the previous one's out), with a warning and an
/// error onset (the error one latched in a second pair), driven through every kind of record.
struct HistoryChain {
  SimulatedClock clock;
  Coordinator co;
  std::vector<Record> stream;
  EventId err{}, err_done{}, warn{}, warn_done{}, latched{}, latched_done{};
  MachineId a_app{};
  MachineId c_fw{};

  explicit HistoryChain(CoordinatorOptions options) : co("history", &clock, options) {
    for (const char* name : {"A", "B", "C", "D"}) {
      const ComponentId c = *co.add_component(name);
      (void)*co.add_provided(c, "out");
      (void)*co.add_required(c, "in");
    }
    for (const char* link : {"B.in|A.out", "C.in|B.out", "D.in|C.out"}) {
      const std::string s(link);
      (void)*co.connect(s.substr(0, s.find('|')), s.substr(s.find('|') + 1));
    }
    err = *co.add_event(test::onset("EVT_ERR", 50, kToError));
    err_done = *co.add_event(test::completion("/EVT_ERR", 50, kFromError));
    warn = *co.add_event(test::onset("EVT_WARN", 30, kToWarning));
    warn_done = *co.add_event(test::completion("/EVT_WARN", 30, kFromWarning));
    latched = *co.add_event(test::onset("EVT_LATCHED", 60, kToError, true));
    latched_done = *co.add_event(test::completion("/EVT_LATCHED", 60, kFromError));
    a_app = co.structure().application_machine(*co.structure().find_component("A"));
    c_fw = co.structure().framework_machine(*co.structure().find_component("C"));
    co.subscribe([this](const Record& r) { stream.push_back(r); });
  }

  /// One round: roots with and without filter data, masked, joined and override onsets, ignored
  /// completions (not active, latched), clears that propagate, an injection record and a reset.
  void round(int k) {
    SampleCause cause;
    cause.filter = co.intern("limit");
    cause.signal = co.intern("A.force");
    cause.value = 30.0 + k;
    cause.sample_time = clock.now();
    cause.injected = k % 2 == 0;
    clock.advance(std::chrono::milliseconds(1));
    co.generate(err, a_app, cause);  // raised at A.s_A, mirrored into B, C, D
    co.generate(warn, a_app);        // masked
    co.generate(warn_done, c_fw);    // ignored: not active
    clock.advance(std::chrono::milliseconds(1));
    co.generate(latched, c_fw);       // raised at C.s_F, mirrored into D
    co.generate(latched_done, c_fw);  // ignored: latched
    Record injection;
    injection.kind = RecordKind::Injection;
    injection.machine = a_app;
    injection.time = clock.now();
    injection.text = co.structure().name_of(co.intern("inject A.force " + std::to_string(k)));
    co.publish(injection);
    clock.advance(std::chrono::milliseconds(1));
    co.generate(err_done, a_app);  // cleared at A and every mirror
    ASSERT_TRUE(reset(co, "C", "operator", "round " + std::to_string(k)));
    co.generate(warn_done, a_app);
  }

  /// The records the history should hold: the newest `capacity` records of the stream that name
  /// a machine or a component (all of them here).
  std::vector<Record> newest(std::size_t capacity) const {
    const std::size_t n = std::min(capacity, stream.size());
    return std::vector<Record>(stream.end() - static_cast<std::ptrdiff_t>(n), stream.end());
  }
};

/// A history ring of exactly `n` records, whatever the model's size.
CoordinatorOptions ring_of(std::size_t n) {
  CoordinatorOptions options;
  options.history_records = n;
  options.history_per_address = 1;
  options.history_records_max = n;
  return options;
}

TEST(HistoryStorage, TheHistoryReturnsExactlyTheRecordsTheStreamPublished) {
  CoordinatorOptions options;  // the defaults: nothing is overwritten in 5 rounds
  HistoryChain chain(options);
  for (int k = 0; k < 5; ++k) chain.round(k);
  const std::vector<Record> got = chain.co.history(Address{});
  const std::vector<Record> want = chain.newest(chain.co.history_size());
  ASSERT_EQ(got.size(), want.size());
  ASSERT_GT(got.size(), 100u);
  for (std::size_t i = 0; i < got.size(); ++i) expect_same(got[i], want[i], i);
}

TEST(HistoryStorage, AfterTheRingWrapsTheNewestRecordsKeepTheirRootCausesAndTexts) {
  // A ring of 64 records overwritten many times: every root slot a kept record names must still
  // hold its own root (each record writes at most one root into a ring of the same capacity).
  HistoryChain chain(ring_of(64));
  for (int k = 0; k < 40; ++k) chain.round(k);
  ASSERT_EQ(chain.co.history_size(), 64u);
  const std::vector<Record> got = chain.co.history(Address{});
  const std::vector<Record> want = chain.newest(64);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) expect_same(got[i], want[i], i);
  // And one address's view is the same records, filtered.
  std::vector<Record> of_d;
  for (const Record& r : want) {
    if (r.machine == chain.co.structure().required_machines(*chain.co.structure().find_component("D"))[0])
      of_d.push_back(r);
  }
  const std::vector<Record> d =
      chain.co.history(chain.co.structure().required_machines(*chain.co.structure().find_component("D"))[0]);
  ASSERT_EQ(d.size(), of_d.size());
  for (std::size_t i = 0; i < d.size(); ++i) expect_same(d[i], of_d[i], i);
}

TEST(HistoryStorage, GrowingTheRingWhileTheModelIsConfiguredKeepsEveryRecordAndItsRoot) {
  // Records made while the model is still being configured survive the ring's growth.
  CoordinatorOptions options;
  options.history_records = 8;
  options.history_per_address = 4;
  HistoryChain chain(options);
  chain.round(0);
  const std::size_t before = chain.co.history_size();
  const std::vector<Record> kept = chain.co.history(Address{});
  for (int k = 0; k < 40; ++k) (void)*chain.co.add_component("X" + std::to_string(k));
  ASSERT_GT(chain.co.history_size(), before) << "the ring grew with the model";
  const std::vector<Record> got = chain.co.history(Address{});
  ASSERT_EQ(got.size(), kept.size());
  for (std::size_t i = 0; i < got.size(); ++i) expect_same(got[i], kept[i], i);
  chain.round(1);  // and the grown ring goes on storing roots correctly
  const std::vector<Record> after = chain.co.history(Address{});
  const std::vector<Record> want = chain.newest(chain.co.history_size());
  ASSERT_EQ(after.size(), want.size());
  for (std::size_t i = 0; i < after.size(); ++i) expect_same(after[i], want[i], i);
}

/// Every record records_since() gives after `seq`, read on from the last one until an answer is
/// empty, as a follower reads.
std::vector<Record> read_on(const Coordinator& co, std::uint64_t seq, std::size_t max) {
  std::vector<Record> out;
  for (;;) {
    const std::vector<Record> part = co.records_since(seq, max);
    if (part.empty()) return out;
    EXPECT_LE(part.size(), max == 0 ? std::size_t{256} : max);
    seq = part.back().seq;
    out.insert(out.end(), part.begin(), part.end());
  }
}

TEST(HistoryStorage, RecordsSinceGivesTheRecordsAfterASequenceNumberExactlyAsTheStreamPublishedThem) {
  HistoryChain chain(CoordinatorOptions{});
  for (int k = 0; k < 5; ++k) chain.round(k);
  ASSERT_GT(chain.stream.size(), 100u);
  for (const std::size_t from : {std::size_t{0}, std::size_t{1}, chain.stream.size() / 2, chain.stream.size() - 1}) {
    SCOPED_TRACE("after the record at " + std::to_string(from));
    const std::uint64_t seq = from == 0 ? 0 : chain.stream[from - 1].seq;
    const std::vector<Record> got = read_on(chain.co, seq, 7);
    const std::vector<Record> want(chain.stream.begin() + static_cast<std::ptrdiff_t>(from), chain.stream.end());
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) expect_same(got[i], want[i], i);
  }
  EXPECT_TRUE(chain.co.records_since(chain.stream.back().seq, 10).empty()) << "nothing after the newest";
}

TEST(HistoryStorage, RecordsSinceReturnsAtMostHistoryCapacityRecordsPerReadWhateverIsAsked) {
  CoordinatorOptions options;
  options.history_capacity = 16;
  HistoryChain chain(options);
  for (int k = 0; k < 3; ++k) chain.round(k);
  ASSERT_GT(chain.stream.size(), 16u);
  EXPECT_EQ(chain.co.records_since(0, 0).size(), 16u) << "0 asks for the bound";
  EXPECT_EQ(chain.co.records_since(0, 1000000).size(), 16u) << "more than the bound is the bound";
  EXPECT_EQ(chain.co.records_since(0, 5).size(), 5u);
  EXPECT_EQ(chain.co.records_since(0, 5).front().seq, chain.stream.front().seq);
}

TEST(HistoryStorage, AfterTheRingWrapsRecordsSinceStartsAtTheOldestRecordKeptSoTheReaderSeesTheLoss) {
  HistoryChain chain(ring_of(64));
  for (int k = 0; k < 40; ++k) chain.round(k);
  const std::vector<Record> want = chain.newest(64);
  const std::vector<Record> got = read_on(chain.co, chain.stream.front().seq, 10);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) expect_same(got[i], want[i], i);
  EXPECT_GT(got.front().seq, chain.stream.front().seq + 1) << "the records in between were overwritten";
}

}  // namespace
}  // namespace safecass
