#include "banks.hpp"

#include <algorithm>

namespace safecass::detail {

using builtin::MovingAverage;
using builtin::Threshold;
using builtin::Watchdog;

bool Banks::bankable(Filter& filter, Kind& kind) const noexcept {
  if (!banking_ || filter.inputs().size() != 1 || filter.inputs()[0]->size() != 1) return false;
  if (dynamic_cast<Threshold*>(&filter) != nullptr) {
    kind = Kind::Threshold;
  } else if (dynamic_cast<Watchdog*>(&filter) != nullptr) {
    kind = Kind::Watchdog;
  } else if (auto* average = dynamic_cast<MovingAverage*>(&filter); average != nullptr && average->scalar()) {
    kind = Kind::Average;
  } else {
    return false;
  }
  return true;
}

void Banks::add(Filter* filter) {
  ++size_;
  // A signal this filter writes cannot be read ahead of the run: it changes during it.
  for (const Signal* output : filter->outputs()) {
    if (output == nullptr) continue;
    written_.push_back(output);
    for (Reader& r : readers_) r.source = r.source && r.cursor.signal() != output;
  }
  Kind kind{};
  if (!bankable(*filter, kind)) {
    steps_.push_back(Step{filter, 0});
    return;
  }
  const Signal* input = filter->inputs()[0];
  // A filter joins the reader before it when both read the same signal from the same sample on.
  const bool join = !steps_.empty() && steps_.back().object == nullptr &&
                    readers_[steps_.back().reader].cursor.signal() == input &&
                    filter->first_.level_with(readers_[steps_.back().reader].cursor);
  if (!join) {
    Reader reader;
    reader.cursor = SignalCursor(input);
    reader.cursor.follow(filter->first_);
    reader.begin = reader.end = static_cast<std::uint32_t>(members_.size());
    reader.source = std::find(written_.begin(), written_.end(), input) == written_.end();
    readers_.push_back(std::move(reader));
    steps_.push_back(Step{nullptr, static_cast<std::uint32_t>(readers_.size() - 1)});
    const std::size_t samples = 2 * (input->buffer().capacity() + 1);  // written and injected
    if (times_.size() < samples) {
      times_.resize(samples);
      values_.resize(samples);
      injected_.resize(samples);
    }
  }
  Member m;
  m.filter = filter;
  m.kind = kind;
  m.reader = steps_.back().reader;
  m.out = filter->detour_.load(std::memory_order_acquire) != 0;
  m.reported = filter->detected();
  m.slow = filter->invalid_count_ != 0;
  members_.push_back(m);
  readers_[m.reader].end = static_cast<std::uint32_t>(members_.size());
  adopt(members_.back());
  filter->cold_->bank_changes = &changes_;
}

void Banks::adopt(Member& member) {
  // Moves the filter's state into its bank; when the bank's array grows, every member of that
  // kind is pointed at its element's new address.
  auto place = [&](auto& bank, auto state_of) {
    const auto* before = bank.data();
    bank.emplace_back();
    member.index = static_cast<std::uint32_t>(bank.size() - 1);
    state_of(member.filter).adopt(&bank.back());
    if (bank.data() == before) return;
    for (Member& m : members_) {
      if (m.kind == member.kind && &m != &member) state_of(m.filter).rebind(&bank[m.index]);
    }
  };
  switch (member.kind) {
    case Kind::Threshold:
      place(
          thresholds_, [](Filter * f) -> auto& { return static_cast<Threshold*>(f)->state(); });
      break;
    case Kind::Watchdog:
      place(
          watchdogs_, [](Filter * f) -> auto& { return static_cast<Watchdog*>(f)->state(); });
      break;
    case Kind::Average: {
      place(
          averages_, [](Filter * f) -> auto& { return static_cast<MovingAverage*>(f)->state(); });
      // Its ring too, next to the rings of the averages before it.
      builtin::AverageState& s = averages_.back();
      const double* before = rings_.data();
      ring_offsets_.push_back(static_cast<std::uint32_t>(rings_.size()));
      rings_.insert(rings_.end(), s.ring, s.ring + s.window);
      s.ring = rings_.data() + ring_offsets_.back();
      if (rings_.data() == before) break;
      for (std::size_t i = 0; i < averages_.size(); ++i) averages_[i].ring = rings_.data() + ring_offsets_[i];
      break;
    }
  }
}

void Banks::run(Time now) noexcept {
  if (const std::uint32_t changes = changes_.load(std::memory_order_acquire); changes != seen_) {
    seen_ = changes;
    refresh();
  }
  // First the signals no filter of the group writes, one sample each in the common case: their
  // reads do not wait for one another (the run below would do them one filter after another,
  // each a chain of dependent loads). The rest, and any run with more than one new sample, are
  // read in turn below.
  for (Reader& r : readers_) r.taken = r.source && r.cursor.take_single(r.time, r.value);
  for (const Step& step : steps_) {
    if (step.object != nullptr) {
      step.object->run(now);
    } else {
      run_reader(readers_[step.reader], now);
    }
  }
}

void Banks::settle() noexcept {
  for (Member& m : members_) {
    if (!m.out) m.filter->first_.follow(readers_[m.reader].cursor);
  }
}

void Banks::refresh() noexcept {
  // A member was disabled or injected into: from this run on it runs as an object, from the
  // sample its reader reads next.
  for (Member& m : members_) {
    if (m.out || m.filter->detour_.load(std::memory_order_acquire) == 0) continue;
    m.out = true;
    m.filter->first_.follow(readers_[m.reader].cursor);
  }
}

void Banks::run_reader(Reader& reader, Time now) noexcept {
  std::size_t samples = 0;
  bool plain = true;  // every sample finite and written, not injected: the common case
  if (reader.taken) {
    times_[0] = reader.time;
    values_[0] = reader.value;
    injected_[0] = 0;
    plain = std::isfinite(reader.value);
    samples = 1;
  } else {
    const std::uint64_t missed = reader.cursor.missed();
    reader.cursor.read_new([this, &samples, &plain](const SampleView& s) noexcept {
      times_[samples] = s.time;
      values_[samples] = s.data[0];
      injected_[samples] = s.injected ? 1 : 0;
      plain = plain && !s.injected && std::isfinite(s.data[0]);
      ++samples;
    });
    if (const std::uint64_t lost = reader.cursor.missed() - missed; lost != 0) {
      for (std::uint32_t i = reader.begin; i < reader.end; ++i) {
        if (!members_[i].out) members_[i].filter->cold_->banked_missed.fetch_add(lost, std::memory_order_relaxed);
      }
    }
  }
  plain_ = plain;
  for (std::uint32_t i = reader.begin; i < reader.end; ++i) {
    Member& m = members_[i];
    if (m.out) {
      run_out(m, reader, now);
      continue;
    }
    switch (m.kind) {
      case Kind::Threshold: run_threshold(m, samples); break;
      case Kind::Watchdog: run_watchdog(m, samples, now); break;
      case Kind::Average: run_average(m, samples); break;
    }
  }
}

void Banks::run_out(Member& m, const Reader& reader, Time now) noexcept {
  Filter& f = *m.filter;
  f.run(now);
  m.reported = f.detected();
  m.slow = f.invalid_count_ != 0;
  // Back in the bank once nothing detours it and it has read what its reader read.
  m.out = f.detour_.load(std::memory_order_acquire) != 0 || !f.first_.level_with(reader.cursor);
}

void Banks::deliver(Member& m, std::size_t j) noexcept {
  Filter& f = *m.filter;
  f.deliver(0, SampleView{times_[j], &values_[j], 1, injected_[j] != 0});
  f.current_injected_ = false;
  m.slow = f.invalid_count_ != 0;
  m.reported = f.detected();
}

void Banks::run_threshold(Member& m, std::size_t samples) noexcept {
  builtin::ThresholdState& s = thresholds_[m.index];
  for (std::size_t j = 0; j < samples; ++j) {
    if (!judged_here(m, j)) {
      deliver(m, j);
      continue;
    }
    const double x = values_[j];
    const bool detected = s.step(x, times_[j]);
    if (detected || m.reported) report(m, detected, x, times_[j]);
    if (s.output != nullptr) s.output->push(times_[j], s.output_value());
  }
}

void Banks::run_watchdog(Member& m, std::size_t samples, Time now) noexcept {
  builtin::WatchdogState& s = watchdogs_[m.index];
  for (std::size_t j = 0; j < samples; ++j) {
    if (judged_here(m, j)) {
      s.on_sample(times_[j]);
    } else {
      deliver(m, j);
    }
  }
  const Time age = s.age(now);
  const bool stale = age > s.timeout;
  if (stale || m.reported) report(m, stale, to_seconds(age), s.last);
  if (s.output != nullptr) s.output->push(now, to_seconds(age));
}

void Banks::run_average(Member& m, std::size_t samples) noexcept {
  builtin::AverageState& s = averages_[m.index];
  for (std::size_t j = 0; j < samples; ++j) {
    if (!judged_here(m, j)) {
      deliver(m, j);
      continue;
    }
    const double mean = s.step(values_[j]);
    if (s.output != nullptr) s.output->push(times_[j], mean);
  }
}

}  // namespace safecass::detail
