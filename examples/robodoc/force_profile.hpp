#pragma once
/// @file force_profile.hpp
/// A force over time for the simulated JR3 sensors of the ROBODOC examples (ROS 1 and ROS 2):
/// "T:FZ,T:FZ,..." (seconds since start, newtons), linear between points, held after the last.
/// Plain C++17, header-only.

#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace robodoc {

using ForceProfile = std::vector<std::pair<double, double>>;

/// False for text that is not "T:FZ,..." with increasing times.
inline bool parse_force_profile(const std::string& text, ForceProfile& out) {
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) return false;
    char* end = nullptr;
    const double t = std::strtod(item.c_str(), &end);
    if (end != item.c_str() + colon) return false;
    const double v = std::strtod(item.c_str() + colon + 1, &end);
    if (*end != '\0' || (!out.empty() && t < out.back().first)) return false;
    out.emplace_back(t, v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return !out.empty();
}

inline double force_at(const ForceProfile& p, double t) {
  if (t <= p.front().first) return p.front().second;
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (t <= p[i].first) {
      const double span = p[i].first - p[i - 1].first;
      const double a = span > 0 ? (t - p[i - 1].first) / span : 1.0;
      return p[i - 1].second + a * (p[i].second - p[i - 1].second);
    }
  }
  return p.back().second;
}

/// The JR3's own health check, as its driver reports it on /diagnostics: WARN above 38 N.
inline constexpr double kSaturationWarning = 38.0;

}  // namespace robodoc
