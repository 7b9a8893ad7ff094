#include "safecass/filters/signal.hpp"

#include <bit>
#include <cstring>

namespace safecass {

namespace {
constexpr std::size_t kHeaderWords = 2;  // time, flags
constexpr std::uint64_t kInjectedFlag = 1;

std::size_t round_up_pow2(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}
}  // namespace

HistoryBuffer::HistoryBuffer(std::size_t width, std::size_t capacity)
    : width_(width),
      mask_(round_up_pow2(capacity < 2 ? 2 : capacity) - 1),
      slots_(std::make_unique<Slot[]>(mask_ + 1)),
      words_(std::make_unique<std::atomic<std::uint64_t>[]>((mask_ + 1) * (width + kHeaderWords))) {}

void HistoryBuffer::push(Time time, const double* values, bool injected) noexcept {
  const std::uint64_t index = head_.fetch_add(1, std::memory_order_acq_rel);
  Slot& slot = slots_[index & mask_];
  std::atomic<std::uint64_t>* w = &words_[(index & mask_) * (width_ + kHeaderWords)];
  slot.seq.store(2 * index + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  w[0].store(static_cast<std::uint64_t>(time.count()), std::memory_order_relaxed);
  w[1].store(injected ? kInjectedFlag : 0, std::memory_order_relaxed);
  for (std::size_t i = 0; i < width_; ++i) {
    w[kHeaderWords + i].store(std::bit_cast<std::uint64_t>(values[i]), std::memory_order_relaxed);
  }
  slot.seq.store(2 * index + 2, std::memory_order_release);
}

bool HistoryBuffer::read(std::uint64_t index, Time& time, double* out, bool& injected) const noexcept {
  const Slot& slot = slots_[index & mask_];
  const std::atomic<std::uint64_t>* w = &words_[(index & mask_) * (width_ + kHeaderWords)];
  const std::uint64_t before = slot.seq.load(std::memory_order_acquire);
  if (before != 2 * index + 2) return false;
  time = Time{static_cast<Time::rep>(w[0].load(std::memory_order_relaxed))};
  injected = (w[1].load(std::memory_order_relaxed) & kInjectedFlag) != 0;
  for (std::size_t i = 0; i < width_; ++i) {
    out[i] = std::bit_cast<double>(w[kHeaderWords + i].load(std::memory_order_relaxed));
  }
  std::atomic_thread_fence(std::memory_order_acquire);
  return slot.seq.load(std::memory_order_relaxed) == before;
}

Signal::Signal(std::string name, ComponentId component, std::size_t size, std::size_t history)
    : name_(std::move(name)), component_(component), buffer_(size, history) {}

bool Signal::latest(Time& time, double* out) const noexcept {
  bool injected = false;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t end = buffer_.end();
    if (end == 0) return false;
    if (buffer_.read(end - 1, time, out, injected)) return true;
    // The newest slot is still being written: the one before it is the newest published sample.
    if (end >= 2 && buffer_.read(end - 2, time, out, injected)) return true;
  }
  return false;
}

SignalCursor::SignalCursor(const Signal* signal)
    : signal_(signal), scratch_(signal != nullptr ? signal->size() : 0) {}

bool SignalCursor::next(SampleView& out) noexcept {
  if (signal_ == nullptr) return false;
  const HistoryBuffer& b = signal_->buffer();
  const std::uint64_t end = b.end();
  if (next_ >= end) return false;
  if (end - next_ > b.capacity()) {
    missed_ += end - next_ - b.capacity();
    next_ = end - b.capacity();
  }
  Time t{};
  bool injected = false;
  while (next_ < end) {
    if (b.read(next_, t, scratch_.data(), injected)) {
      ++next_;
      out = SampleView{t, scratch_.data(), scratch_.size(), injected};
      return true;
    }
    // Either not yet published (stop: read it next time) or overwritten (skip it).
    if (b.end() - next_ > b.capacity()) {
      ++missed_;
      ++next_;
      continue;
    }
    return false;
  }
  return false;
}

void SignalCursor::skip_to_end() noexcept {
  if (signal_ != nullptr) next_ = signal_->buffer().end();
}

Expected<Signal*> SignalRegistry::add(std::string_view name, ComponentId component, std::size_t size) {
  const auto dot = name.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 == name.size()) {
    return fail(ErrorCode::InvalidArgument, "signal name '" + std::string(name) + "' must be Component.signal");
  }
  if (size == 0) return fail(ErrorCode::InvalidArgument, "signal '" + std::string(name) + "' has size 0");
  if (Signal* s = find(name)) {
    if (s->size() != size) {
      return fail(ErrorCode::Duplicate, "signal '" + std::string(name) + "' already exists with size " +
                                            std::to_string(s->size()) + ", not " + std::to_string(size));
    }
    return s;
  }
  signals_.push_back(std::make_unique<Signal>(std::string(name), component, size, default_history_));
  return signals_.back().get();
}

Signal* SignalRegistry::find(std::string_view name) const noexcept {
  for (const auto& s : signals_) {
    if (s->name() == name) return s.get();
  }
  return nullptr;
}

}  // namespace safecass
