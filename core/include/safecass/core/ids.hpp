#pragma once
/// @file ids.hpp
/// Dense indices that name the parts of a coordinator's model. They are stable for the lifetime
/// of the coordinator and index its tables directly, so the hot path never looks up a string.
///
/// Each kind of id is its own type (a scoped enumeration over a 32-bit index), so one kind cannot
/// be passed where another is expected: a ComponentId given to a function that takes a MachineId,
/// or a plain integer given for any id, does not compile. Conversions are explicit and free:
/// `to_index(id)` gives the index, `MachineId{i}` (i a std::uint32_t) or `id_at<MachineId>(n)`
/// (any unsigned integer) gives the id. Ids compare with ==, != and < within one kind only.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace safecass {

enum class ComponentId : std::uint32_t {};   ///< a component of the coordinator
enum class MachineId : std::uint32_t {};     ///< a state machine (s_F, s_A, s_P.p, s_R.r)
enum class EventId : std::uint32_t {};       ///< an event definition
enum class ConnectionId : std::uint32_t {};  ///< a connection required → provided
enum class NameId : std::uint32_t {};        ///< an interned string (filter, signal, reason, ...)

/// True for the id types above (and only for them).
template <class T>
inline constexpr bool is_id_v =
    std::is_same_v<T, ComponentId> || std::is_same_v<T, MachineId> || std::is_same_v<T, EventId> ||
    std::is_same_v<T, ConnectionId> || std::is_same_v<T, NameId>;

/// The index an id stands for.
template <class Id, std::enable_if_t<is_id_v<Id>, int> = 0>
constexpr std::uint32_t to_index(Id id) noexcept {
  return static_cast<std::uint32_t>(id);
}

/// The id of index `i` (for example a table's size); `i` must fit in 32 bits.
template <class Id, class Int, std::enable_if_t<is_id_v<Id> && std::is_unsigned_v<Int>, int> = 0>
constexpr Id id_at(Int i) noexcept {
  return static_cast<Id>(static_cast<std::uint32_t>(i));
}

/// The ids [first, last) in order, for range-for: `for (MachineId m : id_range<MachineId>(n))`.
template <class Id>
class IdRange {
public:
  class iterator {
  public:
    constexpr explicit iterator(std::uint32_t i) noexcept : i_(i) {}
    constexpr Id operator*() const noexcept { return static_cast<Id>(i_); }
    constexpr iterator& operator++() noexcept {
      ++i_;
      return *this;
    }
    constexpr bool operator==(const iterator& o) const noexcept { return i_ == o.i_; }
    constexpr bool operator!=(const iterator& o) const noexcept { return i_ != o.i_; }

  private:
    std::uint32_t i_;
  };
  constexpr IdRange(std::uint32_t first, std::uint32_t last) noexcept : first_(first), last_(last) {}
  constexpr iterator begin() const noexcept { return iterator(first_); }
  constexpr iterator end() const noexcept { return iterator(last_); }

private:
  std::uint32_t first_;
  std::uint32_t last_;
};

/// The ids of a table of `count` elements: index 0 to count - 1.
template <class Id, std::enable_if_t<is_id_v<Id>, int> = 0>
constexpr IdRange<Id> id_range(std::size_t count) noexcept {
  return IdRange<Id>(0, static_cast<std::uint32_t>(count));
}
/// The ids from `first` (included) to index `last` (excluded).
template <class Id, std::enable_if_t<is_id_v<Id>, int> = 0>
constexpr IdRange<Id> id_range(Id first, std::size_t last) noexcept {
  return IdRange<Id>(to_index(first), static_cast<std::uint32_t>(last));
}

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
inline constexpr EventId kNoEvent{kNone};
inline constexpr MachineId kNoMachine{kNone};
inline constexpr ComponentId kNoComponent{kNone};
inline constexpr ConnectionId kNoConnection{kNone};
inline constexpr NameId kNoName{kNone};

}  // namespace safecass
