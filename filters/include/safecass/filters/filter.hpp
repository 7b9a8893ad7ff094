#pragma once
/// @file filter.hpp
/// The filter base (DESIGN §3). A filter reads input signals, may write output signals, and
/// generates onset/completion events to a target state machine.
///
/// Filter authors derive from Filter, publish a static `manifest()` and implement the protected
/// hooks:
/// - `on_sample(input, sample)`: one new sample of input `input` (in order, none skipped unless
///   the history buffer overflowed);
/// - `on_tick(now)`: once per run, after the new samples (timing filters: Watchdog, Deadline);
///   an override must not call the default (it is private: the default stops the calls);
/// - `on_reset()`: forget internal state.
/// They call `report(detected, value, sample_time)` to turn a detection into events according to
/// the detection mode, and `write(output, time, values)` to feed output signals.
///
/// Lifecycle: created by Monitor::add_filter (parameters checked, inputs resolved, nothing half
/// built on error) → run() repeatedly from one thread (the component's loop for ACTIVE, the
/// monitor thread for PASSIVE) → destroyed with the monitor. run() without a detection takes no
/// lock and allocates nothing. A non-finite input sample is never passed to on_sample: it raises
/// EVT_INVALID_SAMPLE on the target component's s_F until a finite sample arrives on that input
/// (with several inputs: on every input whose last sample was not finite).

#include <atomic>
#include <cmath>
#include <cstddef>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/filters/params.hpp"
#include "safecass/filters/signal.hpp"

namespace safecass {

/// EDGE: one onset per crossing, one completion on return. LEVEL: an onset every sample while
/// detected (the state machine refreshes), one completion on return.
enum class DetectionMode : std::uint8_t { Edge, Level };
/// ACTIVE: run in the owning component's loop. PASSIVE: run by the monitor thread.
enum class ExecutionMode : std::uint8_t { Active, Passive };

/// Where a filter's events go: `{"type": "s_A", "component": "JR3"}`.
struct FilterTarget {
  MachineKind kind = MachineKind::Application;
  std::string component;
  std::string interface;  ///< for s_P / s_R
};

/// A filter instance as written in a specification.
struct FilterConfig {
  std::string name;  ///< unique within the monitor (default: the type and an index)
  std::string type;  ///< registry name
  FilterTarget target;
  ExecutionMode execution = ExecutionMode::Active;
  DetectionMode detection = DetectionMode::Edge;
  bool enabled = true;
  Params params;
};

/// Everything a filter needs at construction, prepared by the monitor.
struct FilterInit {
  FilterConfig config;  ///< params checked and completed with defaults
  Coordinator* coordinator = nullptr;
  MachineId target = kNoMachine;
  ComponentId component = kNoComponent;
  std::vector<Signal*> inputs;   ///< resolved, in manifest order (lists expanded)
  std::vector<Signal*> outputs;  ///< resolved or created, in manifest order
  EventId onset = kNoEvent;
  EventId completion = kNoEvent;
  NameId name_id = kNoName;
};

/// What a filter has done so far, read from any thread while it runs (docs/filters.md, "Run-time
/// facts"): what `safecass analyze now` judges a hazard's coverage by.
struct FilterFacts {
  bool enabled = true;
  /// A shallow injection is queued, or the newest sample the filter judged was injected.
  bool injected = false;
  /// The time of the newest sample the filter judged, the last in its input's order (none: none).
  std::optional<Time> last_sample;
  /// The runs of its monitor's group (its component's ACTIVE filters, or the PASSIVE ones) in which it
  /// judged its inputs: a run while disabled is none.
  std::uint64_t evaluations = 0;
};

namespace detail {
class Banks;

inline constexpr std::int64_t kNoSample = std::numeric_limits<std::int64_t>::min();

/// What a bank's reader (or pair) publishes of its reads: the last sample of the last read that had
/// one, and how many such reads it made. Written by the bank's thread once per read with samples.
/// Copied only while the bank is configured (its reader moves with the bank's array).
struct ReadFacts {
  ReadFacts() = default;
  ReadFacts(const ReadFacts& other) noexcept
      : last(other.last.load(std::memory_order_relaxed)), reads(other.reads.load(std::memory_order_relaxed)) {}
  ReadFacts& operator=(const ReadFacts& other) noexcept {
    last.store(other.last.load(std::memory_order_relaxed), std::memory_order_relaxed);
    reads.store(other.reads.load(std::memory_order_relaxed), std::memory_order_relaxed);
    return *this;
  }

  /// The last sample in one word, read at once: its time (ns) times two, plus one when it was
  /// injected; kNoSample before any.
  static constexpr std::int64_t word(Time time, bool injected) noexcept {
    return time.count() * 2 + (injected ? 1 : 0);
  }
  static constexpr Time time_of(std::int64_t word) noexcept { return Time{word >> 1}; }
  static constexpr bool injected_in(std::int64_t word) noexcept { return (word & 1) != 0; }
  /// A read whose last sample is `time` (the bank's thread, the one writer).
  void note(Time time, bool injected) noexcept {
    last.store(word(time, injected), std::memory_order_relaxed);
    reads.store(reads.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  std::atomic<std::int64_t> last{kNoSample};
  std::atomic<std::uint64_t> reads{0};
};

/// Where a banked filter's newest sample is while it is in its bank: its reader's, once the reader
/// has read since the filter entered. Written by the filter's thread when it enters or leaves.
struct BankSeat {
  const ReadFacts* reader = nullptr;
  std::atomic<bool> in{false};
  std::atomic<std::uint64_t> entry_reads{0};  ///< the reader's reads when it entered
};
}  // namespace detail

class Filter {
public:
  Filter(const Filter&) = delete;
  Filter& operator=(const Filter&) = delete;

  virtual ~Filter();
  const std::string& name() const noexcept { return cold_->config.name; }
  const std::string& type() const noexcept { return cold_->config.type; }
  const FilterConfig& config() const noexcept { return cold_->config; }
  ExecutionMode execution() const noexcept { return cold_->config.execution; }
  DetectionMode detection() const noexcept { return cold_->config.detection; }
  ComponentId component() const noexcept { return cold_->component; }
  MachineId target() const noexcept { return cold_->target; }
  /// The onset it raises, or kNoEvent (a filter that only writes outputs).
  EventId onset() const noexcept { return cold_->onset; }
  const std::vector<Signal*>& inputs() const noexcept { return cold_->inputs; }
  const std::vector<Signal*>& outputs() const noexcept { return cold_->outputs; }

  bool enabled() const noexcept { return (detour_.load(std::memory_order_acquire) & kDisabled) == 0; }
  /// A disabled filter skips its runs; its unread samples are dropped when it is enabled again.
  void set_enabled(bool enabled) noexcept {
    if (enabled) {
      detour_.fetch_and(static_cast<std::uint8_t>(~kDisabled), std::memory_order_acq_rel);
    } else {
      detour_.fetch_or(kDisabled, std::memory_order_acq_rel);
    }
    tell_bank();
  }
  /// True while the filter's detection is active (an onset sent, its completion not yet).
  bool detected() const noexcept { return detected_.load(std::memory_order_acquire); }
  /// Samples lost to history-buffer overflow since creation.
  std::uint64_t missed_samples() const noexcept;
  /// Enabled, injected, the newest sample judged and the runs so far, whether it runs as an object
  /// or in a bank. Any thread; lock-free (it retries while the filter's thread changes them).
  FilterFacts facts() const noexcept;

  /// Processes the new samples of every input, then on_tick(now). Call from one thread only. A
  /// filter of a monitor is run by it (Monitor::run_active, Monitor::tick), which may run it in a
  /// bank without calling run(): do not also run it yourself.
  void run(Time now) noexcept {
    // The hot path, inlined into the caller: enabled, no shallow injection queued, one input.
    if (detour_.load(std::memory_order_acquire) != 0) {
      run_general(now);
      return;
    }
    first_.read_new([this](const SampleView& sample) noexcept { deliver(0, sample); });
    current_injected_ = false;
    if (ticks_) on_tick(now);
  }
  /// Shallow fault injection: each queued sample replaces the first input's samples for one run,
  /// seen by this filter alone. The end of the injection restores reality (DESIGN §3): the first
  /// run after the queue ran out judges the first input's newest real sample once, as a new
  /// sample, even when the signal has not changed since (a sensor that publishes only on change).
  /// Errors: those of check_injection(); then nothing is queued.
  [[nodiscard]] Expected<void> inject(const std::vector<std::vector<double>>& samples);
  /// Why inject(samples) would refuse, changing nothing: InvalidArgument when the filter has no
  /// input or a sample's size is not the first input's.
  [[nodiscard]] Expected<void> check_injection(const std::vector<std::vector<double>>& samples) const;
  /// Forgets internal state and the detection (no completion is sent: the machine is reset
  /// separately). Call from the thread that runs the filter.
  void reset() noexcept;

protected:
  explicit Filter(FilterInit init);

  virtual void on_sample(std::size_t input, const SampleView& sample) noexcept = 0;
  virtual void on_reset() noexcept {}

  /// Turns a detection into events (EDGE/LEVEL), carrying the filter, signal and value as the
  /// root cause. Takes the coordinator's lock only when an event is generated.
  void report(bool detected, double value, Time sample_time, std::size_t input = 0) noexcept {
    if (!detected && !detected_.load(std::memory_order_relaxed)) return;  // the common case: nothing to say
    report_change(detected, value, sample_time, input);
  }
  /// Writes a sample of output `output` (size doubles must match the output signal).
  void write(std::size_t output, Time time, const double* values) noexcept {
    if (Signal* s = output_signal(output)) s->push(time, values);
  }
  void write(std::size_t output, Time time, double value) noexcept { write(output, time, &value); }
  bool has_output(std::size_t output) const noexcept { return output_signal(output) != nullptr; }
  /// The newest value of input `input` seen by this filter (zero-order hold), or nullptr.
  const double* held(std::size_t input) const noexcept {
    return input < cold_->inputs.size() ? cursor(input).kept() : nullptr;
  }
  /// Whether the sample being processed was injected.
  bool current_injected() const noexcept { return current_injected_; }

  const Params& params() const noexcept { return cold_->config.params; }
  double number(std::string_view param) const;
  const std::string& text(std::string_view param) const;
  bool flag(std::string_view param) const;

private:
  friend class detail::Banks;  // runs a banked filter's samples without run() (docs/filters.md)

  /// Once per run, after the new samples: for filters that watch time (Watchdog, Deadline).
  /// The default does nothing and tells run() to stop calling it. It is private so that an
  /// override, which may be protected, cannot call it.
  virtual void on_tick(Time /*now*/) noexcept { ticks_ = false; }
  void report_change(bool detected, double value, Time sample_time, std::size_t input) noexcept;
  /// Raises (invalid) or clears EVT_INVALID_SAMPLE; `sample` is the offending one when raising:
  /// its first non-finite value is the root cause's value (an inf is reported as inf, not NaN).
  void invalid_sample(std::size_t input, const SampleView& sample, bool invalid) noexcept;
  /// One sample of input `input`, as just read (or staged) by its cursor: checked (a non-finite
  /// sample raises EVT_INVALID_SAMPLE and is not passed on), held, then handed to on_sample().
  void deliver(std::size_t input, const SampleView& sample) noexcept {
    current_injected_ = sample.injected;  // also marks an EVT_INVALID_SAMPLE raised by this sample
    last_judged_.store(detail::ReadFacts::word(sample.time, sample.injected), std::memory_order_relaxed);  // facts()
    bool finite;
    if (sample.size == 1) {  // scalars: no loop
      finite = std::isfinite(sample.data[0]);
    } else {
      // x * 0 is 0 for a finite x and NaN for NaN or ±inf: one test for the whole vector.
      double zero = 0.0;
      for (std::size_t k = 0; k < sample.size; ++k) zero += sample.data[k] * 0.0;
      finite = zero == 0.0;
    }
    if (!finite) {
      invalid_sample(input, sample, true);
      return;
    }
    // invalid_count_ (in the object's first cache line) spares the common case a look at the
    // inputs' marks.
    if (invalid_count_ != 0 && cold_->invalid[input] != 0) invalid_sample(input, sample, false);
    cursor(input).keep();
    on_sample(input, sample);
  }
  /// Changes facts that facts() reads together: a reader that overlaps `change` reads them again
  /// (a sequence lock; only the filter's thread writes them).
  template <class Change>
  void change_facts(Change&& change) noexcept {
    std::atomic<std::uint32_t>& version = cold_->facts_version;
    const std::uint32_t v = version.load(std::memory_order_relaxed);
    version.store(v + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    change();
    version.store(v + 2, std::memory_order_release);
  }
  /// A bank that runs this filter learns that it must look at detour_ again.
  void tell_bank() noexcept {
    if (cold_->bank_changes != nullptr) cold_->bank_changes->fetch_add(1, std::memory_order_acq_rel);
  }
  SignalCursor& cursor(std::size_t input) noexcept { return input == 0 ? first_ : cold_->more_cursors[input - 1]; }
  const SignalCursor& cursor(std::size_t input) const noexcept {
    return input == 0 ? first_ : cold_->more_cursors[input - 1];
  }
  Signal* output_signal(std::size_t output) const noexcept {
    if (output == 0) return output0_;
    return output < cold_->outputs.size() ? cold_->outputs[output] : nullptr;
  }
  /// run() for everything but the hot path: disabled, re-enabled, injected, several inputs.
  void run_general(Time now) noexcept;
  void run_merged(bool injected_run, bool restore, Time now) noexcept;
  bool run_injection(Time now) noexcept;
  /// The first input's newest sample, judged again at `now` (the end of a shallow injection).
  void restore_reality(Time now) noexcept;

  // The filter's layout (docs/filters.md, "Memory layout"): a monitor runs thousands of filters
  // per cycle, and each cache line one of them touches is a likely miss. So what run() and the
  // common on_sample() need (flags, the first input's cursor with a scalar's samples, the first
  // output) is in the object's first two lines with the virtual table pointer, a derived filter's
  // own state right after them, and everything else in one separate block, cold_.
  // Why run() leaves its hot path, as bits of detour_: set_enabled() and inject() set them from
  // any thread; run_general() sets and clears kReenabled; kSeveralInputs is set at creation.
  static constexpr std::uint8_t kDisabled = 1;       ///< set_enabled(false)
  static constexpr std::uint8_t kInjection = 2;      ///< shallow injections queued
  static constexpr std::uint8_t kReenabled = 4;      ///< ran disabled: skip the samples it missed
  static constexpr std::uint8_t kSeveralInputs = 8;  ///< not exactly one input: merge
  static constexpr std::uint8_t kRestore = 16;       ///< a shallow injection ended: judge reality once
  std::atomic<std::uint8_t> detour_{0};
  std::atomic<bool> detected_{false};
  bool current_injected_ = false;
  bool ticks_ = true;                ///< on_tick is overridden (cleared by the default on its first call)
  std::uint32_t invalid_count_ = 0;  ///< inputs marked in cold_->invalid
  Signal* output0_ = nullptr;        ///< the first output, or nullptr
  std::atomic<std::int64_t> last_judged_{detail::kNoSample};  ///< the last sample judged as an object (a word)
  SignalCursor first_;  ///< the first input's cursor; it keeps the newest finite sample

  /// What the hot path does not read: configuration, the other inputs, injections.
  struct Cold {
    FilterConfig config;
    Coordinator* coordinator = nullptr;
    MachineId target = kNoMachine;
    ComponentId component = kNoComponent;
    EventId onset = kNoEvent;
    EventId completion = kNoEvent;
    NameId name_id = kNoName;
    std::vector<Signal*> inputs;
    std::vector<Signal*> outputs;
    std::vector<SignalCursor> more_cursors;  ///< inputs after the first
    std::vector<char> invalid;               ///< per input: its last sample was not finite
    std::vector<SampleView> pending;         ///< merge of several inputs: next sample of each
    std::vector<char> has_pending;
    std::mutex injection_mutex;  ///< guards injections and kInjection
    std::deque<std::vector<double>> injections;
    std::atomic<std::uint32_t>* bank_changes = nullptr;  ///< the bank's change count, when banked
    // The facts kept where they change, not per run (facts()): runs are counted by the group.
    std::atomic<std::uint32_t> facts_version{0};             ///< odd while the filter's thread changes them
    const std::atomic<std::uint64_t>* group_runs = nullptr;  ///< the runs its group has done
    std::atomic<std::uint64_t> runs_at_join{0};              ///< group_runs when it joined the group
    std::atomic<std::uint64_t> skipped{0};                   ///< runs while disabled, before the last
    std::atomic<std::int64_t> disabled_at{-1};    ///< group_runs before the first run it skipped; -1: enabled
    detail::BankSeat* seat = nullptr;             ///< in its bank, when banked
    std::atomic<std::uint64_t> banked_missed{0};  ///< samples its bank's reader missed
  };
  std::unique_ptr<Cold> cold_;
};

}  // namespace safecass
