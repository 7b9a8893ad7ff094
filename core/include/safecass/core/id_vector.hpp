#pragma once
/// @file id_vector.hpp
/// A std::vector indexed by one kind of id (ids.hpp) and by nothing else, so that a table of
/// machines cannot be read with a component id or with a bare integer by mistake.

#include <cstddef>
#include <vector>

#include "safecass/core/ids.hpp"

namespace safecass {

template <class T, class Id>
class IdVector : private std::vector<T> {
  using Base = std::vector<T>;

public:
  static_assert(is_id_v<Id>, "IdVector is indexed by an id type of ids.hpp");
  using typename Base::const_reference;
  using typename Base::reference;
  using typename Base::size_type;
  using typename Base::value_type;

  IdVector() = default;
  /// `n` copies of `value`.
  IdVector(std::size_t n, const T& value) : Base(n, value) {}
  explicit IdVector(std::size_t n) : Base(n) {}

  using Base::assign;
  using Base::begin;
  using Base::clear;
  using Base::empty;
  using Base::end;
  using Base::push_back;
  using Base::reserve;
  using Base::resize;
  using Base::size;

  reference operator[](Id id) { return Base::operator[](to_index(id)); }
  const_reference operator[](Id id) const { return Base::operator[](to_index(id)); }
  /// True when `id` names an element.
  bool contains(Id id) const noexcept { return to_index(id) < size(); }
  /// The ids of the elements, in order.
  IdRange<Id> ids() const noexcept { return id_range<Id>(size()); }
};

}  // namespace safecass
