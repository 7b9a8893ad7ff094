#pragma once
/// @file expected.hpp
/// Recoverable API errors (STYLE "Errors, in three tiers", tier 2).

#include <string>
#include <utility>

#include <tl/expected.hpp>

namespace safecass {

/// What kind of recoverable error happened; the message says which thing and why.
enum class ErrorCode {
  Duplicate,        ///< a name that must be unique is used twice
  NotFound,         ///< a name or address that does not exist
  InvalidArgument,  ///< a value outside its range or of the wrong shape
  InvalidState,     ///< the operation is not allowed in the current state
  Io,               ///< a file could not be read or written
  Parse,            ///< malformed input text
  Denied,           ///< refused for lack of write access
};

struct Error {
  ErrorCode code;
  std::string message;
};

template <class T>
using Expected = tl::expected<T, Error>;

/// Builds the error side of an Expected: `return fail(ErrorCode::NotFound, "no component 'X'");`
inline tl::unexpected<Error> fail(ErrorCode code, std::string message) {
  return tl::unexpected<Error>(Error{code, std::move(message)});
}

}  // namespace safecass
