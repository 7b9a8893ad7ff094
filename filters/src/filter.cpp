#include "safecass/filters/filter.hpp"

#include <cmath>
#include <limits>

namespace safecass {

Filter::Filter(FilterInit init) : cold_(std::make_unique<Cold>()) {
  Cold& c = *cold_;
  c.config = std::move(init.config);
  c.coordinator = init.coordinator;
  c.target = init.target;
  c.component = init.component;
  c.onset = init.onset;
  c.completion = init.completion;
  c.name_id = init.name_id;
  c.inputs = std::move(init.inputs);
  c.outputs = std::move(init.outputs);
  detour_.store(
      static_cast<std::uint8_t>((c.config.enabled ? 0 : kDisabled) | (c.inputs.size() == 1 ? 0 : kSeveralInputs)));
  if (!c.outputs.empty()) output0_ = c.outputs[0];
  if (!c.inputs.empty()) first_ = SignalCursor(c.inputs[0]);
  c.more_cursors.reserve(c.inputs.size() > 1 ? c.inputs.size() - 1 : 0);
  for (std::size_t i = 1; i < c.inputs.size(); ++i) c.more_cursors.emplace_back(c.inputs[i]);
  for (std::size_t i = 0; i < c.inputs.size(); ++i) cursor(i).skip_to_end();
  c.invalid.assign(c.inputs.size(), 0);
  c.pending.resize(c.inputs.size());
  c.has_pending.assign(c.inputs.size(), 0);
}

Filter::~Filter() = default;

std::uint64_t Filter::missed_samples() const noexcept {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < cold_->inputs.size(); ++i) n += cursor(i).missed();
  return n + cold_->banked_missed.load(std::memory_order_relaxed);
}

FilterFacts Filter::facts() const noexcept {
  const Cold& c = *cold_;
  FilterFacts f;
  for (;;) {
    const std::uint32_t version = c.facts_version.load(std::memory_order_acquire);
    if ((version & 1U) != 0) continue;  // being changed: a few stores
    const std::uint8_t detour = detour_.load(std::memory_order_acquire);
    f.enabled = (detour & kDisabled) == 0;
    std::int64_t last = last_judged_.load(std::memory_order_relaxed);
    if (const detail::BankSeat* seat = c.seat; seat != nullptr && seat->in.load(std::memory_order_relaxed)) {
      // In its bank, the filter has judged what its reader read since it entered.
      if (seat->reader->reads.load(std::memory_order_acquire) != seat->entry_reads.load(std::memory_order_relaxed)) {
        last = seat->reader->last.load(std::memory_order_relaxed);
      }
    }
    const bool sampled = last != detail::kNoSample;
    f.injected = (detour & kInjection) != 0 || (sampled && detail::ReadFacts::injected_in(last));
    f.last_sample.reset();
    if (sampled) f.last_sample = detail::ReadFacts::time_of(last);
    f.evaluations = 0;
    if (c.group_runs != nullptr) {
      // The runs done since it joined, less those it spent disabled.
      const std::uint64_t runs = c.group_runs->load(std::memory_order_relaxed);
      const std::int64_t disabled_at = c.disabled_at.load(std::memory_order_relaxed);
      std::uint64_t off = c.runs_at_join.load(std::memory_order_relaxed) + c.skipped.load(std::memory_order_relaxed);
      if (disabled_at >= 0) off += runs - static_cast<std::uint64_t>(disabled_at);
      f.evaluations = runs >= off ? runs - off : 0;
    }
    std::atomic_thread_fence(std::memory_order_acquire);
    if (c.facts_version.load(std::memory_order_relaxed) == version) return f;
  }
}

void Filter::run_general(Time now) noexcept {
  const std::uint8_t detour = detour_.load(std::memory_order_acquire);
  if ((detour & kDisabled) != 0) {
    if ((detour & kReenabled) == 0) {
      detour_.fetch_or(kReenabled, std::memory_order_acq_rel);
      // The first run it skips: from this one on, its group's runs are not its evaluations.
      if (const auto* runs = cold_->group_runs) {
        change_facts(
            [&] { cold_->disabled_at.store(static_cast<std::int64_t>(runs->load(std::memory_order_relaxed))); });
      }
    }
    return;
  }
  if ((detour & kReenabled) != 0) {
    for (std::size_t i = 0; i < cold_->inputs.size(); ++i) cursor(i).skip_to_end();
    detour_.fetch_and(static_cast<std::uint8_t>(~kReenabled), std::memory_order_acq_rel);
    if (const auto* runs = cold_->group_runs; runs != nullptr && cold_->disabled_at.load() >= 0) {
      change_facts([&] {
        const auto skipped =
            runs->load(std::memory_order_relaxed) - static_cast<std::uint64_t>(cold_->disabled_at.load());
        cold_->skipped.store(cold_->skipped.load() + skipped);
        cold_->disabled_at.store(-1);
      });
    }
  }
  const bool injected_run = (detour & kInjection) != 0 && run_injection(now);
  // The first run after a shallow injection ran out (DESIGN §3): the injection stood in for
  // reality, so its end restores reality even when the real signal has not changed since.
  const bool restore = !injected_run && (detour & kRestore) != 0;
  if (restore) detour_.fetch_and(static_cast<std::uint8_t>(~kRestore), std::memory_order_acq_rel);
  if (cold_->inputs.size() == 1) {
    // The hot path: one input, its new samples in order.
    if (!injected_run) {
      bool any = false;
      first_.read_new([this, &any](const SampleView& sample) noexcept {
        any = true;
        deliver(0, sample);
      });
      if (restore && !any) restore_reality(now);
    }
  } else if (!cold_->inputs.empty()) {
    run_merged(injected_run, restore, now);
  }
  current_injected_ = false;
  if (ticks_) on_tick(now);
}

bool Filter::run_injection(Time now) noexcept {
  const double* staged;
  {
    std::lock_guard lock(cold_->injection_mutex);
    auto& injections = cold_->injections;
    if (injections.empty()) {
      detour_.fetch_and(static_cast<std::uint8_t>(~kInjection), std::memory_order_acq_rel);
      return false;
    }
    staged = first_.stage(injections.front().data());
    injections.pop_front();
    if (injections.empty()) {
      // The last injected sample: the next run restores reality.
      detour_.fetch_or(kRestore, std::memory_order_acq_rel);
      detour_.fetch_and(static_cast<std::uint8_t>(~kInjection), std::memory_order_acq_rel);
    }
  }
  // A shallow injection replaces the first input's samples for this run.
  first_.skip_to_end();
  deliver(0, SampleView{now, staged, cold_->inputs[0]->size(), true});
  return true;
}

void Filter::restore_reality(Time now) noexcept {
  SampleView sample;
  if (!first_.stage_latest(sample)) return;  // the signal never had a sample: nothing to restore
  sample.time = now;
  deliver(0, sample);
}

void Filter::run_merged(bool injected_run, bool restore, Time now) noexcept {
  // Several inputs: deliver their new samples merged in time order (ties: input order).
  const std::size_t n = cold_->inputs.size();
  auto& pending = cold_->pending;
  auto& has_pending = cold_->has_pending;
  for (std::size_t i = 0; i < n; ++i) {
    has_pending[i] = !(i == 0 && injected_run) && cursor(i).next(pending[i]);
  }
  if (restore && !has_pending[0] && first_.stage_latest(pending[0])) {
    // The end of a shallow injection into the first input: its real value, judged as new, after
    // the other inputs' samples of this run.
    pending[0].time = now;
    has_pending[0] = true;
  }
  for (;;) {
    std::size_t best = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (has_pending[i] && (best == n || pending[i].time < pending[best].time)) best = i;
    }
    if (best == n) break;
    deliver(best, pending[best]);
    has_pending[best] = cursor(best).next(pending[best]);
  }
}

Expected<void> Filter::check_injection(const std::vector<std::vector<double>>& samples) const {
  const std::vector<Signal*>& inputs = cold_->inputs;
  if (inputs.empty()) return fail(ErrorCode::InvalidArgument, "filter '" + name() + "' has no input to inject into");
  const std::size_t size = inputs[0]->size();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].size() != size) {
      return fail(ErrorCode::InvalidArgument, "filter '" + name() + "': injected sample " + std::to_string(i + 1) +
                                                  " has " + std::to_string(samples[i].size()) + " values; input '" +
                                                  inputs[0]->name() + "' has size " + std::to_string(size));
    }
  }
  return {};
}

Expected<void> Filter::inject(const std::vector<std::vector<double>>& samples) {
  if (auto ok = check_injection(samples); !ok) return ok;
  std::lock_guard lock(cold_->injection_mutex);
  cold_->injections.insert(cold_->injections.end(), samples.begin(), samples.end());
  if (!cold_->injections.empty()) detour_.fetch_or(kInjection, std::memory_order_acq_rel);
  tell_bank();
  return {};
}

void Filter::reset() noexcept {
  detected_.store(false, std::memory_order_release);
  std::fill(cold_->invalid.begin(), cold_->invalid.end(), 0);
  invalid_count_ = 0;
  for (std::size_t i = 0; i < cold_->inputs.size(); ++i) cursor(i).forget();
  on_reset();
}

void Filter::report_change(bool detected, double value, Time sample_time, std::size_t input) noexcept {
  const bool was = detected_.load(std::memory_order_relaxed);
  const Cold& c = *cold_;
  const SampleCause cause{c.name_id, input < c.inputs.size() ? c.inputs[input]->name_id() : kNoName, value, sample_time,
                          current_injected_};
  if (detected) {
    if (was && c.config.detection == DetectionMode::Edge) return;
    detected_.store(true, std::memory_order_release);
    if (c.onset != kNoEvent) c.coordinator->generate(c.onset, c.target, cause);
    return;
  }
  detected_.store(false, std::memory_order_release);
  if (c.completion != kNoEvent) c.coordinator->generate(c.completion, c.target, cause);
}

void Filter::invalid_sample(std::size_t input, const SampleView& sample, bool invalid) noexcept {
  std::vector<char>& marks = cold_->invalid;
  if ((marks[input] != 0) == invalid) return;
  marks[input] = invalid ? 1 : 0;
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
  const Cold& c = *cold_;
  const SampleCause cause{c.name_id, c.inputs[input]->name_id(), value, sample.time, current_injected_};
  const EventId event =
      invalid ? framework_event::kInvalidSample : framework_event::completion_of(framework_event::kInvalidSample);
  c.coordinator->generate(event, c.coordinator->structure().framework_machine(c.component), cause);
}

double Filter::number(std::string_view param) const {
  const auto it = cold_->config.params.find(param);
  return it == cold_->config.params.end() ? 0.0 : std::get<double>(it->second);
}

const std::string& Filter::text(std::string_view param) const {
  static const std::string empty;
  const auto it = cold_->config.params.find(param);
  return it == cold_->config.params.end() ? empty : std::get<std::string>(it->second);
}

bool Filter::flag(std::string_view param) const {
  const auto it = cold_->config.params.find(param);
  return it != cold_->config.params.end() && std::get<bool>(it->second);
}

}  // namespace safecass
