#pragma once
/// @file condition_set.hpp
/// The set of active conditions of one state machine and the rules that change it (DESIGN §2.4,
/// docs/semantics.md §4). A plain value type: it knows no coordinator, clock, lock, record or
/// callback. The coordinator keeps one per machine and turns every change it reports into records,
/// callbacks and propagation; tests drive it directly, rule by rule.
///
/// Invariants after every call: state() is the highest level of the conditions held (Normal when
/// there are none); outstanding() is, among the conditions at that level, the one of highest
/// severity, the most recently activated on ties; at most one root condition per event and at most
/// one mirror per root cause.
///
/// Thread-safety: none of its own (the coordinator calls it under its lock). Allocation: adding a
/// condition allocates only while the set grows beyond the largest size it has had; nothing else
/// allocates.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/condition.hpp"
#include "safecass/core/event.hpp"
#include "safecass/core/ids.hpp"
#include "safecass/core/observer.hpp"
#include "safecass/core/state.hpp"

namespace safecass {

/// What one call to a ConditionSet changed.
struct ConditionChange {
  /// Raised, Override, Joined or Masked: a condition was added (onset rule 2). Cleared: one was
  /// removed. Ignored: a completion changed nothing, `reason` says why. None: an onset refreshed
  /// its active condition (onset rule 1), which is not recorded.
  Outcome outcome = Outcome::None;
  State from = State::Normal;  ///< the machine's state before
  State to = State::Normal;    ///< the machine's state after
  /// Added or refreshed: the condition's index (valid until the set changes again). Ignored
  /// because latched: the index of the condition that stays. Otherwise -1.
  std::int32_t index = -1;
  Condition removed;        ///< Cleared: the condition that was removed
  std::string_view reason;  ///< Ignored: why (one of the ConditionSet::kIgnored* texts)

  bool transition() const noexcept { return from != to; }
};

class ConditionSet {
public:
  /// Reasons of an ignored completion (docs/semantics.md §4.3); static storage.
  static constexpr std::string_view kIgnoredNoOnset = "completes an onset that is not defined";
  static constexpr std::string_view kIgnoredNotActive = "not active";
  static constexpr std::string_view kIgnoredLatched = "latched: needs reset";

  ConditionSet() = default;

  // ---- reads -----------------------------------------------------------------------------------
  /// The highest level held; Normal when the set is empty.
  State state() const noexcept { return state_; }
  bool empty() const noexcept { return size_ == 0; }
  std::size_t size() const noexcept { return size_; }
  const Condition& operator[](std::size_t i) const noexcept { return data()[i]; }
  const Condition* begin() const noexcept { return data(); }
  const Condition* end() const noexcept { return data() + size_; }
  /// How many conditions are held at `level`.
  std::uint32_t count_at(State level) const noexcept { return counts_[static_cast<std::size_t>(level)]; }
  /// Index of the outstanding condition; -1 in Normal.
  std::int32_t outstanding_index() const noexcept { return outstanding_; }
  /// The outstanding condition; nullptr in Normal.
  const Condition* outstanding() const noexcept { return outstanding_ < 0 ? nullptr : &data()[outstanding_]; }
  /// The outstanding condition's event; kNoEvent in Normal.
  EventId outstanding_event() const noexcept { return outstanding_ < 0 ? kNoEvent : data()[outstanding_].event; }

  /// Index of the root condition (not a mirror) of `onset`, or -1.
  std::int32_t find_root(EventId onset) const noexcept;
  /// Index of the mirror of `root` (same event, origin and remote slot), or -1.
  std::int32_t find_mirror(const RootCause& root) const noexcept;
  /// Index of a root condition of the lowest level (the first such one held), or -1. A reset
  /// removes roots in this order so that a machine drops once, E2N, instead of through Warning.
  std::int32_t find_lowest_root() const noexcept;

  // ---- the rules of DESIGN §2.4 -------------------------------------------------------------
  /// An onset arrives. Rule 1: when its root condition is active, only its last time and count
  /// change (outcome None). Rule 2: otherwise a root condition is added at the onset's level in the
  /// current state (onset_level()), with `root` as its root cause, `now` as its first and last
  /// time and `++activations` as its activation order; the outcome is Raised (level above the
  /// state), Override (same level, severity at least the outstanding's), Joined (same level, lower
  /// severity) or Masked (level below the state). `onset` must be an onset.
  ConditionChange onset(const Event& onset, const RootCause& root, Time now, std::uint64_t& activations);
  /// Rule 2 for a condition built by the caller (a mirror, or a root that arrived from another
  /// process): adds it as it is and reports Raised, Override, Joined or Masked.
  ConditionChange add(const Condition& condition);
  /// A completion of `onset` arrives (nullptr: the onset it completes is not defined). Ignored when
  /// the onset is undefined, when its root condition is not active (mirrors never match), or when
  /// the onset is latched; otherwise the root condition is removed (Cleared) and the state drops to
  /// the highest level that remains.
  ConditionChange complete(const Event* onset);
  /// Removes condition `index` (Cleared).
  ConditionChange remove(std::size_t index);
  /// A reset (§4.5): removes every root condition, latched ones too, lowest level first. Mirrors
  /// stay: they report faults whose roots are elsewhere. Returns how many were removed. (The
  /// coordinator resets several machines at once with find_lowest_root() and remove(), propagating
  /// after each removal; the rule is the same.)
  std::size_t reset();

  /// Reserves room for `n` conditions (so that adding up to `n` does not allocate).
  void reserve(std::size_t n);

private:
  const Condition* data() const noexcept { return on_heap_ ? heap_.data() : &first_; }
  Condition* data() noexcept { return on_heap_ ? heap_.data() : &first_; }
  void push(const Condition& c);
  void recompute() noexcept;

  // Most machines hold at most one condition at a time: it lives inline, next to the machine's
  // other data, so propagation through thousands of machines does not chase one heap block per
  // machine. From the second condition on, all of them live in heap_, which grows but never
  // shrinks (the set stays on the heap): after warm-up, changes do not allocate. The order of the
  // conditions is the same either way.
  Condition first_{};
  std::vector<Condition> heap_;
  std::uint32_t size_ = 0;
  bool on_heap_ = false;
  State state_ = State::Normal;
  std::int32_t outstanding_ = -1;
  std::uint32_t counts_[3] = {0, 0, 0};  ///< conditions per level
};

}  // namespace safecass
