#pragma once
// Internal: how a sequence of structs or strings is read from a bus message. Included before the
// generated Slice header by every file that decodes one, and by the generated source itself
// (slice2cpp --add-header), so that one reader serves them all.
//
// Ice 3.7 checks a sequence's declared size against the bytes left as `size * minWireSize` in 32
// bits: a size near 2^31 / minWireSize wraps the product and passes, and the vector of that many
// elements is then allocated and built (gigabytes, from a message of a few dozen bytes). A member
// holds a valid key, so its payload reaches the decoder (found by tests/fuzz/wire_events_fuzz.cpp).
// Here the bound is checked in 64 bits: a sequence of more elements than the bytes left can hold
// is refused (UnmarshalOutOfBoundsException, which decode() turns into a refusal), so what a
// message makes us allocate is bounded by its size.

#include <Ice/Ice.h>

#include <cstdint>
#include <type_traits>
#include <vector>

namespace Ice {

template <typename E>
requires std::is_class_v<E>
struct StreamHelper<std::vector<E>, StreamHelperCategorySequence> {
  template <class S>
  static void write(S* stream, const std::vector<E>& v) {
    stream->writeSize(static_cast<Int>(v.size()));
    for (const E& e : v) stream->write(e);
  }

  template <class S>
  static void read(S* stream, std::vector<E>& v) {
    const Int size = stream->readSize();
    const std::int64_t left = stream->b.end() - stream->i;
    if (static_cast<std::int64_t>(size) * StreamableTraits<E>::minWireSize > left) {
      throw UnmarshalOutOfBoundsException(__FILE__, __LINE__);
    }
    std::vector<E>(static_cast<std::size_t>(size)).swap(v);
    for (E& e : v) stream->read(e);
  }
};

}  // namespace Ice
