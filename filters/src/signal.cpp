#include "safecass/filters/signal.hpp"

#include <algorithm>
#include <new>

namespace safecass {

namespace {
std::size_t round_up_pow2(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}
}  // namespace

void* Arena::allocate(std::size_t bytes) {
  bytes = (bytes + kLine - 1) / kLine * kLine;
  if (blocks_.empty() || blocks_.back().size - blocks_.back().used < bytes) {
    const std::size_t size = std::max(bytes, block_bytes_);
    blocks_.push_back(Block{
        std::unique_ptr<std::byte[], Free>(static_cast<std::byte*>(::operator new[](size, std::align_val_t{kLine}))),
        size, 0});
  }
  Block& b = blocks_.back();
  void* p = b.memory.get() + b.used;
  b.used += bytes;
  return p;
}

void Arena::release(Mark mark) noexcept {
  while (blocks_.size() > mark.blocks) blocks_.pop_back();
  if (!blocks_.empty()) blocks_.back().used = mark.used;
}

HistoryBuffer::HistoryBuffer(std::size_t width, std::size_t capacity, bool keyed)
    : width_(width),
      header_(keyed ? 2 : 1),
      stride_(width + header_),
      mask_(round_up_pow2(capacity < 2 ? 2 : capacity) - 1),
      words_(nullptr),
      own_(std::make_unique<std::atomic<std::uint64_t>[]>((mask_ + 1) * stride_)) {
  words_ = own_.get();
}

HistoryBuffer::HistoryBuffer(std::size_t width, std::size_t capacity, Arena& memory)
    : width_(width), header_(1), stride_(width + header_), mask_(round_up_pow2(capacity < 2 ? 2 : capacity) - 1) {
  const std::size_t words = (mask_ + 1) * stride_;
  // A line more than the ring: the rings of a registry then lie one line apart modulo a page, so
  // the slots that every ring writes in one cycle (the same index in each) fall into different
  // cache sets instead of all into one (docs/filters.md, "Memory layout").
  constexpr std::size_t kStagger = 64;
  words_ =
      static_cast<std::atomic<std::uint64_t>*>(memory.allocate(words * sizeof(std::atomic<std::uint64_t>) + kStagger));
  for (std::size_t i = 0; i < words; ++i) new (&words_[i]) std::atomic<std::uint64_t>(0);
}

Signal::Signal(std::string name, ComponentId component, std::size_t size, std::size_t history)
    : buffer_(size, history), name_(std::move(name)), component_(component) {}

Signal::Signal(std::string name, ComponentId component, std::size_t size, std::size_t history, Arena& rings)
    : buffer_(size, history, rings), name_(std::move(name)), component_(component) {}

void Signal::inject(Time time, const double* values) {
  std::lock_guard lock(inject_mutex_);
  if (!injection_ring_) {
    injection_ring_ = std::make_unique<HistoryBuffer>(size(), buffer_.capacity() + 1, true);
    injections_.store(injection_ring_.get(), std::memory_order_release);
  }
  // The key places the sample after every sample written so far (see SignalCursor).
  injection_ring_->push(time, values, buffer_.end());
}

std::uint64_t Signal::count() const noexcept {
  const HistoryBuffer* inj = injections();
  return buffer_.end() + (inj != nullptr ? inj->end() : 0);
}

bool Signal::latest(Time& time, double* out, bool* injected) const noexcept {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t written = buffer_.end();
    const HistoryBuffer* inj = injections();
    const std::uint64_t n = inj != nullptr ? inj->end() : 0;
    if (n > 0) {
      std::uint64_t key = 0;
      if (!inj->read(n - 1, time, out, &key)) continue;  // overwritten by a concurrent injection
      if (key >= written) {
        if (injected != nullptr) *injected = true;
        return true;
      }
    }
    if (written == 0) return false;
    if (buffer_.read(written - 1, time, out)) {
      if (injected != nullptr) *injected = false;
      return true;
    }
  }
  return false;
}

SignalCursor::SignalCursor(const Signal* signal)
    : signal_(signal),
      width_(signal != nullptr ? static_cast<std::uint32_t>(signal->size()) : 0),
      wide_(width_ > 1 ? std::make_unique<double[]>(2 * std::size_t{width_}) : nullptr) {}

const double* SignalCursor::stage(const double* values) noexcept {
  double* into = reading();
  std::copy(values, values + width_, into);
  return into;
}

bool SignalCursor::stage_latest(SampleView& out) noexcept {
  if (signal_ == nullptr) return false;
  skip_to_end();
  bool injected = false;
  if (!signal_->latest(out.time, reading(), &injected)) return false;
  out.data = reading();
  out.size = width_;
  out.injected = injected;
  return true;
}

bool SignalCursor::next_merged(const HistoryBuffer& inj, SampleView& out) noexcept {
  for (;;) {
    const std::uint64_t end = inj.end();
    if (injected_next_ >= end) return next_written(out);
    if (end - injected_next_ > inj.capacity()) {
      missed_ += end - injected_next_ - inj.capacity();
      injected_next_ = end - inj.capacity();
    }
    std::uint64_t key = 0;
    Time t{};
    if (!inj.read(injected_next_, t, reading(), &key)) {
      ++missed_;  // overwritten while we copied it
      ++injected_next_;
      continue;
    }
    // Samples written before the injection come first. If they are gone, next_written() returns
    // false with next_ past them, and the injected sample is read again on the next pass.
    if (next_ < key) {
      if (next_written(out)) return true;
      continue;
    }
    ++injected_next_;
    out.time = t;
    out.data = reading();
    out.size = width_;
    out.injected = true;
    return true;
  }
}

void SignalCursor::skip_to_end() noexcept {
  if (signal_ == nullptr) return;
  next_ = signal_->buffer().end();
  const HistoryBuffer* inj = signal_->injections();
  injected_next_ = inj != nullptr ? inj->end() : 0;
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
  // Its places first (amortised growth), so that nothing can fail once it is built.
  marks_.emplace_back(headers_.mark(), rings_.mark());
  signals_.push_back(nullptr);
  Signal* s = nullptr;
  try {
    s = new (headers_.allocate(sizeof(Signal))) Signal(std::string(name), component, size, default_history_, rings_);
    by_name_.emplace(s->name(), s);
  } catch (...) {
    if (s != nullptr) s->~Signal();
    headers_.release(marks_.back().first);
    rings_.release(marks_.back().second);
    signals_.pop_back();
    marks_.pop_back();
    throw;
  }
  signals_.back() = s;
  return s;
}

SignalRegistry::~SignalRegistry() { truncate(0); }

Signal* SignalRegistry::find(std::string_view name) const noexcept {
  const auto it = by_name_.find(name);
  return it == by_name_.end() ? nullptr : it->second;
}

void SignalRegistry::truncate(std::size_t count) {
  if (signals_.size() <= count) return;
  for (std::size_t i = signals_.size(); i-- > count;) {
    by_name_.erase(signals_[i]->name());
    signals_[i]->~Signal();
  }
  headers_.release(marks_[count].first);
  rings_.release(marks_[count].second);
  signals_.resize(count);
  marks_.resize(count);
}

}  // namespace safecass
