#include "safecass/filters/filter.hpp"

#include <cmath>
#include <limits>

namespace safecass {

Filter::Filter(FilterInit init)
    : config_(std::move(init.config)),
      coordinator_(init.coordinator),
      target_(init.target),
      component_(init.component),
      inputs_(std::move(init.inputs)),
      outputs_(std::move(init.outputs)),
      onset_(init.onset),
      completion_(init.completion),
      name_id_(init.name_id) {
  detour_.store(
      static_cast<std::uint8_t>((config_.enabled ? 0 : kDisabled) | (inputs_.size() == 1 ? 0 : kSeveralInputs)));
  cursors_.reserve(inputs_.size());
  for (Signal* s : inputs_) {
    cursors_.emplace_back(s);
    cursors_.back().skip_to_end();
  }
  invalid_.assign(inputs_.size(), 0);
  pending_.resize(inputs_.size());
  has_pending_.assign(inputs_.size(), 0);
}

std::uint64_t Filter::missed_samples() const noexcept {
  std::uint64_t n = 0;
  for (const SignalCursor& c : cursors_) n += c.missed();
  return n;
}

void Filter::run_general(Time now) noexcept {
  const std::uint8_t detour = detour_.load(std::memory_order_acquire);
  if ((detour & kDisabled) != 0) {
    if ((detour & kReenabled) == 0) detour_.fetch_or(kReenabled, std::memory_order_acq_rel);
    return;
  }
  if ((detour & kReenabled) != 0) {
    for (SignalCursor& c : cursors_) c.skip_to_end();
    detour_.fetch_and(static_cast<std::uint8_t>(~kReenabled), std::memory_order_acq_rel);
  }
  const bool injected_run = (detour & kInjection) != 0 && run_injection(now);
  // The first run after a shallow injection ran out (DESIGN §3): the injection stood in for
  // reality, so its end restores reality even when the real signal has not changed since.
  const bool restore = !injected_run && (detour & kRestore) != 0;
  if (restore) detour_.fetch_and(static_cast<std::uint8_t>(~kRestore), std::memory_order_acq_rel);
  if (inputs_.size() == 1) {
    // The hot path: one input, its new samples in order.
    if (!injected_run) {
      bool any = false;
      cursors_[0].read_new([this, &any](const SampleView& sample) noexcept {
        any = true;
        deliver(0, sample);
      });
      if (restore && !any) restore_reality(now);
    }
  } else if (!inputs_.empty()) {
    run_merged(injected_run, restore, now);
  }
  current_injected_ = false;
  if (ticks_) on_tick(now);
}

bool Filter::run_injection(Time now) noexcept {
  const double* staged;
  {
    std::lock_guard lock(injection_mutex_);
    if (injections_.empty()) {
      detour_.fetch_and(static_cast<std::uint8_t>(~kInjection), std::memory_order_acq_rel);
      return false;
    }
    staged = cursors_[0].stage(injections_.front().data());
    injections_.pop_front();
    if (injections_.empty()) {
      // The last injected sample: the next run restores reality.
      detour_.fetch_or(kRestore, std::memory_order_acq_rel);
      detour_.fetch_and(static_cast<std::uint8_t>(~kInjection), std::memory_order_acq_rel);
    }
  }
  // A shallow injection replaces the first input's samples for this run.
  cursors_[0].skip_to_end();
  deliver(0, SampleView{now, staged, inputs_[0]->size(), true});
  return true;
}

void Filter::restore_reality(Time now) noexcept {
  SampleView sample;
  if (!cursors_[0].stage_latest(sample)) return;  // the signal never had a sample: nothing to restore
  sample.time = now;
  deliver(0, sample);
}

void Filter::run_merged(bool injected_run, bool restore, Time now) noexcept {
  // Several inputs: deliver their new samples merged in time order (ties: input order).
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    has_pending_[i] = !(i == 0 && injected_run) && cursors_[i].next(pending_[i]);
  }
  if (restore && !has_pending_[0] && cursors_[0].stage_latest(pending_[0])) {
    // The end of a shallow injection into the first input: its real value, judged as new, after
    // the other inputs' samples of this run.
    pending_[0].time = now;
    has_pending_[0] = true;
  }
  for (;;) {
    std::size_t best = inputs_.size();
    for (std::size_t i = 0; i < inputs_.size(); ++i) {
      if (has_pending_[i] && (best == inputs_.size() || pending_[i].time < pending_[best].time)) best = i;
    }
    if (best == inputs_.size()) break;
    deliver(best, pending_[best]);
    has_pending_[best] = cursors_[best].next(pending_[best]);
  }
}

Expected<void> Filter::inject(const std::vector<std::vector<double>>& samples) {
  if (inputs_.empty()) return fail(ErrorCode::InvalidArgument, "filter '" + name() + "' has no input to inject into");
  const std::size_t size = inputs_[0]->size();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].size() != size) {
      return fail(ErrorCode::InvalidArgument, "filter '" + name() + "': injected sample " + std::to_string(i + 1) +
                                                  " has " + std::to_string(samples[i].size()) + " values; input '" +
                                                  inputs_[0]->name() + "' has size " + std::to_string(size));
    }
  }
  std::lock_guard lock(injection_mutex_);
  injections_.insert(injections_.end(), samples.begin(), samples.end());
  if (!injections_.empty()) detour_.fetch_or(kInjection, std::memory_order_acq_rel);
  return {};
}

void Filter::reset() noexcept {
  detected_.store(false, std::memory_order_release);
  std::fill(invalid_.begin(), invalid_.end(), 0);
  invalid_count_ = 0;
  for (SignalCursor& c : cursors_) c.forget();
  on_reset();
}

void Filter::report_change(bool detected, double value, Time sample_time, std::size_t input) noexcept {
  const bool was = detected_.load(std::memory_order_relaxed);
  const SampleCause cause{name_id_, input < inputs_.size() ? inputs_[input]->name_id() : kNoName, value, sample_time,
                          current_injected_};
  if (detected) {
    if (was && config_.detection == DetectionMode::Edge) return;
    detected_.store(true, std::memory_order_release);
    if (onset_ != kNoEvent) coordinator_->generate(onset_, target_, cause);
    return;
  }
  detected_.store(false, std::memory_order_release);
  if (completion_ != kNoEvent) coordinator_->generate(completion_, target_, cause);
}

void Filter::invalid_sample(std::size_t input, const SampleView& sample, bool invalid) noexcept {
  if ((invalid_[input] != 0) == invalid) return;
  invalid_[input] = invalid ? 1 : 0;
  const bool was_raised = invalid_count_ > 0;
  invalid_count_ = invalid ? invalid_count_ + 1 : invalid_count_ - 1;
  // One condition for the filter: raised by the first bad input, cleared when none is left.
  if (was_raised == (invalid_count_ > 0)) return;
  double value = 0.0;
  if (invalid) {
    value = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t k = 0; k < sample.size; ++k) {
      if (!std::isfinite(sample.data[k])) {
        value = sample.data[k];  // the value as it came: NaN, +inf or -inf
        break;
      }
    }
  }
  const SampleCause cause{name_id_, inputs_[input]->name_id(), value, sample.time, current_injected_};
  const EventId event =
      invalid ? framework_event::kInvalidSample : framework_event::completion_of(framework_event::kInvalidSample);
  coordinator_->generate(event, coordinator_->framework_machine(component_), cause);
}

double Filter::number(std::string_view param) const {
  const auto it = config_.params.find(param);
  return it == config_.params.end() ? 0.0 : std::get<double>(it->second);
}

const std::string& Filter::text(std::string_view param) const {
  static const std::string kEmpty;
  const auto it = config_.params.find(param);
  return it == config_.params.end() ? kEmpty : std::get<std::string>(it->second);
}

bool Filter::flag(std::string_view param) const {
  const auto it = config_.params.find(param);
  return it != config_.params.end() && std::get<bool>(it->second);
}

}  // namespace safecass
