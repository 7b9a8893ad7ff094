#pragma once
// How a long-running command (`safecass run --coordinator`, `safecass supervisor`) waits for its end:
// SIGINT or SIGTERM, or the end of its --duration. The signals are blocked from the start, before
// any thread exists (every thread inherits the mask, so none is interrupted by them), and the main
// thread takes them with sigtimedwait: it sleeps until one comes or the time is up, instead of
// waking a hundred times a second to look at a flag.

#include <chrono>
#include <csignal>
#include <optional>

namespace safecass::tools {

class StopSignals {
public:
  /// Blocks SIGINT and SIGTERM in the calling thread (the main one, before it starts any other).
  StopSignals();
  /// Takes any stop signal still pending, then restores the signal mask found at construction.
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// Waits until SIGINT or SIGTERM comes (true), or until `deadline` has passed (false); without
  /// a deadline, until a signal comes. A signal that came before the call ends it at once.
  bool wait(std::optional<std::chrono::steady_clock::time_point> deadline) const;

private:
  sigset_t stop_;
  sigset_t before_;
};

/// The end of a run of `seconds` from now; none (until a signal) when `seconds` is not positive.
std::optional<std::chrono::steady_clock::time_point> deadline_after(double seconds);

}  // namespace safecass::tools
