#pragma once
// The filters of one run group (a component's ACTIVE filters, or the monitor's PASSIVE ones) and
// how they run: filter banks (DESIGN §3, docs/filters.md "Filter banks"). Internal to the filters
// module: the monitor owns one per group.
//
// A group runs its filters in creation order, as steps. A step is either one filter run as an
// object (Filter::run), or a *reader*: consecutive built-in filters of a bankable type that read
// one signal, or a *pair*: consecutive Deadlines that read one start and one end signal. A reader
// reads each new sample of its signal once (a pair merges the new samples of its two in time
// order once) and hands it to each of its filters in turn; their state lives in one array per
// type (the banks), and they are run by a switch over their type, not a virtual call. A filter object is touched only
// when it has an event to raise, a non-finite or injected sample to judge, or a detour (disabled, shallow injection):
// then that filter runs its samples through the object path until it is level with the reader
// again. Same filters, same order, same samples: the events, values and times are those of the
// filters run one by one.

#include <atomic>
#include <cstdint>
#include <deque>
#include <vector>

#include "builtin/banked.hpp"
#include "safecass/filters/filter.hpp"

namespace safecass::detail {

class Banks {
public:
  /// `banking` false: every filter runs as an object (the reference the differential test
  /// compares the banks with). `runs`: the runs a group it replaces had begun (Monitor::regroup).
  explicit Banks(bool banking, std::uint64_t runs = 0) : banking_(banking), runs_(runs) {}
  Banks(const Banks&) = delete;
  Banks& operator=(const Banks&) = delete;

  /// Appends a filter to the group, after those added before (configuration time; allocates). A
  /// bankable filter's state moves into its bank.
  void add(Filter* filter);
  /// Runs every filter of the group once, in creation order. Lock-free and allocation-free unless
  /// an event fires; call from one thread.
  void run(Time now) noexcept;
  /// Makes every banked filter's own cursor read on from where its reader stands (before the
  /// filters join another group).
  void settle() noexcept;
  std::size_t size() const noexcept { return size_; }
  /// The runs done: every filter of the group runs in each (Filter::facts()).
  std::uint64_t runs() const noexcept { return runs_.load(std::memory_order_relaxed); }
  /// Filters whose state is in a bank (for tests and docs).
  std::size_t banked() const noexcept { return members_.size(); }

private:
  enum class Kind : std::uint8_t { Threshold, Watchdog, Average, VectorAverage, Debounce, Frequency, Norm, Deadline };
  struct Member {
    Filter* filter = nullptr;
    std::uint32_t index = 0;   ///< its state in the array of its kind
    std::uint32_t reader = 0;  ///< the reader of its signal (a Deadline: its pair)
    Kind kind = Kind::Threshold;
    bool out = false;       ///< runs as an object until level with its reader and without a detour
    bool slow = false;      ///< its input is marked invalid: samples go through Filter::deliver
    bool reported = false;  ///< Filter::detected() as of its last report
  };
  struct Reader {
    SignalCursor cursor;
    ReadFacts facts;          ///< what it publishes of its reads (Filter::facts()), next to what a read touches
    std::uint32_t begin = 0;  ///< its members: [begin, end) of members_
    std::uint32_t end = 0;
    std::uint32_t width = 1;  ///< doubles per sample
    bool source = true;       ///< no filter of the group writes its signal: it can be read ahead
    std::uint32_t first = 0;  ///< the first reader of the same signal (itself if none before)
    bool taken = false;       ///< read ahead (a scalar): this run's one sample is `time`, `value`
    Time time{};
    double value = 0.0;
  };
  /// Consecutive Deadlines of one start and one end signal that read both from the same samples
  /// on. The new samples of the two are merged in time order (ties: the start first), as a
  /// Deadline run as an object merges them.
  struct Pair {
    SignalCursor cursors[2];  ///< start, end: the Deadline's inputs 0 and 1
    ReadFacts facts;          ///< what it publishes of its reads
    std::uint32_t begin = 0;  ///< its members: [begin, end) of members_
    std::uint32_t end = 0;
  };
  struct Step {
    Filter* object = nullptr;  ///< a filter run as an object, or nullptr: readers_[reader] or pairs_[reader]
    std::uint32_t reader = 0;
    bool pair = false;
  };
  /// The ring of a banked filter's state (MovingAverage's samples, with a vector's sums and means;
  /// Frequency's intervals), kept in rings_ after the others'.
  struct Ring {
    Kind kind;
    std::uint32_t index;
    std::uint32_t offset;
  };

  bool bankable(Filter& filter, Kind& kind) const noexcept;
  /// Whether something takes `filter` out of its bank: disabled, re-enabled, a shallow injection
  /// queued or just ended (several inputs is not a detour: a pair merges them).
  static bool detoured(const Filter& filter) noexcept {
    return (filter.detour_.load(std::memory_order_acquire) & ~Filter::kSeveralInputs) != 0;
  }
  /// A step for a new reader of `filter`'s input, or a new pair of its two; its buffers grown.
  void add_reader(Filter& filter);
  void add_pair(Filter& filter);
  /// Grows the buffers of a read to hold `samples` samples of up to `width` doubles.
  void reserve_read(std::size_t samples, std::size_t width);
  /// Whether `filter`'s own cursors stand where its reader's (or pair's) do.
  bool level(const Member& m) const noexcept;
  /// Makes `filter`'s own cursors read on from where its reader's (or pair's) stand.
  void hand_over(Member& m) noexcept;
  void adopt(Member& member);
  /// Moves `member`'s state, `get(filter)`, into `bank`.
  template <class State, class Get>
  State& place(Member& member, std::vector<State>& bank, Get get);
  void keep_ring(const Member& member, double* ring, std::size_t length);
  double*& ring_of(const Ring& ring) noexcept;
  [[gnu::cold]] void refresh() noexcept;
  /// Its seat (in seats_), through the filter: members_ stays small, the run reads it.
  static BankSeat& seat_of(const Member& m) noexcept { return *m.filter->cold_->seat; }
  /// Points each member's seat at its reader's (or pair's) facts again: they moved with readers_
  /// or pairs_ (configuration only).
  void reseat() noexcept;
  const ReadFacts* read_facts(const Member& m) const noexcept {
    return m.kind == Kind::Deadline ? &pairs_[m.reader].facts : &readers_[m.reader].facts;
  }
  /// `m` enters (or leaves) its bank: where its newest sample is read changes (Filter::facts()).
  void enter(Member& m) noexcept;
  void leave(Member& m) noexcept;
  /// This run's new samples of `reader`'s signal into times_, values_, injected_ and finite_; the
  /// last noted in the reader's facts, before the filters of the read run (one that enters the
  /// bank in this run has judged this read itself).
  [[gnu::always_inline]] inline std::size_t read(Reader& reader) noexcept;
  [[gnu::always_inline]] inline void run_reader(Reader& reader, Time now) noexcept;
  /// This run's new samples of `pair`'s two signals, merged, into times_, values_, inputs_,
  /// injected_ and finite_; the last noted in the pair's facts.
  std::size_t read_pair(Pair& pair) noexcept;
  void run_pair(Pair& pair, Time now) noexcept;
  [[gnu::cold]] void run_out(Member& m, Time now) noexcept;
  /// Hands each sample of this read that the bank judges to `judge(j)`, the others to the object.
  template <class Judge>
  [[gnu::always_inline]] void each_sample(Member& m, std::size_t samples, Judge&& judge) noexcept {
    for (std::size_t j = 0; j < samples; ++j) {
      if (judged_here(m, j)) {
        judge(j);
      } else {
        deliver(m, j);
      }
    }
  }
  /// Sample `j` of this read, of the filter's input `input`, through the object path
  /// (non-finite, injected, or the input marked).
  [[gnu::cold]] void deliver(Member& m, std::size_t j, std::size_t input = 0) noexcept;
  /// Stores `s` as sample `samples` of this read (width_ doubles apart) and counts it; false, and
  /// nothing written, when the buffers are full (a writer outran the read).
  [[gnu::always_inline]] inline bool store_sample(std::size_t& samples, const SampleView& s, bool& plain) noexcept;
  /// Counts samples lost (overwritten, or not kept) as missed by the filters of [begin, end)
  /// still in the bank.
  [[gnu::cold]] void add_missed(std::uint32_t begin, std::uint32_t end, std::uint64_t lost) noexcept;
  [[gnu::cold]] void report(Member& m, bool detected, double value, Time time, std::size_t input = 0) noexcept {
    others_ran_ = true;  // the event's observers and callbacks
    m.filter->report(detected, value, time, input);
    m.reported = m.filter->detected();
  }
  bool judged_here(const Member& m, std::size_t j) const noexcept {
    return !m.slow && (plain_ || (injected_[j] == 0 && finite_[j] != 0));
  }
  const double* sample(std::size_t j) const noexcept { return &values_[j * width_]; }

  bool banking_;
  std::size_t size_ = 0;
  std::vector<Step> steps_;
  std::vector<const Signal*> written_;  ///< the outputs of the group's filters
  std::vector<Reader> readers_;
  std::vector<Pair> pairs_;
  std::vector<Member> members_;
  std::deque<BankSeat> seats_;          ///< per member, read by Filter::facts() (a deque: they never move)
  std::atomic<std::uint64_t> runs_{0};  ///< runs done
  std::vector<builtin::ThresholdState> thresholds_;
  std::vector<builtin::WatchdogState> watchdogs_;
  std::vector<builtin::AverageState> averages_;
  std::vector<builtin::VectorAverageState> vector_averages_;
  std::vector<builtin::DebounceState> debounces_;
  std::vector<builtin::FrequencyState> frequencies_;
  std::vector<builtin::NormState> norms_;
  std::vector<builtin::DeadlineState> deadlines_;
  std::vector<double> rings_;
  std::vector<Ring> ring_list_;
  // The samples of the current read, for every filter of the reader in turn.
  std::vector<Time> times_;
  std::vector<double> values_;  ///< width_ doubles per sample
  std::vector<char> injected_;
  std::vector<char> finite_;
  std::vector<char> inputs_;  ///< a pair's read: 0 (start) or 1 (end)
  std::size_t width_ = 1;     ///< doubles per sample in values_
  bool plain_ = true;         ///< every sample of the current read is finite and not injected
  /// Code other than the banks' (an object filter, an event's observers and callbacks) ran on
  /// this thread during this run, so it may have written a signal read ahead.
  bool others_ran_ = false;
  std::atomic<std::uint32_t> changes_{0};  ///< bumped by a member's set_enabled() and inject()
  std::uint32_t seen_ = 0;
};

}  // namespace safecass::detail
