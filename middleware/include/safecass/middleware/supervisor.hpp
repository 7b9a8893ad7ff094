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
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/model.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

class SupervisorLine;

struct SupervisorOptions {
  IceEndpoint ice;
  std::string listen_host = "127.0.0.1";
  /// A coordinator is lost when no heartbeat arrived for this long: since its last one, or, for
  /// one never heard from, since the supervisor first connected to IceStorm.
  std::chrono::milliseconds lost_after{600};
  /// The system's bus keys (keys.hpp; the supervisor signs as "supervisor"). Empty: $SAFECASS_KEYS.
  std::string keys_dir;
  /// Mutual TLS; the certificate name defaults to "supervisor".
  TlsOptions tls;
  /// Accept a non-loopback endpoint without TLS (docs/security.md).
  bool insecure = false;
  /// Follow the event records (safecass.events): every transition of every machine and component,
  /// the system-wide history. false: the state topics and heartbeats only, so the view holds the
  /// provided interfaces' service states with their root causes (what a status aggregator shows),
  /// at a fraction of the cost; a lost or stale state stream is detected from the heartbeats and
  /// resynchronised (docs/middleware.md, "The supervisor").
  bool records = true;
  /// The filter types of the system file (an application's own included); it must outlive the
  /// supervisor. Null: the built-in types.
  const FilterRegistry* registry = nullptr;
  /// Receives each output line (transitions as they arrive, states, lost/recovered). The line is
  /// formatted only when the consumer calls text(). Default: `print`.
  std::function<void(const SupervisorLine&)> output;
  /// Receives the text of each output line when `output` is not set. Default: stdout.
  std::function<void(const std::string&)> print;
};

/// One line of the supervisor's output, formatted by the read model's formatter
/// (introspect::live_line, live_state_line) only when text() is called: a consumer that counts or
/// filters lines does not pay for their text. Valid only during the call that receives it.
class SupervisorLine {
public:
  enum class Kind : std::uint8_t {
    Record,  ///< a transition or reset a coordinator reported (or one in the supervisor's own model)
    State,   ///< a service state a coordinator reported, a row refreshed, or a row of the view
    Notice,  ///< the supervisor's own notices: connected, up, lost, recovered, missed, refused
  };
  /// "[COORDINATOR] " + introspect::live_line(record), or "supervisor: " + it for the supervisor's
  /// own model (coordinator empty); with a note, " (NOTE)" after it (a record that arrived after
  /// newer ones says so).
  static SupervisorLine of_record(std::string_view coordinator, const introspect::HistoryEntry& record,
                                  std::string_view note = {}) noexcept;
  /// "[COORDINATOR] " + introspect::live_state_line(address, state, note).
  static SupervisorLine of_state(std::string_view coordinator, std::string_view address, State state,
                                 std::string_view note) noexcept;
  static SupervisorLine notice(std::string_view text) noexcept;

  Kind kind() const noexcept { return kind_; }
  /// The coordinator that reported it (empty: the supervisor itself).
  std::string_view coordinator() const noexcept { return coordinator_; }
  /// The record of a Record line, else nullptr.
  const introspect::HistoryEntry* record() const noexcept { return record_; }
  /// The line as printed: one line, names from messages escaped (no control character, so a
  /// forged name cannot add a line).
  std::string text() const;

private:
  SupervisorLine() = default;
  Kind kind_ = Kind::Notice;
  std::string_view coordinator_;
  const introspect::HistoryEntry* record_ = nullptr;
  std::string_view address_;
  State state_ = State::Normal;
  std::string_view note_;
};

/// One line of the system-wide view.
struct ViewRow {
  std::string coordinator;
  std::string address;
  State state = State::Normal;
  std::string cause;  ///< "origin:event" of the last transition (a service: "origin:event, ..."), empty when Normal
  /// The coordinator's record that set it (its seq), so that a record arriving late never takes
  /// the row back to an older state; 0 when a state update set it.
  std::int64_t record_seq = 0;
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
