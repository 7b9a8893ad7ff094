// The condition set of one machine and the severity policy of DESIGN §2.4.

#include "safecass/core/condition_set.hpp"

#include <algorithm>

namespace safecass {

namespace {
constexpr std::size_t slot(State s) noexcept { return static_cast<std::size_t>(s); }
}  // namespace

std::int32_t ConditionSet::find_root(EventId onset) const noexcept {
  const Condition* items = data();
  for (std::size_t i = 0; i < size_; ++i) {
    if (!items[i].mirror && items[i].event == onset) return static_cast<std::int32_t>(i);
  }
  return -1;
}

std::int32_t ConditionSet::find_mirror(const RootCause& root) const noexcept {
  const Condition* items = data();
  for (std::size_t i = 0; i < size_; ++i) {
    const Condition& c = items[i];
    if (c.mirror && c.root.event == root.event && c.root.origin == root.origin && c.root.remote == root.remote) {
      return static_cast<std::int32_t>(i);
    }
  }
  return -1;
}

std::int32_t ConditionSet::find_lowest_root() const noexcept {
  const Condition* items = data();
  std::int32_t found = -1;
  for (std::size_t i = 0; i < size_; ++i) {
    const Condition& c = items[i];
    if (c.mirror) continue;
    if (found < 0 || c.level < items[found].level) found = static_cast<std::int32_t>(i);
  }
  return found;
}

ConditionChange ConditionSet::onset(const Event& onset, const RootCause& root, Time now, std::uint64_t& activations) {
  if (const std::int32_t i = find_root(onset.id); i >= 0) {
    // Rule 1: already active. A level-triggered filter repeats its onset every sample; the
    // repeat must not flood the history, so only the count and the last time change.
    Condition& c = data()[i];
    c.last = now;
    ++c.count;
    ConditionChange change;
    change.from = change.to = state_;
    change.index = i;
    return change;
  }
  Condition c;
  c.event = onset.id;
  c.level = onset_level(onset.transitions, state_);
  c.severity = onset.severity;
  c.first = c.last = now;
  c.seq = ++activations;
  c.root = root;
  return add(c);
}

ConditionChange ConditionSet::add(const Condition& condition) {
  ConditionChange change;
  change.from = state_;
  if (condition.level > state_) {
    change.outcome = Outcome::Raised;
  } else if (condition.level == state_) {
    const bool overrides = outstanding_ < 0 || condition.severity >= data()[outstanding_].severity;
    change.outcome = overrides ? Outcome::Override : Outcome::Joined;
  } else {
    // A worsening is never ignored (fail toward safe): the condition stays, below the state.
    change.outcome = Outcome::Masked;
  }
  push(condition);
  ++counts_[slot(condition.level)];
  recompute();
  change.to = state_;
  change.index = static_cast<std::int32_t>(size_ - 1);
  return change;
}

ConditionChange ConditionSet::complete(const Event* onset) {
  ConditionChange change;
  change.from = change.to = state_;
  change.outcome = Outcome::Ignored;
  if (onset == nullptr) {
    change.reason = kIgnoredNoOnset;
    return change;
  }
  const std::int32_t i = find_root(onset->id);
  if (i < 0) {
    change.reason = kIgnoredNotActive;
    return change;
  }
  if (onset->latched) {
    change.reason = kIgnoredLatched;
    change.index = i;
    return change;
  }
  return remove(static_cast<std::size_t>(i));
}

ConditionChange ConditionSet::remove(std::size_t index) {
  ConditionChange change;
  change.outcome = Outcome::Cleared;
  change.from = state_;
  Condition* items = data();
  change.removed = items[index];
  --counts_[slot(change.removed.level)];
  // Order of the others: the last one takes the removed one's place (no shifting).
  items[index] = items[size_ - 1];
  if (on_heap_) heap_.pop_back();
  --size_;
  recompute();
  change.to = state_;
  return change;
}

std::size_t ConditionSet::reset() {
  std::size_t removed = 0;
  for (std::int32_t i = find_lowest_root(); i >= 0; i = find_lowest_root()) {
    remove(static_cast<std::size_t>(i));
    ++removed;
  }
  return removed;
}

void ConditionSet::push(const Condition& c) {
  if (!on_heap_ && size_ == 0) {
    first_ = c;
  } else {
    if (!on_heap_) {
      heap_.reserve(std::max<std::size_t>(heap_.capacity(), 4));
      heap_.push_back(first_);
      on_heap_ = true;
    }
    heap_.push_back(c);
  }
  ++size_;
}

void ConditionSet::reserve(std::size_t n) {
  if (n <= 1 || (on_heap_ && heap_.capacity() >= n)) return;
  heap_.reserve(n);
  if (!on_heap_) {
    if (size_ == 1) heap_.push_back(first_);
    on_heap_ = true;
  }
}

void ConditionSet::recompute() noexcept {
  state_ = counts_[slot(State::Error)] > 0     ? State::Error
           : counts_[slot(State::Warning)] > 0 ? State::Warning
                                               : State::Normal;
  // Outstanding: highest severity at the current level; ties go to the most recent activation.
  outstanding_ = -1;
  const Condition* items = data();
  for (std::size_t i = 0; i < size_; ++i) {
    const Condition& c = items[i];
    if (c.level != state_) continue;
    if (outstanding_ < 0) {
      outstanding_ = static_cast<std::int32_t>(i);
      continue;
    }
    const Condition& best = items[outstanding_];
    if (c.severity > best.severity || (c.severity == best.severity && c.seq > best.seq)) {
      outstanding_ = static_cast<std::int32_t>(i);
    }
  }
}

}  // namespace safecass
