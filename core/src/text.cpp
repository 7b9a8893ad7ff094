#include "safecass/core/text.hpp"

#include <fmt/format.h>

namespace safecass {

std::string number_text(double v) { return fmt::format("{:.9g}", v); }

std::string seconds_text(Time t) { return fmt::format("{:.6f}", to_seconds(t)); }

}  // namespace safecass
