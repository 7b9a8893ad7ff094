#pragma once
/// @file supervisor.hpp
/// The supervisor (DESIGN §4): subscribes to everything every coordinator publishes, holds the
/// system-wide view, and detects a lost coordinator by its missing heartbeat. Losing one raises
/// EVT_COORDINATOR_LOST (severity 240) on the framework machine (s_F) of each of its components in
/// the supervisor's own model of the whole system, from where propagation marks everything
/// connected to it; a heartbeat from it again completes the event. Both are in the model's
/// history and in the printed output.
///
/// Threads: Ice's dispatch thread applies messages; a watch thread checks heartbeats. All
/// accessors are thread-safe. Lifecycle: create → start → stop (or destructor).

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

struct SupervisorOptions {
  IceEndpoint ice;
  std::string listen_host = "127.0.0.1";
  /// A coordinator is lost when no heartbeat arrived for this long.
  std::chrono::milliseconds lost_after{600};
  /// The system's bus keys (keys.hpp; the supervisor signs as "supervisor"). Empty: $SAFECASS_KEYS.
  std::string keys_dir;
  /// Mutual TLS; the certificate name defaults to "supervisor".
  TlsOptions tls;
  /// Accept a non-loopback endpoint without TLS (docs/security.md).
  bool insecure = false;
  /// Receives each output line (transitions as they arrive, lost/recovered). Default: stdout.
  std::function<void(const std::string&)> print;
};

/// One line of the system-wide view.
struct ViewRow {
  std::string coordinator;
  std::string address;
  State state = State::Normal;
  std::string cause;  ///< "origin:event" of the last transition, empty when Normal
};

class Supervisor {
public:
  /// `system` must outlive the supervisor. Errors: as spec::instantiate.
  [[nodiscard]] static Expected<std::unique_ptr<Supervisor>> create(const spec::SystemSpec& system,
                                                                    SupervisorOptions options);
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Connects to IceStorm in the background (retrying) and starts watching heartbeats.
  [[nodiscard]] Expected<void> start();
  void stop() noexcept;

  /// The last known state of every address a coordinator reported, sorted by address.
  std::vector<ViewRow> view() const;
  /// Bus messages refused (unauthenticated, forged, replayed or malformed).
  std::uint64_t messages_refused() const;
  /// Names of the coordinators currently lost.
  std::vector<std::string> lost() const;
  /// The supervisor's model of the system (EVT_COORDINATOR_LOST lives here). Read it with the
  /// Coordinator's thread-safe reads (state, explain, history).
  const Coordinator& model() const;

  struct Impl;

private:
  explicit Supervisor(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::middleware
