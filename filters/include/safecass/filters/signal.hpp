#pragma once
/// @file signal.hpp
/// Signals (DESIGN §3): named `Component.signal`, scalar or fixed-size vector of doubles, each
/// sample timestamped, with a history buffer that keeps the recent samples.
///
/// Each signal has two lock-free rings that any number of readers follow:
/// - the **history buffer**, written by the signal's one writer (the component, or the filter whose
///   output it is) with plain stores and no read-modify-write: a push is a handful of stores;
/// - the **injection ring**, created on the first deep fault injection, written under a mutex by
///   any thread (tools), so an injection never races the writer.
/// Each injected sample remembers how many samples the history buffer held when it was injected;
/// a cursor merges the two rings in that order, so every consumer sees the samples in the order
/// they were written. A reader copies a slot and then checks, with the ring's head, that the
/// writer had not started to overwrite it (an overwriting ring: the newest capacity() samples are
/// always readable). Nothing allocates after construction, except the injection ring, once.
///
/// The hot paths (push, read, SignalCursor::next) are defined here so they inline into filters.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/ids.hpp"

namespace safecass {

/// A sample as read from a buffer: valid while the reader's scratch storage is not reused.
struct SampleView {
  Time time{};
  const double* data = nullptr;
  std::size_t size = 0;
  bool injected = false;  ///< written by fault injection
  double operator[](std::size_t i) const noexcept { return data[i]; }
  double scalar() const noexcept { return data[0]; }
};

/// Memory handed out in creation order from a few large blocks, each piece on a cache line of its
/// own, freed all at once or back to a mark. A registry keeps its signals in one and their
/// history buffers in another: what a cycle touches of N signals (each signal's first line, each
/// ring's current slot) then lies in a few dense blocks, wherever the heap puts the filters
/// created between them (docs/filters.md, "Memory layout"). Configuration time only.
class Arena {
public:
  /// What was allocated up to a point, to go back to.
  struct Mark {
    std::size_t blocks = 0;
    std::size_t used = 0;  ///< bytes used of the last block
  };
  /// New blocks hold `block_bytes`, or one piece larger than that.
  explicit Arena(std::size_t block_bytes) noexcept : block_bytes_(block_bytes) {}
  Arena(const Arena&) = delete;
  Arena& operator=(const Arena&) = delete;

  /// `bytes` of uninitialised memory, aligned to a cache line.
  void* allocate(std::size_t bytes);
  Mark mark() const noexcept { return Mark{blocks_.size(), blocks_.empty() ? 0 : blocks_.back().used}; }
  /// Frees what was allocated after `mark` (its objects already destroyed).
  void release(Mark mark) noexcept;

private:
  static constexpr std::size_t kLine = 64;
  struct Free {
    void operator()(std::byte* p) const noexcept { ::operator delete[](p, std::align_val_t{kLine}); }
  };
  struct Block {
    std::unique_ptr<std::byte[], Free> memory;
    std::size_t size = 0;
    std::size_t used = 0;
  };
  std::size_t block_bytes_;
  std::vector<Block> blocks_;
};

/// A ring of timestamped samples with one writer at a time and any number of lock-free readers.
/// Each slot holds the time, in a keyed ring an order key (see Signal), and width() doubles, stored as bit
/// patterns in relaxed atomics so that a reader racing the writer is well defined (the head check
/// discards such a copy).
class HistoryBuffer {
public:
  /// `width` doubles per sample; the ring has `capacity` rounded up to a power of two slots.
  /// `keyed`: each slot also keeps an order key (the injection ring; see Signal).
  HistoryBuffer(std::size_t width, std::size_t capacity, bool keyed = false);
  /// The same, its ring in `memory` (a registry's signals: SignalRegistry).
  HistoryBuffer(std::size_t width, std::size_t capacity, Arena& memory);
  HistoryBuffer(const HistoryBuffer&) = delete;
  HistoryBuffer& operator=(const HistoryBuffer&) = delete;

  std::size_t width() const noexcept { return width_; }
  /// How many of the newest samples are always readable: the ring's size minus one (the slot the
  /// writer fills next may be half-written).
  std::size_t capacity() const noexcept { return mask_; }

  /// Appends a sample (`values` holds width() doubles). One writer at a time; lock-free,
  /// allocation-free, no read-modify-write.
  void push(Time time, const double* values, std::uint64_t key = 0) noexcept {
    const std::uint64_t index = head_.load(std::memory_order_relaxed);
    // Orders the previous head store before this slot's stores (pairs with read()'s fence): a
    // reader that sees any of these stores then sees the head past the slot's previous sample.
    std::atomic_thread_fence(std::memory_order_release);
    std::atomic<std::uint64_t>* w = slot(index);
    w[0].store(static_cast<std::uint64_t>(time.count()), std::memory_order_relaxed);
    if (header_ == 2) w[1].store(key, std::memory_order_relaxed);
    if (width_ == 1) {
      store(w[header_], values[0]);  // scalars: no loop
    } else {
      for (std::size_t i = 0; i < width_; ++i) store(w[header_ + i], values[i]);
    }
    head_.store(index + 1, std::memory_order_release);
    // The next push writes the next slot, usually in a line no cache holds any more (a ring of
    // capacity() samples per signal, one push per cycle): fetch it now, while the loop goes on.
    const auto* next = reinterpret_cast<const char*>(slot(index + 1));
    __builtin_prefetch(next, 1);
    __builtin_prefetch(next + (stride_ * sizeof(std::uint64_t)) - 1, 1);
  }

  /// Index the next push will take: samples [end() - capacity(), end()) are readable.
  std::uint64_t end() const noexcept { return head_.load(std::memory_order_acquire); }

  /// Copies sample `index` into `out` (width() doubles). Returns false if that sample is not
  /// (yet, or any more) in the buffer. Lock-free, allocation-free.
  bool read(std::uint64_t index, Time& time, double* out, std::uint64_t* key = nullptr) const noexcept {
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    if (index >= head || head - index > mask_) return false;
    const std::atomic<std::uint64_t>* w = slot(index);
    time = Time{static_cast<Time::rep>(w[0].load(std::memory_order_relaxed))};
    if (key != nullptr) *key = header_ == 2 ? w[1].load(std::memory_order_relaxed) : 0;
    for (std::size_t i = 0; i < width_; ++i) out[i] = load(w[header_ + i]);
    std::atomic_thread_fence(std::memory_order_acquire);
    // The slot is rewritten by sample index + mask_ + 1, whose stores start after the head
    // reached index + mask_ + 1: while the head is below that, the copy is intact.
    return head_.load(std::memory_order_relaxed) - index <= mask_;
  }

  /// read() for a sample known to be published (index < a head loaded earlier); `head` is updated
  /// to the head seen after the copy.
  bool read_published(std::uint64_t index, Time& time, double* out, std::uint64_t& head) const noexcept {
    const std::atomic<std::uint64_t>* w = slot(index);
    time = Time{static_cast<Time::rep>(w[0].load(std::memory_order_relaxed))};
    if (width_ == 1) {
      out[0] = load(w[header_]);
    } else {
      for (std::size_t i = 0; i < width_; ++i) out[i] = load(w[header_ + i]);
    }
    std::atomic_thread_fence(std::memory_order_acquire);
    head = head_.load(std::memory_order_relaxed);
    return head - index <= mask_;
  }

private:
  std::atomic<std::uint64_t>* slot(std::uint64_t index) const noexcept { return &words_[(index & mask_) * stride_]; }
  // A double as the bits of a relaxed atomic word (std::bit_cast, in C++17).
  static void store(std::atomic<std::uint64_t>& word, double value) noexcept {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    word.store(bits, std::memory_order_relaxed);
  }
  static double load(const std::atomic<std::uint64_t>& word) noexcept {
    const std::uint64_t bits = word.load(std::memory_order_relaxed);
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  // Every reader loads the head along with these fields (they never change after construction),
  // so the head shares their cache line: a reader of a signal touches one line besides the slot.
  // A slot is the time, the order key in a keyed ring, then width_ values: 16 bytes for a scalar
  // of the writer's ring, four to a cache line (docs/filters.md, "Memory layout").
  std::size_t width_;
  std::size_t header_;  ///< words before the values: 1 (time) or 2 (time, key)
  std::size_t stride_;  ///< words per slot
  std::size_t mask_;
  std::atomic<std::uint64_t>* words_;  ///< the ring: in own_, or in an arena
  std::atomic<std::uint64_t> head_{0};
  std::unique_ptr<std::atomic<std::uint64_t>[]> own_;
};

/// A named signal with its history buffer and, after the first deep injection, its injection ring.
/// What every read and write touches (the injection ring's pointer, the buffer's fields and head)
/// is in the object's first cache line; the name and the injection's lock come after.
class alignas(64) Signal {
public:
  Signal(std::string name, ComponentId component, std::size_t size, std::size_t history);
  /// The same, its history buffer's ring in `rings` (SignalRegistry).
  Signal(std::string name, ComponentId component, std::size_t size, std::size_t history, Arena& rings);

  /// "Component.signal".
  const std::string& name() const noexcept { return name_; }
  ComponentId component() const noexcept { return component_; }
  /// Number of doubles per sample: 1 for a scalar.
  std::size_t size() const noexcept { return buffer_.width(); }
  NameId name_id() const noexcept { return name_id_; }
  void set_name_id(NameId id) noexcept { name_id_ = id; }

  /// Writes a scalar sample. From the signal's one writer; lock-free, allocation-free.
  void push(Time time, double value) noexcept { buffer_.push(time, &value); }
  /// Writes a vector sample of size() doubles. From the signal's one writer; lock-free,
  /// allocation-free.
  void push(Time time, const double* values) noexcept { buffer_.push(time, values); }
  /// Deep fault injection: a sample every consumer sees, after the samples written so far,
  /// marked as injected. From any thread (takes a mutex; allocates the injection ring once).
  void inject(Time time, const double* values);

  /// The writer's history buffer (without the injected samples).
  const HistoryBuffer& buffer() const noexcept { return buffer_; }
  /// The injected samples, or nullptr before the first injection. Lock-free.
  const HistoryBuffer* injections() const noexcept { return injections_.load(std::memory_order_acquire); }
  /// Samples ever written, injected ones included.
  std::uint64_t count() const noexcept;

  /// Copies the newest sample (written or injected) into `out`; false when the signal has none.
  bool latest(Time& time, double* out, bool* injected = nullptr) const noexcept;

private:
  std::atomic<const HistoryBuffer*> injections_{nullptr};
  HistoryBuffer buffer_;
  std::string name_;
  ComponentId component_;
  NameId name_id_ = kNoName;
  std::unique_ptr<HistoryBuffer> injection_ring_;  ///< owns *injections_
  std::mutex inject_mutex_;
};

/// Reads the samples of one signal in order (written and injected merged), remembering where it
/// stopped. One cursor per reader; a new cursor starts at the oldest readable sample.
class SignalCursor {
public:
  SignalCursor() = default;
  explicit SignalCursor(const Signal* signal);
  SignalCursor(const SignalCursor&) = delete;
  SignalCursor& operator=(const SignalCursor&) = delete;
  SignalCursor(SignalCursor&&) noexcept = default;
  SignalCursor& operator=(SignalCursor&&) noexcept = default;

  /// Reads the next unread sample into internal storage; false when there is none. Samples
  /// overwritten before they were read are skipped and counted in missed(). Lock-free,
  /// allocation-free.
  bool next(SampleView& out) noexcept {
    if (signal_ == nullptr) return false;
    if (const HistoryBuffer* inj = signal_->injections(); inj != nullptr && injected_next_ < inj->end()) {
      return next_merged(*inj, out);
    }
    return next_written(out);
  }
  /// Calls `f(sample)` for every unread sample, in order: the same samples as repeated next()
  /// calls, with the history buffer's head read once per sample instead of twice. Lock-free,
  /// allocation-free as long as `f` is.
  /// Always inlined: it is the loop of every filter's run() (docs/filters.md, "Memory layout").
  template <class F>
  [[gnu::always_inline]] void read_new(F&& f) noexcept(noexcept(f(std::declval<const SampleView&>()))) {
    if (signal_ == nullptr) return;
    SampleView sample;
    if (const HistoryBuffer* inj = signal_->injections(); inj != nullptr && injected_next_ < inj->end()) {
      while (next(sample)) f(static_cast<const SampleView&>(sample));
      return;
    }
    const HistoryBuffer& b = signal_->buffer();
    std::uint64_t end = b.end();
    if (next_ >= end) return;
    if (end - next_ > b.capacity()) {
      missed_ += end - next_ - b.capacity();
      next_ = end - b.capacity();
    }
    sample.size = width_;
    while (next_ < end) {
      double* const into = reading();  // f() may keep() the sample: the next goes to the other half
      if (b.read_published(next_, sample.time, into, end)) {
        ++next_;
        sample.data = into;
        f(static_cast<const SampleView&>(sample));
      } else {
        ++missed_;  // overwritten while we copied it
        ++next_;
      }
    }
  }
  /// Reads the next sample into `out` (size() doubles) when it is the only unread one and was
  /// written, not injected: true, and the cursor moves past it. Otherwise false, and nothing
  /// changes (read with next() or read_new()). Lock-free, allocation-free.
  bool take_single(Time& time, double* out) noexcept {
    if (signal_ == nullptr) return false;
    if (const HistoryBuffer* inj = signal_->injections(); inj != nullptr && injected_next_ < inj->end()) return false;
    const HistoryBuffer& b = signal_->buffer();
    std::uint64_t end = b.end();
    if (end != next_ + 1 || !b.read_published(next_, time, out, end)) return false;
    ++next_;
    return true;
  }
  /// Skips every sample written so far.
  void skip_to_end() noexcept;

  /// Samples are read into one of two buffers. keep() makes the sample just read (or staged)
  /// stay readable, as kept(), until the next keep(): the samples after it are read into the
  /// other buffer. A filter holds the last valid sample of an input this way, without a copy.
  void keep() noexcept {
    kept_ = static_cast<std::int8_t>(reading_);
    reading_ ^= 1U;
  }
  /// The sample of the last keep(), or nullptr.
  const double* kept() const noexcept {
    return kept_ < 0 ? nullptr : storage() + static_cast<std::size_t>(kept_) * width_;
  }
  /// Forgets the kept sample.
  void forget() noexcept { kept_ = -1; }
  /// Copies `values` (size() doubles from elsewhere, e.g. a shallow injection) to where the next
  /// sample would be read, so that it can be kept like one; returns that copy.
  const double* stage(const double* values) noexcept;
  /// Copies the signal's newest sample (Signal::latest) to where the next sample would be read,
  /// as stage() does, and skips every sample written so far; false when the signal has none.
  /// Lock-free, allocation-free.
  bool stage_latest(SampleView& out) noexcept;
  std::uint64_t missed() const noexcept { return missed_; }
  const Signal* signal() const noexcept { return signal_; }
  /// Moves this cursor to where `other`, a cursor of the same signal, stands: the next sample it
  /// reads is the one `other` reads next. The kept sample is forgotten.
  void follow(const SignalCursor& other) noexcept {
    next_ = other.next_;
    injected_next_ = other.injected_next_;
    kept_ = -1;
  }
  /// Whether a sample, written or injected, waits to be read. Lock-free.
  bool unread() const noexcept {
    if (signal_ == nullptr) return false;
    if (const HistoryBuffer* inj = signal_->injections(); inj != nullptr && injected_next_ < inj->end()) return true;
    return next_ < signal_->buffer().end();
  }
  /// Whether `other`, a cursor of the same signal, stands one written sample after this one.
  bool one_behind(const SignalCursor& other) const noexcept {
    return next_ + 1 == other.next_ && injected_next_ == other.injected_next_;
  }
  /// Whether this cursor and `other`, of the same signal, read the same sample next.
  bool level_with(const SignalCursor& other) const noexcept {
    return next_ == other.next_ && injected_next_ == other.injected_next_;
  }

private:
  bool next_written(SampleView& out) noexcept {
    const HistoryBuffer& b = signal_->buffer();
    for (;;) {
      const std::uint64_t end = b.end();
      if (next_ >= end) return false;
      if (end - next_ > b.capacity()) {
        missed_ += end - next_ - b.capacity();
        next_ = end - b.capacity();
      }
      if (b.read(next_, out.time, reading())) {
        ++next_;
        out.data = reading();
        out.size = width_;
        out.injected = false;
        return true;
      }
      ++missed_;  // overwritten while we copied it
      ++next_;
    }
  }
  bool next_merged(const HistoryBuffer& inj, SampleView& out) noexcept;
  /// Two samples: the kept one and the one being read. A scalar's are inside the cursor (read
  /// with the cursor's own cache line); a vector's in wide_. Halves are kept as indices, not
  /// pointers, so that a cursor can move.
  double* storage() noexcept { return width_ == 1 ? small_ : wide_.get(); }
  const double* storage() const noexcept { return width_ == 1 ? small_ : wide_.get(); }
  double* reading() noexcept { return storage() + static_cast<std::size_t>(reading_) * width_; }

  const Signal* signal_ = nullptr;
  std::uint64_t next_ = 0;           ///< next sample of the history buffer
  std::uint64_t injected_next_ = 0;  ///< next sample of the injection ring
  std::uint64_t missed_ = 0;
  std::uint32_t width_ = 0;   ///< doubles per sample (the signal's size)
  std::uint8_t reading_ = 0;  ///< the half the next sample is read into
  std::int8_t kept_ = -1;     ///< the half of the last keep(); -1: none
  double small_[2] = {0.0, 0.0};
  std::unique_ptr<double[]> wide_;  ///< 2 × width_ values, for a vector signal
};

/// The signals of one coordinator, by name. Signals are created during configuration; their
/// addresses are stable for the registry's lifetime. The signals and their history buffers are
/// kept in two arenas, in creation order (see Arena).
class SignalRegistry {
public:
  explicit SignalRegistry(std::size_t default_history = 1024) : default_history_(default_history) {}
  SignalRegistry(const SignalRegistry&) = delete;
  SignalRegistry& operator=(const SignalRegistry&) = delete;
  ~SignalRegistry();
  /// Creates `name` ("Component.signal") of `size` doubles. Errors: Duplicate (with a different
  /// size), InvalidArgument (size 0, malformed name). Creating an existing signal with the same
  /// size returns it.
  [[nodiscard]] Expected<Signal*> add(std::string_view name, ComponentId component, std::size_t size);
  Signal* find(std::string_view name) const noexcept;
  const std::vector<Signal*>& all() const noexcept { return signals_; }
  /// Removes the signals created after the first `count` (undoing a failed configuration step).
  void truncate(std::size_t count);

private:
  std::size_t default_history_;
  Arena headers_{std::size_t{64} << 10};                    ///< the Signal objects
  Arena rings_{std::size_t{1} << 20};                       ///< their history buffers' rings
  std::vector<Signal*> signals_;                            ///< in headers_, in creation order
  std::vector<std::pair<Arena::Mark, Arena::Mark>> marks_;  ///< before each signal: headers_, rings_
  std::unordered_map<std::string_view, Signal*> by_name_;   ///< keys: the signals' own names
};

}  // namespace safecass
