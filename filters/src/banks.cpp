#include "banks.hpp"

#include <algorithm>
#include <cmath>

namespace safecass::detail {

using builtin::Deadline;
using builtin::Debounce;
using builtin::Frequency;
using builtin::MovingAverage;
using builtin::Norm;
using builtin::Threshold;
using builtin::Watchdog;

bool Banks::bankable(Filter& filter, Kind& kind) const noexcept {
  if (!banking_) return false;
  if (dynamic_cast<Deadline*>(&filter) != nullptr) {
    kind = Kind::Deadline;
    return filter.inputs().size() == 2;
  }
  if (filter.inputs().size() != 1) return false;
  const bool scalar = filter.inputs()[0]->size() == 1;
  if (dynamic_cast<Threshold*>(&filter) != nullptr) {
    kind = Kind::Threshold;
  } else if (dynamic_cast<Watchdog*>(&filter) != nullptr) {
    kind = Kind::Watchdog;
  } else if (auto* average = dynamic_cast<MovingAverage*>(&filter); average != nullptr) {
    kind = average->scalar() ? Kind::Average : Kind::VectorAverage;
  } else if (dynamic_cast<Debounce*>(&filter) != nullptr) {
    kind = Kind::Debounce;
  } else if (dynamic_cast<Frequency*>(&filter) != nullptr) {
    kind = Kind::Frequency;
  } else if (dynamic_cast<Norm*>(&filter) != nullptr) {
    kind = Kind::Norm;
  } else {
    return false;
  }
  return scalar || kind == Kind::VectorAverage || kind == Kind::Watchdog || kind == Kind::Frequency ||
         kind == Kind::Norm;
}

void Banks::add(Filter* filter) {
  ++size_;
  filter->change_facts([&] {
    Filter::Cold& c = *filter->cold_;
    // It counts this group's runs from now on (an earlier group's were kept by settle()).
    c.runs_at_join.store(runs() - (c.group_runs != nullptr ? c.group_runs->load() - c.runs_at_join.load() : 0));
    c.group_runs = &runs_;
    c.seat = nullptr;
    c.bank_changes = nullptr;
  });
  // A signal this filter writes cannot be read ahead of the run: it changes during it.
  for (const Signal* output : filter->outputs()) {
    if (output == nullptr) continue;
    written_.push_back(output);
    for (Reader& r : readers_) r.source = r.source && r.cursor.signal() != output;
  }
  Kind kind{};
  if (!bankable(*filter, kind)) {
    steps_.push_back(Step{filter, 0, false});
    return;
  }
  // A filter joins the step before it when that step reads the same signals from the same
  // samples on.
  const Step* last = steps_.empty() || steps_.back().object != nullptr ? nullptr : &steps_.back();
  if (kind == Kind::Deadline) {
    const bool join = last != nullptr && last->pair &&
                      pairs_[last->reader].cursors[0].signal() == filter->inputs()[0] &&
                      pairs_[last->reader].cursors[1].signal() == filter->inputs()[1] &&
                      filter->cursor(0).level_with(pairs_[last->reader].cursors[0]) &&
                      filter->cursor(1).level_with(pairs_[last->reader].cursors[1]);
    if (!join) add_pair(*filter);
  } else {
    const bool join = last != nullptr && !last->pair && readers_[last->reader].cursor.signal() == filter->inputs()[0] &&
                      filter->first_.level_with(readers_[last->reader].cursor);
    if (!join) add_reader(*filter);
  }
  Member m;
  m.filter = filter;
  m.kind = kind;
  m.reader = steps_.back().reader;
  m.out = detoured(*filter);
  m.reported = filter->detected();
  m.slow = filter->invalid_count_ != 0;
  BankSeat& seat = seats_.emplace_back();
  seat.reader = read_facts(m);
  members_.push_back(m);
  const auto end = static_cast<std::uint32_t>(members_.size());
  if (kind == Kind::Deadline) {
    pairs_[m.reader].end = end;
  } else {
    readers_[m.reader].end = end;
  }
  adopt(members_.back());
  filter->cold_->bank_changes = &changes_;
  filter->cold_->seat = &seat;
  if (!members_.back().out) enter(members_.back());
}

void Banks::add_reader(Filter& filter) {
  const Signal* input = filter.inputs()[0];
  Reader reader;
  reader.cursor = SignalCursor(input);
  reader.cursor.follow(filter.first_);
  reader.begin = reader.end = static_cast<std::uint32_t>(members_.size());
  reader.source = std::find(written_.begin(), written_.end(), input) == written_.end();
  reader.first = static_cast<std::uint32_t>(readers_.size());
  for (std::size_t r = 0; r < readers_.size(); ++r) {
    if (readers_[r].cursor.signal() == input) {
      reader.first = static_cast<std::uint32_t>(r);
      break;
    }
  }
  reader.width = static_cast<std::uint32_t>(input->size());
  const Reader* before = readers_.data();
  readers_.push_back(std::move(reader));
  if (readers_.data() != before) reseat();
  steps_.push_back(Step{nullptr, static_cast<std::uint32_t>(readers_.size() - 1), false});
  reserve_read(2 * (input->buffer().capacity() + 1), input->size());  // written and injected
}

void Banks::add_pair(Filter& filter) {
  Pair pair;
  std::size_t samples = 0;
  std::size_t width = 1;
  for (std::size_t i = 0; i < 2; ++i) {
    const Signal* input = filter.inputs()[i];
    pair.cursors[i] = SignalCursor(input);
    pair.cursors[i].follow(filter.cursor(i));
    samples += 2 * (input->buffer().capacity() + 1);  // written and injected
    width = std::max(width, input->size());
  }
  pair.begin = pair.end = static_cast<std::uint32_t>(members_.size());
  const Pair* before = pairs_.data();
  pairs_.push_back(std::move(pair));
  if (pairs_.data() != before) reseat();
  steps_.push_back(Step{nullptr, static_cast<std::uint32_t>(pairs_.size() - 1), true});
  reserve_read(samples, width);
}

void Banks::reserve_read(std::size_t samples, std::size_t width) {
  if (times_.size() < samples) {
    times_.resize(samples);
    injected_.resize(samples);
    finite_.resize(samples);
    inputs_.resize(samples);
  }
  values_.resize(std::max(values_.size(), samples * width));
}

template <class State, class Get>
State& Banks::place(Member& member, std::vector<State>& bank, Get get) {
  // Moves the filter's state into its bank; when the bank's array grows, every member of that
  // kind is pointed at its element's new address.
  const State* before = bank.data();
  bank.emplace_back();
  member.index = static_cast<std::uint32_t>(bank.size() - 1);
  get(*member.filter).adopt(&bank.back());
  if (bank.data() != before) {
    for (Member& m : members_) {
      if (m.kind == member.kind && &m != &member) get(*m.filter).rebind(&bank[m.index]);
    }
  }
  return bank.back();
}

namespace {
/// The banked state of a filter of built-in type F.
template <class F>
auto& state_of(Filter& filter) noexcept {
  return static_cast<F&>(filter).state();
}
auto& vector_state_of(Filter& filter) noexcept { return static_cast<MovingAverage&>(filter).vector_state(); }
}  // namespace

void Banks::adopt(Member& member) {
  switch (member.kind) {
    case Kind::Threshold: place(member, thresholds_, state_of<Threshold>); break;
    case Kind::Watchdog: place(member, watchdogs_, state_of<Watchdog>); break;
    case Kind::Average: {
      builtin::AverageState& s = place(member, averages_, state_of<MovingAverage>);
      keep_ring(member, s.ring, s.window);
      break;
    }
    case Kind::VectorAverage: {
      builtin::VectorAverageState& s = place(member, vector_averages_, vector_state_of);
      keep_ring(member, s.block, builtin::VectorAverageState::block_size(s.window, s.width));
      break;
    }
    case Kind::Debounce: place(member, debounces_, state_of<Debounce>); break;
    case Kind::Frequency: {
      builtin::FrequencyState& s = place(member, frequencies_, state_of<Frequency>);
      keep_ring(member, s.ring, s.window);
      break;
    }
    case Kind::Norm: place(member, norms_, state_of<Norm>); break;
    case Kind::Deadline: place(member, deadlines_, state_of<Deadline>); break;
  }
}

void Banks::keep_ring(const Member& member, double* ring, std::size_t length) {
  // The ring goes next to the rings of the filters before it; when rings_ grows, every state is
  // pointed at its ring's new address.
  const double* before = rings_.data();
  ring_list_.push_back(Ring{member.kind, member.index, static_cast<std::uint32_t>(rings_.size())});
  rings_.insert(rings_.end(), ring, ring + length);
  if (rings_.data() != before) {
    for (const Ring& r : ring_list_) ring_of(r) = rings_.data() + r.offset;
  } else {
    ring_of(ring_list_.back()) = rings_.data() + ring_list_.back().offset;
  }
}

double*& Banks::ring_of(const Ring& ring) noexcept {
  switch (ring.kind) {
    case Kind::Average: return averages_[ring.index].ring;
    case Kind::VectorAverage: return vector_averages_[ring.index].block;
    default: return frequencies_[ring.index].ring;
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
  // A signal that several readers follow (filters of one signal with others in between) is read
  // once: a reader one sample behind the first reader of its signal takes the same sample.
  for (Reader& r : readers_) {
    r.taken = false;
    if (!r.source || r.width != 1) continue;
    const Reader& first = readers_[r.first];
    if (&first != &r && first.taken && r.cursor.one_behind(first.cursor)) {
      r.cursor.follow(first.cursor);
      r.time = first.time;
      r.value = first.value;
      r.taken = true;
    } else {
      r.taken = r.cursor.take_single(r.time, &r.value);
    }
  }
  others_ran_ = false;
  for (const Step& step : steps_) {
    if (step.object != nullptr) {
      others_ran_ = true;
      step.object->run(now);
    } else if (step.pair) {
      run_pair(pairs_[step.reader], now);
    } else {
      run_reader(readers_[step.reader], now);
    }
  }
  // Counted when done: a filter that finds itself disabled in this run never counted it.
  runs_.store(runs_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // one writer
}

void Banks::settle() noexcept {
  for (Member& m : members_) {
    if (m.out) continue;
    hand_over(m);
    leave(m);  // the filter keeps its newest sample: the group goes
  }
}

void Banks::reseat() noexcept {
  for (Member& m : members_) {
    m.filter->change_facts([&] { seat_of(m).reader = read_facts(m); });
  }
}

void Banks::enter(Member& m) noexcept {
  m.filter->change_facts([&] {
    BankSeat& seat = seat_of(m);
    seat.entry_reads.store(seat.reader->reads.load(std::memory_order_relaxed), std::memory_order_relaxed);
    seat.in.store(true, std::memory_order_relaxed);
  });
}

void Banks::leave(Member& m) noexcept {
  Filter& f = *m.filter;
  f.change_facts([&] {
    // The last sample it judged in the bank becomes the object's own (facts()).
    BankSeat& seat = seat_of(m);
    if (seat.reader->reads.load(std::memory_order_relaxed) != seat.entry_reads.load(std::memory_order_relaxed)) {
      f.last_judged_.store(seat.reader->last.load(std::memory_order_relaxed), std::memory_order_relaxed);
    }
    seat.in.store(false, std::memory_order_relaxed);
  });
}

void Banks::refresh() noexcept {
  // A member was disabled or injected into: from this run on it runs as an object, from the
  // sample its reader reads next.
  for (Member& m : members_) {
    if (m.out || !detoured(*m.filter)) continue;
    m.out = true;
    hand_over(m);
    leave(m);
  }
}

bool Banks::level(const Member& m) const noexcept {
  const Filter& f = *m.filter;
  if (m.kind != Kind::Deadline) return f.first_.level_with(readers_[m.reader].cursor);
  const Pair& pair = pairs_[m.reader];
  return f.cursor(0).level_with(pair.cursors[0]) && f.cursor(1).level_with(pair.cursors[1]);
}

void Banks::hand_over(Member& m) noexcept {
  Filter& f = *m.filter;
  if (m.kind != Kind::Deadline) {
    f.first_.follow(readers_[m.reader].cursor);
    return;
  }
  const Pair& pair = pairs_[m.reader];
  f.cursor(0).follow(pair.cursors[0]);
  f.cursor(1).follow(pair.cursors[1]);
}

std::size_t Banks::read(Reader& reader) noexcept {
  width_ = reader.width;
  std::size_t samples = 0;
  bool plain = true;  // every sample finite and written, not injected
  if (reader.taken) {
    times_[0] = reader.time;
    values_[0] = reader.value;
    injected_[0] = 0;
    finite_[0] = std::isfinite(reader.value) ? 1 : 0;
    plain = finite_[0] != 0;
    samples = 1;
    // A sample written since the read ahead, during this run (an application's observer of an
    // earlier filter's event), is read now, as the filters one by one would read it. Only code
    // run on this thread in between can have written one before this reader's turn: a sample
    // another thread writes meanwhile may as well come after the run (and is read by the next).
    if (!others_ran_ || !reader.cursor.unread()) {
      plain_ = plain;
      reader.facts.note(reader.time, false);
      return 1;
    }
  } else if (reader.cursor.take_single(times_[0], values_.data())) {  // one new sample: the common case
    bool finite = true;
    for (std::size_t i = 0; i < width_; ++i) finite = finite && std::isfinite(values_[i]);
    injected_[0] = 0;
    finite_[0] = finite ? 1 : 0;
    plain_ = finite;
    reader.facts.note(times_[0], false);
    return 1;
  }
  const std::uint64_t missed = reader.cursor.missed();
  std::uint64_t dropped = 0;
  reader.cursor.read_new([this, &samples, &plain, &dropped](const SampleView& s) noexcept {
    if (!store_sample(samples, s, plain)) ++dropped;
  });
  if (const std::uint64_t lost = reader.cursor.missed() - missed + dropped; lost != 0) {
    add_missed(reader.begin, reader.end, lost);
  }
  plain_ = plain;
  if (samples != 0) reader.facts.note(times_[samples - 1], injected_[samples - 1] != 0);
  return samples;
}

bool Banks::store_sample(std::size_t& samples, const SampleView& s, bool& plain) noexcept {
  // The buffers hold all a run can read (history and injections) unless a writer outran this
  // read: what does not fit is counted as missed, never written past them.
  if (samples == times_.size() || (samples + 1) * width_ > values_.size()) return false;
  times_[samples] = s.time;
  bool finite = true;
  for (std::size_t k = 0; k < s.size; ++k) {
    values_[samples * width_ + k] = s.data[k];
    finite = finite && std::isfinite(s.data[k]);
  }
  injected_[samples] = s.injected ? 1 : 0;
  finite_[samples] = finite ? 1 : 0;
  plain = plain && !s.injected && finite;
  ++samples;
  return true;
}

void Banks::add_missed(std::uint32_t begin, std::uint32_t end, std::uint64_t lost) noexcept {
  for (std::uint32_t i = begin; i < end; ++i) {
    if (!members_[i].out) members_[i].filter->cold_->banked_missed.fetch_add(lost, std::memory_order_relaxed);
  }
}

std::size_t Banks::read_pair(Pair& pair) noexcept {
  width_ = std::max(pair.cursors[0].signal()->size(), pair.cursors[1].signal()->size());
  const std::uint64_t missed = pair.cursors[0].missed() + pair.cursors[1].missed();
  std::uint64_t dropped = 0;
  SampleView next[2];
  bool has[2] = {pair.cursors[0].next(next[0]), pair.cursors[1].next(next[1])};
  std::size_t samples = 0;
  bool plain = true;
  while (has[0] || has[1]) {
    // The earlier of the two; a tie goes to the start, as in the object's merge.
    const std::size_t i = has[1] && (!has[0] || next[1].time < next[0].time) ? 1 : 0;
    if (store_sample(samples, next[i], plain)) {
      inputs_[samples - 1] = static_cast<char>(i);
    } else {
      ++dropped;
    }
    has[i] = pair.cursors[i].next(next[i]);
  }
  if (const std::uint64_t lost = pair.cursors[0].missed() + pair.cursors[1].missed() - missed + dropped; lost != 0) {
    add_missed(pair.begin, pair.end, lost);
  }
  plain_ = plain;
  if (samples != 0) pair.facts.note(times_[samples - 1], injected_[samples - 1] != 0);
  return samples;
}

void Banks::run_pair(Pair& pair, Time now) noexcept {
  const std::size_t samples = read_pair(pair);
  for (std::uint32_t i = pair.begin; i < pair.end; ++i) {
    Member& m = members_[i];
    if (m.out) {
      run_out(m, now);
      continue;
    }
    // Deadline's on_sample() for each sample, then its on_tick().
    builtin::DeadlineState& s = deadlines_[m.index];
    for (std::size_t j = 0; j < samples; ++j) {
      if (!judged_here(m, j)) {
        deliver(m, j, static_cast<std::size_t>(inputs_[j]));
        continue;
      }
      if (inputs_[j] == 0) {
        s.on_start(times_[j]);
        continue;
      }
      Time elapsed{};
      bool late = false;
      if (!s.on_end(times_[j], elapsed, late)) continue;
      if (late || m.reported) report(m, late, to_seconds(elapsed), times_[j], 1);
      if (s.output != nullptr) s.output->push(times_[j], to_seconds(elapsed));
    }
    if (s.overdue(now)) report(m, true, to_seconds(now - s.start), now);
  }
}

void Banks::run_reader(Reader& reader, Time now) noexcept {
  const std::size_t samples = read(reader);
  for (std::uint32_t i = reader.begin; i < reader.end; ++i) {
    Member& m = members_[i];
    if (m.out) {
      run_out(m, now);
      continue;
    }
    // Each kind: the step its object's on_sample() takes, then the report and the output write.
    switch (m.kind) {
      case Kind::Threshold: {
        builtin::ThresholdState& s = thresholds_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          const double x = *sample(j);
          const bool detected = s.step(x, times_[j]);
          if (detected || m.reported) report(m, detected, x, times_[j]);
          if (s.output != nullptr) s.output->push(times_[j], s.output_value());
        });
        break;
      }
      case Kind::Watchdog: {
        builtin::WatchdogState& s = watchdogs_[m.index];
        each_sample(m, samples, [&](std::size_t j) { s.on_sample(times_[j]); });
        const Time age = s.age(now);  // its on_tick()
        const bool stale = age > s.timeout;
        if (stale || m.reported) report(m, stale, to_seconds(age), s.last);
        if (s.output != nullptr) s.output->push(now, to_seconds(age));
        break;
      }
      case Kind::Average: {
        builtin::AverageState& s = averages_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          const double mean = s.step(*sample(j));
          if (s.output != nullptr) s.output->push(times_[j], mean);
        });
        break;
      }
      case Kind::VectorAverage: {
        builtin::VectorAverageState& s = vector_averages_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          const double* means = s.step(sample(j));
          if (s.output != nullptr) s.output->push(times_[j], means);
        });
        break;
      }
      case Kind::Debounce: {
        builtin::DebounceState& s = debounces_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          const double x = *sample(j);
          const bool detected = s.step(x, times_[j]);
          if (detected || m.reported) report(m, detected, x, times_[j]);
          if (s.output != nullptr) s.output->push(times_[j], detected ? 1.0 : 0.0);
        });
        break;
      }
      case Kind::Frequency: {
        builtin::FrequencyState& s = frequencies_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          bool detected = false;
          double rate = 0.0;
          if (!s.step(times_[j], detected, rate)) return;
          if (detected || m.reported) report(m, detected, rate, times_[j]);
          if (s.output != nullptr) s.output->push(times_[j], rate);
        });
        break;
      }
      case Kind::Norm: {
        const builtin::NormState& s = norms_[m.index];
        each_sample(m, samples, [&](std::size_t j) {
          if (s.output != nullptr) s.output->push(times_[j], s.step(sample(j), width_));
        });
        break;
      }
      case Kind::Deadline: break;  // never in a reader: a pair's (run_pair)
    }
  }
}

void Banks::run_out(Member& m, Time now) noexcept {
  Filter& f = *m.filter;
  others_ran_ = true;
  f.run(now);
  m.reported = f.detected();
  m.slow = f.invalid_count_ != 0;
  // Back in the bank once nothing detours it and it has read what its reader read.
  m.out = detoured(f) || !level(m);
  if (!m.out) enter(m);
}

void Banks::deliver(Member& m, std::size_t j, std::size_t input) noexcept {
  Filter& f = *m.filter;
  others_ran_ = true;
  f.deliver(input, SampleView{times_[j], sample(j), f.inputs()[input]->size(), injected_[j] != 0});
  f.current_injected_ = false;
  m.slow = f.invalid_count_ != 0;
  m.reported = f.detected();
}

}  // namespace safecass::detail
