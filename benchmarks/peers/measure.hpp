#pragma once
// What every peer program measures the same way (C++17: the ROS 1 peers include it too):
// CPU time and memory of a process read from /proc, the host's monotonic clock, percentiles.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace peers {

/// The host's monotonic clock in ns: the same time line in every process of the machine.
inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// CPU seconds (user + system) a process has used so far, from /proc/PID/stat; -1 if unreadable.
inline double cpu_seconds(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  if (close == std::string::npos) return -1.0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  // After "pid (comm) ": state is field 3; utime and stime are fields 14 and 15.
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

/// A "VmRSS" / "VmHWM" line of /proc/PID/status in bytes; -1 if unreadable.
inline double status_bytes(int pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size() + 1, key + ":") == 0) return std::stod(line.substr(key.size() + 1)) * 1024.0;
  }
  return -1.0;
}

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

/// {"p50_us", "p99_us", "max_us", "samples"} of latencies in µs, as JSON members (no braces).
inline std::string latency_members(const std::vector<double>& us) {
  char text[256];
  const double max = us.empty() ? 0.0 : *std::max_element(us.begin(), us.end());
  std::snprintf(text, sizeof text, "\"p50_us\": %.1f, \"p99_us\": %.1f, \"max_us\": %.1f, \"samples\": %zu",
                percentile(us, 0.50), percentile(us, 0.99), max, us.size());
  return text;
}

}  // namespace peers
