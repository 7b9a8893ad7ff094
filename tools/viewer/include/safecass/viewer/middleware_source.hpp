#pragma once
/// @file middleware_source.hpp
/// A ViewSource for a live multi-process system: each coordinator of the system file runs as its
/// own process (`safecass run SYSTEM --coordinator NAME --ice HOST:PORT`) and is reached through
/// the middleware, one connection per coordinator. Built only with the middleware (ZeroC Ice).
///
/// Each coordinator has a thread of its own that connects (finding the coordinator by its
/// heartbeat on IceStorm) and follows the records the coordinator pushes on the events topic
/// (RemoteClient::follow: signed, in order, gaps filled from its history by sequence number), so
/// every transition reaches the page, however short; it fetches the coordinator's state list
/// (the read model's rows) when it first answers and again after each batch of records. The
/// server thread takes the records in poll(), which never waits on the network. Every `retry`
/// without records the thread asks the coordinator for the records after the last one pushed
/// (Subscription::catch_up: that checks that it still answers, and a record lost on the bus with
/// no later one to reveal the gap still reaches the page within `retry`) and fetches the state
/// list again. A coordinator
/// that does not answer is shown with the status "unreachable" (never
/// answered) or "lost" (answered before), keeps its last known states, and is tried again every
/// `retry`. Clicking a state (explain) and the write operations go to the coordinator that owns
/// the target through a second connection of that coordinator, with the request timeout
/// `timeout`: they are the only calls that wait on the network, and only for as long as a person's
/// request takes. Writes carry that coordinator's token (--token-file COORD=FILE).
///
/// The clock (t) is the host's monotonic clock in seconds, the clock of the coordinators' records
/// and causes; running() is always true (no scenario ends; the coordinators' statuses say which
/// of them answer).

#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

struct MiddlewareOptions {
  std::string ice;     ///< IceStorm, "HOST:PORT" or "PORT"
  std::string system;  ///< the system file: its coordinators and their components
  /// The filter types of the system file (an application's own included); it must outlive the
  /// source. Null: the built-in types.
  const FilterRegistry* registry = nullptr;
  /// Coordinator name → its token file (written by `safecass run ... --allow-write --token-file`).
  std::map<std::string, std::string> token_files;
  bool allow_write = false;  ///< without it every write is refused here too
  std::string keys_dir;      ///< the system's bus keys (empty: $SAFECASS_KEYS)
  std::string tls_dir;       ///< mutual TLS (ca.pem, console.pem/.key); empty: TCP
  /// Coordinator name → its read credential file (`safecass run ... --read-token-file`).
  std::map<std::string, std::string> read_token_files;
  std::chrono::milliseconds timeout{1500};  ///< one request; also the wait for a heartbeat
  std::chrono::milliseconds retry{
      500};  ///< pause before trying an unreachable coordinator again; liveness check period
  std::chrono::milliseconds first_wait{3000};  ///< open() waits at most this for every first answer
};

class MiddlewareSource final : public ViewSource {
public:
  /// Loads the system file, reads the token files and starts one thread per coordinator; waits
  /// (at most `first_wait`) until every coordinator has answered or failed once. Coordinators that
  /// do not answer are not an error. Errors: Parse (--ice, the system file: every diagnostic),
  /// InvalidArgument (a system without coordinators, a token file for an unknown coordinator),
  /// Io (a token file that cannot be read).
  [[nodiscard]] static Expected<std::unique_ptr<MiddlewareSource>> open(const MiddlewareOptions& options);
  /// Stops the threads (each finishes its request in progress, at most `timeout`).
  ~MiddlewareSource() override;
  MiddlewareSource(const MiddlewareSource&) = delete;
  MiddlewareSource& operator=(const MiddlewareSource&) = delete;

  void poll() override;
  SystemView view() const override;
  double now() const override;
  bool running() const override;
  std::vector<std::string> take_records() override;
  /// Changes when poll() took new state lists or statuses: they arrive after their records.
  std::uint64_t view_version() const override;
  introspect::CoverageNow coverage() const override;
  [[nodiscard]] Expected<std::vector<Explanation>> explain(std::string_view address) const override;
  /// Sent to the coordinator that owns the action's target (a broadcast and a reset of SYSTEM: to
  /// every coordinator), with that coordinator's token.
  [[nodiscard]] Expected<std::string> apply(const introspect::Action& action) override;

  /// The status of a coordinator: "" (answering), "connecting", "unreachable" or "lost".
  /// For tests and the start-up message.
  std::string status(std::string_view coordinator) const;

private:
  struct Impl;
  explicit MiddlewareSource(std::unique_ptr<Impl> impl);
  [[nodiscard]] Expected<std::string> generate(const std::string& event, const std::string& target);
  [[nodiscard]] Expected<std::string> broadcast(const std::string& event);
  [[nodiscard]] Expected<std::string> inject(bool deep, const std::string& target,
                                             const std::vector<std::vector<double>>& samples);
  [[nodiscard]] Expected<std::string> reset(const introspect::ResetState& reset);
  std::unique_ptr<Impl> impl_;
};

}  // namespace safecass::viewer
