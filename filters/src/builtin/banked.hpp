#pragma once
// The built-in filters that can run in a bank (docs/filters.md, "Filter banks"): Threshold,
// Watchdog, MovingAverage (scalar and vector), Debounce, Frequency, Norm and Deadline. Each keeps the state
// it judges with in a small struct with the step function that updates it. The filter object
// points at that struct: at first its own copy, and once a bank adopts it, the bank's element in
// an array of such structs. Run as an object or in a bank, the filter goes through the same step
// function on the same state, so the two cannot disagree on the arithmetic; what the bank does
// differently (one read of each sample for every filter of its signal, no virtual call, no object
// touched unless an event is due) is what the differential test checks
// (tests/unit/filters/bank_test.cpp).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "common.hpp"

namespace safecass::builtin {

/// Threshold's state: onset when x is beyond the onset level for `persistence`, completion when it
/// is back past the clear level.
struct ThresholdState {
  double onset_level = 0.0;
  double clear_level = 0.0;
  double out_above = 1.0;
  double out_below = 0.0;
  Persistence persistence;
  Signal* output = nullptr;
  bool above = true;
  bool detected = false;

  /// One finite sample; returns whether the condition is detected after it.
  bool step(double x, Time t) noexcept {
    const bool beyond = above ? x > onset_level : x < onset_level;
    const bool held = persistence.update(beyond, t);
    bool now = detected;
    if (!detected && held) now = true;
    if (detected && (above ? x <= clear_level : x >= clear_level)) now = false;
    detected = now;
    return detected;
  }
  double output_value() const noexcept { return detected ? out_above : out_below; }
  void reset() noexcept {
    detected = false;
    persistence.reset();
  }
};

/// Watchdog's state: the newest sample's time, or start-up (the first run) before any.
struct WatchdogState {
  Time timeout{};
  Time last{};
  Signal* output = nullptr;
  bool started = false;

  void on_sample(Time t) noexcept {
    if (!started || t > last) last = t;
    started = true;
  }
  /// Once per run, after the samples: the age of the newest sample at `now`.
  Time age(Time now) noexcept {
    if (!started) {
      last = now;  // start-up counts as the last sign of life
      started = true;
    }
    return now - last;
  }
  void reset() noexcept { started = false; }
};

/// A scalar MovingAverage's state: the ring of the last `window` samples and its running sum.
struct AverageState {
  double* ring = nullptr;  ///< window values: the filter object's, or its bank's
  double sum = 0.0;
  std::uint32_t window = 1;
  std::uint32_t next = 0;
  std::uint32_t count = 0;
  Signal* output = nullptr;

  /// One finite sample; returns the mean of the last `window` samples.
  double step(double x) noexcept {
    if (count == window) sum -= ring[next];
    ring[next] = x;
    sum += x;
    if (++next == window) next = 0;  // not %: a division costs more than the rest of the update
    if (count < window) ++count;
    // Recompute exactly once per window so rounding errors of the running sum cannot accumulate.
    if (next == 0) {
      double exact = 0.0;
      for (std::uint32_t k = 0; k < count; ++k) exact += ring[k];
      sum = exact;
    }
    return sum / static_cast<double>(count);
  }
  void reset() noexcept {
    count = next = 0;
    sum = 0.0;
  }
};

/// A vector MovingAverage's state: one block of (window + 2) × width values, the ring of the last
/// `window` samples, then the running sums, then the means last computed. The arithmetic is the
/// scalar's, element by element.
struct VectorAverageState {
  double* block = nullptr;  ///< the filter object's, or its bank's
  Signal* output = nullptr;
  std::uint32_t window = 1;
  std::uint32_t width = 1;
  std::uint32_t next = 0;
  std::uint32_t count = 0;

  static std::size_t block_size(std::size_t window, std::size_t width) noexcept { return (window + 2) * width; }
  /// One sample of `width` finite values; returns the means of the last `window` samples
  /// (`width` values, kept until the next step).
  const double* step(const double* x) noexcept {
    double* sums = block + std::size_t{window} * width;
    double* means = sums + width;
    double* slot = block + std::size_t{next} * width;
    for (std::uint32_t i = 0; i < width; ++i) {
      if (count == window) sums[i] -= slot[i];
      slot[i] = x[i];
      sums[i] += x[i];
    }
    if (++next == window) next = 0;
    if (count < window) ++count;
    // Recompute exactly once per window so rounding errors of the running sums cannot accumulate.
    if (next == 0) {
      std::fill(sums, sums + width, 0.0);
      for (std::uint32_t k = 0; k < count; ++k)
        for (std::uint32_t i = 0; i < width; ++i) sums[i] += block[std::size_t{k} * width + i];
    }
    for (std::uint32_t i = 0; i < width; ++i) means[i] = sums[i] / static_cast<double>(count);
    return means;
  }
  void reset() noexcept {
    count = next = 0;
    double* sums = block + std::size_t{window} * width;
    std::fill(sums, sums + width, 0.0);
  }
};

/// Debounce's state: on must persist before the onset, off before the completion.
struct DebounceState {
  Persistence on;
  Persistence off;
  Signal* output = nullptr;
  bool detected = false;

  /// One finite sample; returns whether the debounced input is on after it.
  bool step(double x, Time t) noexcept {
    const bool is_on = x != 0.0;
    if (on.update(is_on, t)) detected = true;
    if (off.update(!is_on, t)) detected = false;
    return detected;
  }
  void reset() noexcept {
    detected = false;
    on.reset();
    off.reset();
  }
};

/// Frequency's state: the last `window` intervals between samples and their running sum.
struct FrequencyState {
  double* ring = nullptr;  ///< window intervals in seconds: the filter object's, or its bank's
  double sum = 0.0;
  double min_rate = 0.0;
  double max_rate = 0.0;
  double max_jitter = 0.0;
  Time previous{};
  Signal* output = nullptr;
  std::uint32_t window = 1;
  std::uint32_t next = 0;
  std::uint32_t filled = 0;
  bool has_previous = false;

  /// One finite sample at `t`. Returns true once the window is full, with the verdict in
  /// `detected` and the mean rate in `rate`; false while it fills.
  bool step(Time t, bool& detected, double& rate) noexcept {
    bool judged = false;
    if (has_previous) {
      const double dt = to_seconds(t - previous);
      if (filled == window) sum -= ring[next];
      ring[next] = dt;
      sum += dt;
      next = (next + 1) % window;
      if (filled < window) ++filled;
      if (filled == window && sum > 0) {
        const double mean = sum / static_cast<double>(window);
        rate = 1.0 / mean;
        const bool slow = min_rate > 0 && rate < min_rate;
        const bool fast = max_rate > 0 && rate > max_rate;
        const bool jitter = max_jitter > 0 && std::fabs(dt - mean) > max_jitter;
        detected = slow || fast || jitter;
        judged = true;
      }
    }
    previous = t;
    has_previous = true;
    return judged;
  }
  void reset() noexcept {
    has_previous = false;
    filled = next = 0;
    sum = 0;
  }
};

/// Norm's state: which norm, and where it goes.
struct NormState {
  int kind = 0;  ///< 0: L2, 1: L1, 2: L∞
  Signal* output = nullptr;

  double step(const double* v, std::size_t n) const noexcept {
    double x = 0.0;
    if (kind == 0) {
      for (std::size_t i = 0; i < n; ++i) x += v[i] * v[i];
      return std::sqrt(x);
    }
    if (kind == 1) {
      for (std::size_t i = 0; i < n; ++i) x += std::fabs(v[i]);
      return x;
    }
    for (std::size_t i = 0; i < n; ++i) x = std::max(x, std::fabs(v[i]));
    return x;
  }
  void reset() noexcept {}
};

/// Deadline's state: the start of the open interval, if one is open.
struct DeadlineState {
  Time deadline{};
  Time start{};
  Signal* output = nullptr;
  bool open = false;

  /// A start checkpoint at `t`. A start while an interval is open does not restart it: the
  /// deadline runs from the first unmatched start, so starts that keep coming cannot hide a
  /// missing end.
  void on_start(Time t) noexcept {
    if (!open) start = t;
    open = true;
  }
  /// An end checkpoint at `t`: true when it closes an open interval, with the interval's length
  /// in `elapsed` and whether it was longer than the deadline in `late`; false when none is open.
  bool on_end(Time t, Time& elapsed, bool& late) noexcept {
    if (!open) return false;
    open = false;
    elapsed = t - start;
    late = elapsed > deadline;
    return true;
  }
  /// Once per run, after the samples: the open interval is older than the deadline at `now`.
  bool overdue(Time now) const noexcept { return open && now - start > deadline; }
  void reset() noexcept { open = false; }
};

/// The state a banked filter judges with: its own until a bank adopts it (Banks::add), then the
/// bank's element, which adopt() fills with a copy of the filter's state so far.
template <class State>
class BankedState {
public:
  State& operator*() noexcept { return *state_; }
  State* operator->() noexcept { return state_; }
  const State* operator->() const noexcept { return state_; }
  State& own() noexcept { return own_; }
  void adopt(State* element) noexcept {
    *element = *state_;
    state_ = element;
  }
  /// The bank's array moved: the element is the same, at a new address.
  void rebind(State* element) noexcept { state_ = element; }

private:
  State own_;
  State* state_ = &own_;
};

/// x > threshold + tolerance for `persistence` → onset; x ≤ threshold + tolerance − hysteresis →
/// completion; `direction: below` mirrors both.
class Threshold final : public Filter {
public:
  explicit Threshold(FilterInit init);
  static FilterManifest manifest();
  BankedState<ThresholdState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const double x = s.scalar();
    const bool detected = state_->step(x, s.time);
    report(detected, x, s.time);
    write(0, s.time, state_->output_value());
  }
  void on_reset() noexcept override { state_->reset(); }

private:
  BankedState<ThresholdState> state_;
};

/// No new sample for `timeout` seconds (counted from start-up, i.e. the first run) → onset; a new
/// sample → completion. Defaults to EVT_STALE / /EVT_STALE.
class Watchdog final : public Filter {
public:
  explicit Watchdog(FilterInit init);
  static FilterManifest manifest();
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&) {
    return std::vector<std::size_t>(1, 1);
  }
  BankedState<WatchdogState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override { state_->on_sample(s.time); }
  void on_reset() noexcept override { state_->reset(); }

private:
  void on_tick(Time now) noexcept override {
    const Time age = state_->age(now);
    report(age > state_->timeout, to_seconds(age), state_->last);
    write(0, now, to_seconds(age));
  }
  BankedState<WatchdogState> state_;
};

/// Mean of the last `window` samples (fewer at start-up), element-wise. Scalar or vector, its
/// state can be banked.
class MovingAverage final : public Filter {
public:
  static constexpr const char* kType = "MovingAverage";
  explicit MovingAverage(FilterInit init);
  static FilterManifest manifest();
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s);
  bool scalar() const noexcept { return size_ == 1; }
  /// A scalar's state; vector_state() a vector's.
  BankedState<AverageState>& state() noexcept { return scalar_; }
  BankedState<VectorAverageState>& vector_state() noexcept { return vector_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    if (size_ == 1) {
      write(0, s.time, scalar_->step(s[0]));
    } else {
      write(0, s.time, vector_->step(s.data));
    }
  }
  void on_reset() noexcept override {
    if (size_ == 1) {
      scalar_->reset();
    } else {
      vector_->reset();
    }
  }

private:
  // A scalar's window of up to kInline samples is kept inside the object (docs/filters.md,
  // "Memory layout"); a larger window, and a vector's block, in heap_.
  static constexpr std::size_t kInline = 16;
  std::size_t window_;
  std::size_t size_;
  BankedState<AverageState> scalar_;
  BankedState<VectorAverageState> vector_;
  double inline_[kInline] = {};
  std::vector<double> heap_;
};

/// A non-zero input that holds for `persistence` → onset; zero for `release` samples → completion.
class Debounce final : public Filter {
public:
  explicit Debounce(FilterInit init);
  static FilterManifest manifest();
  BankedState<DebounceState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const bool detected = state_->step(s.scalar(), s.time);
    report(detected, s.scalar(), s.time);
    write(0, s.time, detected ? 1.0 : 0.0);
  }
  void on_reset() noexcept override { state_->reset(); }

private:
  BankedState<DebounceState> state_;
};

/// Rate and jitter of a signal's samples over the last `window` intervals.
class Frequency final : public Filter {
public:
  explicit Frequency(FilterInit init);
  static FilterManifest manifest();
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&) {
    return std::vector<std::size_t>(1, 1);
  }
  BankedState<FrequencyState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    bool detected = false;
    double rate = 0.0;
    if (!state_->step(s.time, detected, rate)) return;
    report(detected, rate, s.time);
    write(0, s.time, rate);
  }
  void on_reset() noexcept override { state_->reset(); }

private:
  BankedState<FrequencyState> state_;
  std::vector<double> intervals_;  ///< the ring, until a bank adopts it
};

/// L2 (default), L1 or L∞ norm of a vector.
class Norm final : public Filter {
public:
  explicit Norm(FilterInit init);
  static FilterManifest manifest();
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&) {
    return std::vector<std::size_t>{1};
  }
  BankedState<NormState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override { write(0, s.time, state_->step(s.data, s.size)); }

private:
  BankedState<NormState> state_;
};

/// A sample of the first input opens a checkpoint, one of the second closes it; more than
/// `deadline` seconds between them (or still open after `deadline`) → onset; a pair within the
/// deadline → completion.
class Deadline final : public Filter {
public:
  explicit Deadline(FilterInit init);
  static FilterManifest manifest();
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s);
  BankedState<DeadlineState>& state() noexcept { return state_; }

protected:
  void on_sample(std::size_t input, const SampleView& s) noexcept override {
    if (input == 0) {
      state_->on_start(s.time);
      return;
    }
    Time elapsed{};
    bool late = false;
    if (!state_->on_end(s.time, elapsed, late)) return;
    report(late, to_seconds(elapsed), s.time, 1);
    write(0, s.time, to_seconds(elapsed));
  }
  void on_reset() noexcept override { state_->reset(); }

private:
  void on_tick(Time now) noexcept override {
    if (state_->overdue(now)) report(true, to_seconds(now - state_->start), now);
  }
  BankedState<DeadlineState> state_;
};

}  // namespace safecass::builtin
