#pragma once
// Internal: how a sequence is read from a bus message. Included by the generated Slice header
// (cpp:include) and source (slice2cpp --add-header), and before the generated header by every file
// that decodes one, so that one reader serves them all.
//
// Ice 3.7 checks a sequence's declared size against the bytes left as `size * minWireSize` in 32
// bits: a size near 2^31 / minWireSize wraps the product and passes, and the vector of that many
// elements is then allocated and built (gigabytes, from a message of a few dozen bytes). A member
// holds a valid key, so its payload reaches the decoder (found by tests/fuzz/wire_events_fuzz.cpp).
// Here the bound is checked in 64 bits: a sequence of more elements than the bytes left can hold
// is refused (UnmarshalOutOfBoundsException, which decode() turns into a refusal), so what a
// message makes us allocate is bounded by its size.
//
// Sequences of bytes, ints, doubles and strings are read by libIce's own functions, which a
// template cannot replace, and the same wrap there is worse: a byte sequence declaring nearly 2^31
// bytes passes the check and is copied from far past the message (a crash, before any signature
// is checked). So the Slice file declares those sequences as `bounded::List`s of ours
// (cpp:type), read here with the bound in 64 bits too.

#include <Ice/Ice.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace safecass::bounded {

/// A std::vector that the bus reads with its size bounded by the bytes left (see above); it
/// converts to and from std::vector freely.
template <class E>
struct List : std::vector<E> {
  using std::vector<E>::vector;
  List() = default;
  List(const std::vector<E>& v) : std::vector<E>(v) {}                 // NOLINT(google-explicit-constructor)
  List(std::vector<E>&& v) noexcept : std::vector<E>(std::move(v)) {}  // NOLINT(google-explicit-constructor)
};
using Bytes = List<Ice::Byte>;
using Ints = List<Ice::Int>;
using Longs = List<Ice::Long>;
using Doubles = List<Ice::Double>;
using Strings = List<std::string>;

/// The fewest bytes an element takes on the wire.
template <class E>
constexpr std::int64_t wire_bytes() {
  return std::is_arithmetic_v<E> ? static_cast<std::int64_t>(sizeof(E)) : 1;  // a string: its size
}

/// Reads a sequence's size; refuses one of more elements, of at least `min_bytes` each, than the
/// bytes left can hold (the bound in 64 bits).
template <class S>
Ice::Int read_count(S* stream, std::int64_t min_bytes) {
  const Ice::Int size = stream->readSize();
  const std::int64_t left = stream->b.end() - stream->i;
  if (static_cast<std::int64_t>(size) * min_bytes > left) throw Ice::UnmarshalOutOfBoundsException(__FILE__, __LINE__);
  return size;
}

}  // namespace safecass::bounded

namespace Ice {

template <typename E>
struct StreamHelper<safecass::bounded::List<E>, StreamHelperCategorySequence> {
  template <class S>
  static void write(S* stream, const safecass::bounded::List<E>& v) {
    stream->write(static_cast<const std::vector<E>&>(v));
  }

  template <class S>
  static void read(S* stream, safecass::bounded::List<E>& v) {
    const Int size = safecass::bounded::read_count(stream, safecass::bounded::wire_bytes<E>());
    if constexpr (std::is_same_v<E, Ice::Byte>) {
      v.assign(stream->i, stream->i + size);
      stream->i += size;
    } else {
      v.assign(static_cast<std::size_t>(size), E{});
      for (E& e : v) stream->read(e);
    }
  }
};

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
    const Int size = safecass::bounded::read_count(stream, StreamableTraits<E>::minWireSize);
    v.resize(
        static_cast<std::size_t>(size));  // a container read again keeps what it holds: reading overwrites every field
    for (E& e : v) stream->read(e);
  }
};

}  // namespace Ice
