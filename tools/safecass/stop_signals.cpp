// Waiting for SIGINT/SIGTERM or a deadline (stop_signals.hpp).

#include "stop_signals.hpp"

#include <pthread.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace safecass::tools {

StopSignals::StopSignals() {
  sigemptyset(&stop_);
  sigaddset(&stop_, SIGINT);
  sigaddset(&stop_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_, &before_);
}

StopSignals::~StopSignals() {
  // A signal that came after the wait (a second Ctrl-C while the run stops) belongs to this run:
  // taken here, so that restoring the mask does not hand it to the default action (a kill).
  const timespec none{0, 0};
  while (sigtimedwait(&stop_, nullptr, &none) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &before_, nullptr);
}

bool StopSignals::wait(std::optional<std::chrono::steady_clock::time_point> deadline) const {
  using namespace std::chrono;
  for (;;) {
    // Slices of at most an hour: a deadline far away (or none) never overflows a timespec.
    nanoseconds left = hours(1);
    if (deadline) {
      left = std::min(left, duration_cast<nanoseconds>(*deadline - steady_clock::now()));
      if (left <= nanoseconds::zero()) return false;
    }
    const timespec slice{static_cast<std::time_t>(duration_cast<seconds>(left).count()),
                         static_cast<long>((left % seconds(1)).count())};
    if (sigtimedwait(&stop_, nullptr, &slice) >= 0) return true;
    // EAGAIN: the slice ended; EINTR: another signal's handler ran. Either way, look again.
    if (errno != EAGAIN && errno != EINTR) return false;
  }
}

std::optional<std::chrono::steady_clock::time_point> deadline_after(double seconds) {
  if (!(seconds > 0)) return std::nullopt;
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace safecass::tools
