#pragma once
/// @file source.hpp
/// Where the viewer's data comes from. The server only talks to a ViewSource: an in-process
/// system driven by a scenario (InProcessSource), or a live multi-process system reached through
/// the middleware (MiddlewareSource). A source gives a picture of the Generic Component Model (coordinators →
/// components → machines, with their states), the records of the observer stream since the last
/// call, the cause of any state (explain), and the write operations of DESIGN §6.
///
/// Threading: the server calls every member from one thread (its event loop), so a source needs
/// no locking of its own against the server. A source fed by other threads (middleware callbacks)
/// buffers what they deliver and hands it over in poll().

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/introspect/model.hpp"

namespace safecass::viewer {

/// What a machine (or derived state) of a component is, as the page groups them.
enum class NodeKind : std::uint8_t { Framework, Application, Provided, Required, Service };

/// "framework", "application", "provided", "required", "service".
std::string_view to_string(NodeKind kind) noexcept;

/// One state machine (s_F, s_A, s_P.p, s_R.r) or service state (s_S.p) of a component.
struct MachineView {
  std::string address;  ///< "CONTROL.s_R.ForceData"
  NodeKind kind = NodeKind::Framework;
  std::string name;  ///< "s_F", "s_A" or the interface name
  State state = State::Normal;
  std::string outstanding;  ///< the outstanding event; empty when Normal or derived
};

struct ComponentView {
  std::string name;
  State state = State::Normal;  ///< extended component state ŝ_ext
  std::string outstanding;
  std::vector<MachineView> machines;  ///< s_F, s_A, then s_P.*, s_R.*, s_S.* in declaration order
};

struct CoordinatorView {
  std::string name;
  State state = State::Normal;  ///< product over its components
  /// Empty while its states are current (always in-process); for a live coordinator reached
  /// through the middleware "connecting", "unreachable" (never answered) or "lost" (answered
  /// before: the states shown are the last it sent).
  std::string status;
  std::vector<ComponentView> components;
};

/// A connection of the system: a required interface and the provided interface it uses.
struct ConnectionView {
  std::string required;  ///< "CONTROL.ForceData" (component.interface)
  std::string provided;  ///< "JR3.ForceData"
};

/// Where a replay stands (ViewSource::replay()).
struct ReplayView {
  double start = 0.0;   ///< the first tick, seconds of the recording's clock
  double end = 0.0;     ///< the last tick
  double period = 0.0;  ///< the tick
  bool playing = false;
  double speed = 1.0;  ///< recording seconds per wall-clock second while playing
  /// Catching up: toward a time asked for ("seek") or to the next transition ("next"); "" when idle.
  std::string busy;
};

/// A replay's controls: play, pause, speed, seek (to `t`) and run on to the next transition.
struct ReplayControl {
  enum class Op : std::uint8_t { Play, Pause, Speed, Seek, Next };
  Op op = Op::Pause;
  double t = 0.0;      ///< Seek: seconds
  double speed = 1.0;  ///< Speed
};

/// The whole picture at one moment.
struct SystemView {
  std::string system;       ///< system name
  std::string description;  ///< where it comes from ("in-process, scenario story.json, speed 1")
  double t = 0.0;           ///< the system's clock, seconds
  bool running = true;      ///< a scenario still has steps to apply (false without one); always true live
  State state = State::Normal;
  std::vector<CoordinatorView> coordinators;
  std::vector<ConnectionView> connections;  ///< in the system file's order
  /// The times of a live system are the host's monotonic clock: shown as wall-clock time, the
  /// time of the host clock + wall_offset_ns (ns since the Unix epoch). Otherwise scenario seconds.
  bool host_clock = false;
  std::int64_t wall_offset_ns = 0;
};

class ViewSource {
public:
  virtual ~ViewSource() = default;

  /// Lets the source catch up (advance its clock, collect what arrived). Called about every
  /// 10 ms. Must not block for long: it runs on the server's event loop.
  virtual void poll() = 0;
  /// The current picture.
  virtual SystemView view() const = 0;
  /// The system's clock in seconds, and whether its scenario is still running: cheap, unlike view().
  virtual double now() const = 0;
  virtual bool running() const = 0;
  /// The observer-stream records since the last call, oldest first, each one JSON object in the
  /// format of record_to_json() (the history-file format).
  virtual std::vector<std::string> take_records() = 0;
  /// Which hazards the system cannot detect now (`analyze now`, docs/analyze.md "At run time"):
  /// judged from every coordinator's filters as last read, a lost or not yet answering
  /// coordinator's filters counting as unable to detect. Costs a read of the filter list: the
  /// server asks a few times a second.
  virtual introspect::CoverageNow coverage() const = 0;
  /// Every active condition at `address` (SYSTEM, a coordinator name, C, C.s_F, …) with its
  /// root cause and hop path. Errors: NotFound / Parse for an unknown or malformed address.
  [[nodiscard]] virtual Expected<std::vector<Explanation>> explain(std::string_view address) const = 0;

  /// Applies an operator's write (generate, broadcast, reset, shallow or deep injection) through
  /// the one action path (introspect::apply, in this process or at the coordinator that owns its
  /// target). The server checks write access and the token first. Returns one line saying what was
  /// done, or an error that says what is wrong and changes nothing.
  [[nodiscard]] virtual Expected<std::string> apply(const introspect::Action& action) = 0;

  // A replay (ReplaySource) can be moved in time; other sources are not replays.
  /// Where the replay stands; nullopt for a source that is not a replay.
  virtual std::optional<ReplayView> replay() const { return std::nullopt; }
  /// Applies a replay control and says what was done. Errors: InvalidArgument (not a replay, a
  /// time out of the replay's range, a bad speed); nothing changed then.
  [[nodiscard]] virtual Expected<std::string> control(const ReplayControl& /*control*/) {
    return fail(ErrorCode::InvalidArgument, "this viewer shows a running system, not a replay");
  }
  /// Changes whenever view() may show other states than at the last call, when the change can come
  /// without a record in the same poll(): a live system's state list arrives after the records
  /// that announced it (MiddlewareSource). A source whose every change of state comes with a
  /// record keeps the default.
  virtual std::uint64_t view_version() const { return 0; }
  /// Changes whenever the source's picture started over (a replay went back in time): the
  /// records taken so far no longer lead to the current picture.
  virtual std::uint64_t generation() const { return 0; }
};

}  // namespace safecass::viewer
