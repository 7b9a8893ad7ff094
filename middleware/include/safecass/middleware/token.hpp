#pragma once
/// @file token.hpp
/// The write token (DESIGN §7 "nothing let in"): a coordinator started with --allow-write creates
/// a file readable only by its owner (mode 0600) that holds a random secret; a tool that wants to
/// inject, generate, broadcast or reset reads it and sends it with the request.

#include <string>
#include <string_view>

#include "safecass/core/expected.hpp"

namespace safecass::middleware {

/// Creates (or replaces) `path` with mode 0600 holding a new 256-bit random secret as 64 hex
/// digits and a newline; returns the secret. Errors: Io (with the path and the reason).
Expected<std::string> create_token_file(const std::string& path);
/// Reads a token file written by create_token_file(). Errors: Io, Parse (not a token).
Expected<std::string> read_token_file(const std::string& path);
/// "$XDG_RUNTIME_DIR/safecass-<coordinator>-<pid>.token", or under /tmp without XDG_RUNTIME_DIR.
std::string default_token_path(std::string_view coordinator);
/// Compares in time independent of where the strings differ.
bool token_matches(std::string_view expected, std::string_view given) noexcept;

}  // namespace safecass::middleware
