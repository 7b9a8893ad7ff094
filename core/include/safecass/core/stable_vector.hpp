#pragma once
/// @file stable_vector.hpp
/// A growable array whose elements never move, for the coordinator's per-machine and
/// per-component data: a reference handed out stays valid while the model grows.

#include <cstddef>
#include <memory>
#include <vector>

#include "safecass/core/ids.hpp"

namespace safecass::detail {

/// Chunks of `kChunk` contiguous elements. Indexing is a shift, a mask and two loads, without
/// allocation or lock; adding allocates one chunk per `kChunk` elements. Not thread-safe against a
/// concurrent add. Indexed by the id type `Id`.
template <class T, class Id>
class StableVector {
public:
  static constexpr std::size_t kChunkBits = 6;
  static constexpr std::size_t kChunk = std::size_t{1} << kChunkBits;

  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  T& operator[](Id id) noexcept { return at(to_index(id)); }
  const T& operator[](Id id) const noexcept { return at(to_index(id)); }
  /// True when `id` names an element.
  bool contains(Id id) const noexcept { return to_index(id) < size_; }
  T& back() noexcept { return at(size_ - 1); }
  /// Appends a default-constructed element and returns it.
  T& emplace_back() {
    if ((size_ >> kChunkBits) == chunks_.size()) chunks_.push_back(std::make_unique<T[]>(kChunk));
    return at(size_++);
  }

private:
  T& at(std::size_t i) noexcept { return chunks_[i >> kChunkBits][i & (kChunk - 1)]; }
  const T& at(std::size_t i) const noexcept { return chunks_[i >> kChunkBits][i & (kChunk - 1)]; }

  std::vector<std::unique_ptr<T[]>> chunks_;
  std::size_t size_ = 0;
};

}  // namespace safecass::detail
