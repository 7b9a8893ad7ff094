// Timing supervision: Occurrence, Watchdog, Frequency, DutyCycle, Deadline.

#include <cmath>

#include "banked.hpp"

namespace safecass::builtin {

namespace {

/// At least `count` occurrences (rising edges of a non-zero input) within the last `window`
/// seconds → onset; fewer → completion.
class Occurrence final : public Filter {
public:
  explicit Occurrence(FilterInit init)
      : Filter(std::move(init)),
        count_(static_cast<std::size_t>(number("count"))),
        window_(seconds_to_time(number("window"))),
        times_(count_) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "event when the input turns on at least count times within window seconds";
    m.params = {ParamSpec::signal("input_signal", "scalar signal; each change from 0 to non-zero is an occurrence"),
                ParamSpec::integer("count", "occurrences that make a fault", 3.0, 1, 1e6),
                ParamSpec::number("window", "sliding window in seconds", std::nullopt, 1e-9, 1e9),
                ParamSpec::signal("output_signal", "occurrences within the window", true)};
    add_event_params(m, true);
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    return m;
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const bool on = s.scalar() != 0.0;
    if (on && !was_on_) {
      times_[next_] = s.time;
      next_ = (next_ + 1) % count_;
      if (seen_ < count_) ++seen_;
    }
    was_on_ = on;
    // Judged at the sample's time (occurrences processed late still count), written once per run.
    report(within(s.time) >= count_, s.scalar(), s.time);
  }
  void on_tick(Time now) noexcept override {
    const std::size_t n = within(now);
    report(n >= count_, 0.0, now);
    write(0, now, static_cast<double>(n));
  }
  void on_reset() noexcept override {
    seen_ = next_ = 0;
    was_on_ = false;
  }

private:
  std::size_t within(Time now) const noexcept {
    std::size_t n = 0;
    for (std::size_t i = 0; i < seen_; ++i) n += (now - times_[i] <= window_) ? 1 : 0;
    return n;
  }
  std::size_t count_;
  Time window_;
  std::vector<Time> times_;  ///< the last `count_` occurrence times (ring)
  std::size_t next_ = 0;
  std::size_t seen_ = 0;
  bool was_on_ = false;
};

}  // namespace

Watchdog::Watchdog(FilterInit init) : Filter(std::move(init)) {
  state_.own().timeout = seconds_to_time(number("timeout"));
  state_.own().output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Watchdog::manifest() {
  FilterManifest m;
  m.doc = "event when the input has no new sample for timeout seconds (heartbeat, staleness)";
  m.params = {ParamSpec::signal("input_signal", "any signal (a heartbeat)"),
              ParamSpec::number("timeout", "seconds without a new sample that make it stale", std::nullopt, 1e-9, 1e9),
              ParamSpec::signal("output_signal", "age of the newest sample in seconds, every run", true),
              ParamSpec::event("event_onset", "event when stale", std::string("EVT_STALE")),
              ParamSpec::event("event_completion", "event when fresh again", std::string("/EVT_STALE"))};
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  return m;
}

Frequency::Frequency(FilterInit init)
    : Filter(std::move(init)), intervals_(static_cast<std::size_t>(number("window")), 0.0) {
  FrequencyState& s = state_.own();
  s.ring = intervals_.data();
  s.window = static_cast<std::uint32_t>(intervals_.size());
  s.min_rate = number("min_rate");
  s.max_rate = number("max_rate");
  s.max_jitter = number("max_jitter");
  s.output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Frequency::manifest() {
  FilterManifest m;
  m.doc =
      "event when the sample rate leaves [min_rate, max_rate] or an interval deviates from the mean by more than "
      "max_jitter";
  m.params = {ParamSpec::signal("input_signal", "any signal whose sample times are judged"),
              ParamSpec::number("min_rate", "lowest allowed rate in Hz (0: no bound)", 0.0, 0, 1e12),
              ParamSpec::number("max_rate", "highest allowed rate in Hz (0: no bound)", 0.0, 0, 1e12),
              ParamSpec::number("max_jitter", "largest allowed |interval - mean interval| in seconds (0: no bound)",
                                0.0, 0, 1e9),
              ParamSpec::integer("window", "intervals averaged; judged once the window is full", 10.0, 1, 1e6),
              ParamSpec::signal("output_signal", "the mean rate in Hz", true)};
  add_event_params(m, true);
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  return m;
}

namespace {

/// Execution time / period above `max_duty` → onset.
class DutyCycle final : public Filter {
public:
  explicit DutyCycle(FilterInit init)
      : Filter(std::move(init)), period_(number("period")), max_duty_(number("max_duty")) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "event when a task's execution time exceeds max_duty of its period";
    m.params = {ParamSpec::signal("input_signal", "execution time of each cycle, in seconds"),
                ParamSpec::number("period", "the task's period in seconds", std::nullopt, 1e-9, 1e9),
                ParamSpec::number("max_duty", "largest allowed execution time / period", 0.8, 0, 1e6),
                ParamSpec::signal("output_signal", "the duty cycle", true)};
    add_event_params(m, true);
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    return m;
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const double duty = s.scalar() / period_;
    report(duty > max_duty_, duty, s.time);
    write(0, s.time, duty);
  }

private:
  double period_;
  double max_duty_;
};

}  // namespace

Deadline::Deadline(FilterInit init) : Filter(std::move(init)) {
  state_.own().deadline = seconds_to_time(number("deadline"));
  state_.own().output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Deadline::manifest() {
  FilterManifest m;
  m.doc = "event when the time from a start checkpoint to an end checkpoint exceeds deadline seconds";
  m.params = {
      ParamSpec::signals("input_signals", "two signals: [start checkpoint, end checkpoint]"),
      ParamSpec::number("deadline", "longest allowed time from start to end, in seconds", std::nullopt, 1e-9, 1e9),
      ParamSpec::signal("output_signal", "elapsed time of each completed pair", true)};
  add_event_params(m, true);
  m.inputs = {"input_signals"};
  m.outputs = {"output_signal"};
  return m;
}

Expected<std::vector<std::size_t>> Deadline::output_sizes(const FilterShape& s) {
  if (s.inputs.size() != 2) {
    return fail(ErrorCode::InvalidArgument,
                "filter '" + s.filter +
                    "' (Deadline): 'input_signals' must list exactly two signals (start, end), not " +
                    std::to_string(s.inputs.size()));
  }
  return std::vector<std::size_t>{1};
}

void register_timing(FilterRegistry& r) {
  (void)r.add<Occurrence>("Occurrence");
  (void)r.add<Watchdog>("Watchdog");
  (void)r.add<Frequency>("Frequency");
  (void)r.add<DutyCycle>("DutyCycle");
  (void)r.add<Deadline>("Deadline");
}

}  // namespace safecass::builtin
