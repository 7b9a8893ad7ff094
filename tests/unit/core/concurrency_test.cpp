// DESIGN §2.5 and docs/semantics.md §9: several threads generating, resetting and reading at once.
// Operations never interleave (one plain mutex, taken once per public call); callbacks and
// observers that call back into the coordinator on the thread that holds the lock neither deadlock
// nor run outside the lock; lock-free readers always see a state that really existed. Run these
// under ThreadSanitizer (preset tsan) as well.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "core_test_support.hpp"
#include "safecass/core/coordinator.hpp"

namespace safecass {
namespace {

using test::Gcm;

constexpr int kThreads = 4;
constexpr int kRounds = 300;

/// Components C0..C3, each providing Out; C(k+1) requires C(k).Out, so a fault at C0 reaches all.
struct Chain : Gcm {
  std::vector<ComponentId> components;
  std::vector<EventId> onsets;
  std::vector<EventId> completions;
  Chain() {
    for (int k = 0; k < kThreads; ++k) {
      components.push_back(component("C" + std::to_string(k), {"Out"}, {"In"}));
      onsets.push_back(pair("EVT_F" + std::to_string(k), 50 + k, State::Error));
      completions.push_back(EventId{to_index(onsets.back()) + 1});
    }
    for (int k = 1; k < kThreads; ++k) {
      test::must(co.connect("C" + std::to_string(k) + ".In", "C" + std::to_string(k - 1) + ".Out"), "connect");
    }
  }
  MachineId app(int k) const { return co.structure().application_machine(components[static_cast<std::size_t>(k)]); }
};

TEST(Concurrency, OperationsFromSeveralThreadsNeverInterleaveAndRecordsStayInOrder) {
  Chain chain;
  Coordinator& co = chain.co;
  std::vector<std::uint64_t> seqs;
  // Records are handed out one write at a time, in order: no mutex needed.
  co.subscribe([&seqs](const Record& r) { seqs.push_back(r.seq); });
  std::vector<std::thread> threads;
  for (int k = 0; k < kThreads; ++k) {
    threads.emplace_back([&chain, k] {
      for (int i = 0; i < kRounds; ++i) {
        chain.co.generate(chain.onsets[static_cast<std::size_t>(k)], chain.app(k));
        chain.co.generate(chain.completions[static_cast<std::size_t>(k)], chain.app(k));
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int k = 0; k < kThreads; ++k) {
    EXPECT_EQ(co.extended(chain.components[static_cast<std::size_t>(k)]).state, State::Normal);
    EXPECT_TRUE(co.conditions(chain.app(k)).empty());
  }
  ASSERT_FALSE(seqs.empty());
  for (std::size_t i = 1; i < seqs.size(); ++i) ASSERT_EQ(seqs[i], seqs[i - 1] + 1) << "one stream, no gaps";
}

TEST(Concurrency, LockFreeReadersSeeOnlyStatesThatExistedWhileWritersWork) {
  Chain chain;
  Coordinator& co = chain.co;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> bad{0};
  std::atomic<std::uint64_t> reads{0};
  std::thread reader([&] {
    while (!done.load()) {
      for (int k = 0; k < kThreads; ++k) {
        const StateSnapshot s = co.extended(chain.components[static_cast<std::size_t>(k)]);
        // Normal has no outstanding event; Error has one (a fault of this chain's events).
        if ((s.state == State::Normal) != (s.outstanding == kNoEvent)) ++bad;
        if (s.state == State::Warning) ++bad;
        ++reads;
      }
    }
  });
  std::thread writer([&] {
    while (reads.load() == 0) std::this_thread::yield();  // overlap with the reader for sure
    for (int i = 0; i < kRounds; ++i) {
      co.generate(chain.onsets[0], chain.app(0));
      co.generate(chain.completions[0], chain.app(0));
    }
  });
  writer.join();
  done.store(true);
  reader.join();
  EXPECT_EQ(bad.load(), 0u);
  EXPECT_GT(reads.load(), 0u);
  EXPECT_EQ(co.coordinator_state(), State::Normal);
}

TEST(Concurrency, ObserversThatReadTheCoordinatorDoNotDeadlockWhileAnotherThreadGenerates) {
  Chain chain;
  Coordinator& co = chain.co;
  std::uint64_t explained = 0;
  std::uint64_t histories = 0;
  co.subscribe([&](const Record& r) {
    // The lock is free while observers run: reads take it as from anywhere else.
    if (r.kind == RecordKind::ComponentTransition && r.to == State::Error) {
      explained += co.explain(Address{Address::Kind::Component, r.component}).empty() ? 0 : 1;
      (void)co.resolve_root(r.root).origin;
    }
    if (r.kind == RecordKind::Transition) histories += co.history(r.machine).empty() ? 0 : 1;
    (void)co.dropped_requests();
  });
  std::vector<std::thread> threads;
  for (int k = 0; k < 2; ++k) {
    threads.emplace_back([&chain, k] {
      for (int i = 0; i < kRounds; ++i) {
        chain.co.generate(chain.onsets[static_cast<std::size_t>(k)], chain.app(k));
        chain.co.generate(chain.completions[static_cast<std::size_t>(k)], chain.app(k));
      }
    });
  }
  std::thread introspector([&] {
    for (int i = 0; i < kRounds; ++i) {
      (void)co.history(Address{});
      (void)co.explain(Address{});
      (void)co.conditions(chain.app(3));
    }
  });
  for (auto& t : threads) t.join();
  introspector.join();
  EXPECT_GT(explained, 0u);
  EXPECT_GT(histories, 0u);
  EXPECT_EQ(co.coordinator_state(), State::Normal);
}

TEST(Concurrency, EventsGeneratedByCallbacksAreQueuedWhileOtherThreadsWait) {
  Chain chain;
  Coordinator& co = chain.co;
  // Whenever C1 enters Error (only C0's fault reaches it), its callback clears the root at C0
  // (a write from a callback: queued, made before the outer call returns); another thread
  // meanwhile raises and clears C2, whose fault reaches C3.
  std::atomic<int> entered{0};
  co.on_component(chain.components[1], StateCallbacks{nullptr, nullptr, [&](State s) {
                                                        if (s != State::Error) return;
                                                        ++entered;
                                                        co.generate(chain.completions[0], chain.app(0));
                                                      }});
  std::thread other([&] {
    for (int i = 0; i < kRounds; ++i) {
      co.generate(chain.onsets[2], chain.app(2));
      co.generate(chain.completions[2], chain.app(2));
    }
  });
  for (int i = 0; i < kRounds; ++i) {
    co.generate(chain.onsets[0], chain.app(0));
    EXPECT_TRUE(co.conditions(chain.app(0)).empty()) << "the queued completion ran before generate() returned";
  }
  other.join();
  EXPECT_EQ(entered.load(), kRounds);
  EXPECT_EQ(co.dropped_requests(), 0u);
  EXPECT_EQ(co.coordinator_state(), State::Normal);
}

TEST(Concurrency, NoLockIsHeldWhileObserversAndCallbacksRunSoAnotherThreadCanReadAndWrite) {
  Chain chain;
  Coordinator& co = chain.co;
  // From inside an observer and a callback, another thread reads the history (takes the lock) and
  // raises a fault at C2 (takes the lock to make the change). Were the lock held, neither would get
  // through. Its records wait for their turn: they are handed out after the current write's.
  std::vector<std::thread> others;
  const auto another_thread_gets_through = [&](int k) {
    std::atomic<bool> read{false};
    others.emplace_back([&co, &chain, &read, k] {
      (void)co.history(Address{});
      read = true;
      co.generate(chain.onsets[static_cast<std::size_t>(k)], chain.app(k));
    });
    for (int i = 0; i < 2000 && !(read && co.state(chain.app(k)) == State::Error); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return read && co.state(chain.app(k)) == State::Error;
  };
  int observed = 0, called = 0;
  bool observer_ok = false, callback_ok = false;
  co.subscribe([&](const Record& r) {
    if (r.kind == RecordKind::ComponentTransition && r.component == chain.components[0] && r.to == State::Error) {
      ++observed;
      observer_ok = another_thread_gets_through(2);
    }
  });
  co.on_component(chain.components[1], StateCallbacks{nullptr, nullptr, [&](State s) {
                                                        if (s != State::Error || called++ > 0) return;
                                                        callback_ok = another_thread_gets_through(3);
                                                      }});
  co.generate(chain.onsets[0], chain.app(0));
  for (auto& t : others) t.join();  // their records were handed out once this write's were
  EXPECT_EQ(observed, 1);
  EXPECT_EQ(called, 1);
  EXPECT_TRUE(observer_ok) << "another thread could not read or write while an observer ran";
  EXPECT_TRUE(callback_ok) << "another thread could not read or write while a callback ran";
}

TEST(Concurrency, ResetsFromSeveralThreadsLeaveTheSystemNormal) {
  Chain chain;
  Coordinator& co = chain.co;
  std::vector<std::thread> threads;
  for (int k = 0; k < kThreads; ++k) {
    threads.emplace_back([&chain, k] {
      for (int i = 0; i < kRounds / 3; ++i) {
        chain.co.generate(chain.onsets[static_cast<std::size_t>(k)], chain.app(k));
        chain.co.reset(Address{}, "test", "thread " + std::to_string(k));
      }
    });
  }
  for (auto& t : threads) t.join();
  co.reset(Address{}, "test", "final");
  EXPECT_EQ(co.coordinator_state(), State::Normal);
}

}  // namespace
}  // namespace safecass
