#pragma once
/// @file assert.hpp
/// Broken invariants are bugs (STYLE tier 3): they call a replaceable fatal handler.

namespace safecass {

using FatalHandler = void (*)(const char* expression, const char* file, int line) noexcept;

/// Replaces the handler called when an invariant fails; returns the previous one.
/// The default prints the failed expression and aborts.
FatalHandler set_fatal_handler(FatalHandler handler) noexcept;

namespace detail {
[[noreturn]] void assertion_failed(const char* expression, const char* file, int line) noexcept;
}  // namespace detail

}  // namespace safecass

#define SAFECASS_ASSERT(expr) \
  ((expr) ? static_cast<void>(0) : ::safecass::detail::assertion_failed(#expr, __FILE__, __LINE__))
