#pragma once
/// @file suggest.hpp
/// Did-you-mean suggestions for a misspelt name, as the spec's diagnostics give them; for tools
/// that report unknown names in other inputs (replayed logs).

#include <string>
#include <string_view>
#include <vector>

namespace safecass::spec {

/// "; did you mean 'x'?" when one candidate is near enough to be a likely typo, else "".
std::string suggest(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace safecass::spec
