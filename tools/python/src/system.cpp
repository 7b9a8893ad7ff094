// An in-process system in simulated time, and a replay, as Python objects (docs/python.md,
// "A system in this process").
//
// A System is what the console opens in-process: a scenario runner (the system built by the one
// factory, driven tick by tick, its scenario's steps and expectations if it has one) read and
// written through a LocalQuery, the one read model and the one action path. A replay is the same
// over a ReplaySession, whose ticks also feed the recording's inputs.
//
// Threads: the system runs on the calling thread with the GIL released, in slices of at most
// kSliceTicks ticks; the records it produces are queued by the follower (which takes no Python
// object) and handed to the Python callbacks between slices and after each call, holding the GIL
// and without the coordinator's lock.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "query_methods.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/replay/replay.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/instance.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::python {

namespace in = safecass::introspect;

namespace {

/// Ticks run between two hand-overs of records to Python (and two checks for Ctrl-C).
constexpr std::int64_t kSliceTicks = 1000;
/// Samples fed between two hand-overs in feed().
constexpr std::size_t kSliceSamples = 1 << 16;

struct Subscriber {
  int id = 0;
  py::function callback;
};

class System {
public:
  /// A system file (and a scenario to drive it, and files to record to).
  static std::unique_ptr<System> open(const std::string& path, const std::string& scenario, const std::string& record,
                                      const std::string& inputs) {
    auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{scenario, path}, builtin_filters());
    if (!opened) raise(opened.error());
    auto system = std::unique_ptr<System>(new System());
    system->owned_ = std::move(*opened);
    system->runner_ = system->owned_.get();
    system->start(scenario, record, inputs);
    return system;
  }

  /// A recording replayed through a system (replay::ReplaySession: every input checked first).
  static std::unique_ptr<System> replay(const replay::ReplayOptions& options) {
    Expected<std::unique_ptr<replay::ReplaySession>> opened = fail(ErrorCode::InvalidState, "not opened");
    {
      py::gil_scoped_release unlocked;
      opened = replay::ReplaySession::open(options, builtin_filters());
    }
    auto session = value_or_raise(std::move(opened));
    auto system = std::unique_ptr<System>(new System());
    system->session_ = std::move(session);
    system->runner_ = &system->session_->runner();
    system->start({}, {}, {});
    return system;
  }

  ~System() { close(); }

  void close() {
    const Busy busy(*this);
    if (closed_) return;
    closed_ = true;
    following_.reset();
    runner_->finish(result_);
    query_.reset();
  }

  // ---- driving ------------------------------------------------------------------------------------
  double now() const { return to_seconds(std::max(runner_->now(), Time{0})); }

  /// Runs every tick up to and including `t` seconds.
  void advance(double t) {
    const Busy busy(*this);
    open_or_raise();
    Time until = time_or_raise(t, "advance");
    if (session_) until = std::min(until, session_->end());
    while (runner_->now() + period() <= until) {  // a tick is due
      const Time slice = std::min(until, runner_->now() + period() * kSliceTicks);
      {
        py::gil_scoped_release unlocked;
        advance_to(slice);
      }
      deliver();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    deliver();
  }

  /// To the end: the scenario's duration, or the replay's last tick.
  void run() {
    const Busy busy(*this);
    if (session_) return advance(to_seconds(session_->end()));
    if (runner_->scenario().duration <= 0.0) {
      raise(Error{ErrorCode::InvalidState, "this system has no scenario and so no end: advance(t) runs it to t"});
    }
    advance(runner_->scenario().duration);
  }

  /// One action through the one action path (LocalQuery::apply: checked first, then applied and
  /// recorded as the console's).
  void apply(const in::Action& action) {
    const Busy busy(*this);
    open_or_raise();
    value_or_raise(query_->apply(action));
    deliver();
  }

  /// `times` (seconds, not decreasing, none before now) and one sample per row of `values`, pushed
  /// into `signal` as the system's ticks reach them; the system then stands at the last sample's time.
  void feed(const std::string& signal, const py::array_t<double, py::array::c_style | py::array::forcecast>& times,
            const py::array_t<double, py::array::c_style | py::array::forcecast>& values) {
    const Busy busy(*this);
    open_or_raise();
    Signal* target = runner_->monitor().signals().find(signal);
    const std::size_t width = target != nullptr ? target->size() : 1;
    value_or_raise(
        in::check(in::PushSample{signal, std::vector<double>(width)}, runner_->coordinator(), runner_->monitor()));
    const std::size_t n = check_feed(times, values, width);
    const double* t = times.data();
    const double* v = values.data();
    for (std::size_t from = 0; from < n; from += kSliceSamples) {
      const std::size_t to = std::min(n, from + kSliceSamples);
      {
        py::gil_scoped_release unlocked;
        for (std::size_t i = from; i < to; ++i) {
          const Time at = seconds_to_time(t[i]);
          if (at > runner_->now()) advance_to(at - Time{1});
          target->push(at, v + i * width);
        }
      }
      deliver();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    if (n > 0) advance(t[n - 1]);
  }

  // ---- reads --------------------------------------------------------------------------------------
  /// The value `read(query)` answers, or its error raised.
  template <class Read>
  auto ask(Read read) {
    const Busy busy(*this);
    open_or_raise();
    return value_or_raise(read(*query_));
  }

  // ---- the observer stream -------------------------------------------------------------------------
  int subscribe(py::function callback) {
    const Busy busy(*this);
    open_or_raise();
    subscribers_.push_back(Subscriber{++last_id_, std::move(callback)});
    return last_id_;
  }
  void unsubscribe(int id) {
    const Busy busy(*this);
    std::erase_if(subscribers_, [id](const Subscriber& s) { return s.id == id; });
  }

  const runner::RunResult& result() const { return result_; }
  runner::ScenarioRunner& runner() { return *runner_; }
  replay::ReplaySession* session() { return session_.get(); }

private:
  /// One Python thread at a time drives a system: another waits here with the GIL released. The
  /// thread that holds it may come back (a callback that reads the system).
  class Busy {
  public:
    explicit Busy(System& s) : lock_(s.busy_, std::defer_lock) {
      if (lock_.try_lock()) return;
      py::gil_scoped_release unlocked;
      lock_.lock();
    }

  private:
    std::unique_lock<std::recursive_mutex> lock_;
  };

  System() = default;

  void start(const std::string& scenario, const std::string& record, const std::string& inputs) {
    runner::RunOptions options;
    options.quiet = true;
    options.record_path = record;
    options.inputs_path = inputs.empty() && record.empty() ? "-" : inputs;
    if (!runner_->begin(options, result_)) raise(Error{ErrorCode::Io, result_.failures.back()});
    const spec::Scenario& sc = runner_->scenario();
    in::LocalOptions local;
    local.period = sc.period;
    local.scenario = scenario;
    local.duration = sc.duration;
    local.actions = runner_->input_recorder();
    query_ = std::make_unique<in::LocalQuery>(runner_->coordinator(), runner_->monitor(), builtin_filters(), local);
    auto following = query_->follow([this](const in::HistoryEntry& e) {
      const std::lock_guard lock(pending_mutex_);
      pending_.push_back(e);
    });
    following_ = value_or_raise(std::move(following));
    if (!session_) runner_->advance_to(Time{0}, result_);  // what happens at t = 0 is in the history
  }

  Time period() const { return session_ ? session_->period() : seconds_to_time(runner_->scenario().period); }

  void advance_to(Time t) {
    if (session_) {
      session_->advance_to(t);
    } else {
      runner_->advance_to(t, result_);
    }
  }

  void open_or_raise() const {
    if (closed_) raise(Error{ErrorCode::InvalidState, "this system is closed"});
  }

  Time time_or_raise(double t, const char* what) const {
    if (!std::isfinite(t) || t < 0.0 || t > 1e9) {
      raise(Error{ErrorCode::InvalidArgument,
                  std::string(what) + ": " + std::to_string(t) + " is not a time in seconds (finite, 0 to 1e9)"});
    }
    return seconds_to_time(t);
  }

  std::size_t check_feed(const py::array_t<double, py::array::c_style | py::array::forcecast>& times,
                         const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
                         std::size_t width) const {
    if (times.ndim() != 1) raise(Error{ErrorCode::InvalidArgument, "feed: times must be one-dimensional"});
    const std::size_t n = static_cast<std::size_t>(times.shape(0));
    const bool shape_ok = (values.ndim() == 1 && width == 1 && static_cast<std::size_t>(values.shape(0)) == n) ||
                          (values.ndim() == 2 && static_cast<std::size_t>(values.shape(0)) == n &&
                           static_cast<std::size_t>(values.shape(1)) == width);
    if (!shape_ok) {
      raise(Error{ErrorCode::InvalidArgument, "feed: values must have one row of " + std::to_string(width) +
                                                  " value(s) per time (" + std::to_string(n) + " times)"});
    }
    const double* t = times.data();
    double last = now();
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t[i]) || t[i] > 1e9 || t[i] < last) {
        raise(Error{ErrorCode::InvalidArgument,
                    "feed: times[" + std::to_string(i) + "] = " + std::to_string(t[i]) +
                        (std::isfinite(t[i]) && t[i] < last ? " goes back (before " + std::to_string(last) + ")"
                                                            : " is not a time in seconds")});
      }
      last = t[i];
    }
    return n;
  }

  /// Hands the queued records to every subscriber, in order. A callback that raises does not stop
  /// the record from reaching the others; the records after it stay queued for the next call, and
  /// its exception is raised here.
  void deliver() {
    std::vector<in::HistoryEntry> records;
    {
      const std::lock_guard lock(pending_mutex_);
      records.swap(pending_);
    }
    std::optional<py::error_already_set> failure;
    std::size_t k = 0;
    for (; k < records.size() && !failure; ++k) {
      const py::object record = py::cast(records[k]);
      for (const Subscriber& s : std::vector<Subscriber>(subscribers_)) {
        try {
          s.callback(record);
        } catch (py::error_already_set& e) {
          if (!failure) failure.emplace(std::move(e));
        }
      }
    }
    if (!failure) return;
    {
      const std::lock_guard lock(pending_mutex_);
      pending_.insert(pending_.begin(), records.begin() + static_cast<std::ptrdiff_t>(k), records.end());
    }
    failure->restore();
    throw py::error_already_set();
  }

  std::unique_ptr<runner::ScenarioRunner> owned_;
  std::unique_ptr<replay::ReplaySession> session_;
  runner::ScenarioRunner* runner_ = nullptr;
  runner::RunResult result_;
  std::unique_ptr<in::LocalQuery> query_;
  std::unique_ptr<in::Subscription> following_;
  std::recursive_mutex busy_;
  std::mutex pending_mutex_;
  std::vector<in::HistoryEntry> pending_;
  std::vector<Subscriber> subscribers_;
  int last_id_ = 0;
  bool closed_ = false;
};

}  // namespace

namespace {

/// What load() answers: the loaded system's outline, as a Result.
py::object outline(const spec::SystemSpec& system, const spec::Diagnostics& warnings) {
  py::dict d;
  d["name"] = system.name;
  d["path"] = system.path;
  py::list components, hazards, invariants;
  for (const spec::ComponentSpec& c : system.components) components.append(c.name);
  for (const spec::HazardSpec& h : system.hazards) hazards.append(h.id);
  for (const spec::InvariantSpec& i : system.invariants) invariants.append(i.name);
  py::dict coordinators;
  for (const auto& [name, members] : system.coordinators) coordinators[py::str(name)] = members;
  d["components"] = components;
  d["coordinators"] = coordinators;
  d["hazards"] = hazards;
  d["invariants"] = invariants;
  py::list notes;
  for (const spec::Diagnostic& w : warnings) notes.append(spec::format(w));
  d["warnings"] = notes;
  return py::module_::import("safecass._values").attr("Result")(d);
}

}  // namespace

void bind_system(py::module_& m) {
  m.def(
      "load",
      [](const std::string& path) {
        spec::Diagnostics warnings;
        spec::Opened<spec::SystemSpec> loaded = tl::unexpected(spec::Diagnostics{});
        {
          py::gil_scoped_release unlocked;
          loaded = spec::load_valid_system(path, builtin_filters(), &warnings);
        }
        if (!loaded) raise(loaded.error());
        return outline(*loaded, warnings);
      },
      py::arg("path"),
      "Loads and validates a system or component file: its outline (name, components, coordinators, hazards, "
      "invariants, warnings), or SpecError carrying every problem with file:line:col.");
  m.def(
      "validate",
      [](const std::string& path) {
        spec::LoadResult loaded;
        {
          py::gil_scoped_release unlocked;
          loaded = spec::load_system(path, builtin_filters());
        }
        return loaded.diagnostics;
      },
      py::arg("path"),
      "Every problem of a system or component file (errors and warnings), each with file:line:col; [] when it is "
      "valid.");
  py::class_<System> c(m, "System",
                       "A system built in this process and run in simulated time, as the console runs it in-process.");
  c.def(py::init(&System::open), py::arg("path"), py::arg("scenario") = "", py::arg("record") = "",
        py::arg("inputs") = "",
        "Loads, validates and builds a system file (SpecError with every problem otherwise). scenario: a scenario "
        "whose steps and expectations run as time advances. record: write the history there (JSON lines) and the "
        "inputs next to it; inputs: the inputs recording's own path ('-': none).")
      .def_property_readonly("now", &System::now, "the last tick processed, in seconds")
      .def("advance", &System::advance, py::arg("t"), "Runs every tick up to and including t seconds.")
      .def("run", &System::run, "Runs to the end: the scenario's duration, or a replay's last tick.")
      .def("subscribe", &System::subscribe, py::arg("callback"),
           "Calls callback(record) for every record from now on, in order, holding the GIL and without the "
           "coordinator's lock; returns an id for unsubscribe(). An exception raised by the callback is raised by "
           "the call that delivered the record.")
      .def("unsubscribe", &System::unsubscribe, py::arg("id"))
      .def_property_readonly(
          "failures", [](const System& s) { return s.result().failures; },
          "the scenario's failed expectations so far, file:line:col: ...")
      .def("close", &System::close, "Stops the system and closes its recordings (the history file is complete then).")
      .def("__enter__", [](System& s) -> System& { return s; })
      .def("__exit__", [](System& s, const py::args&) { s.close(); });
  c.def("feed", &System::feed, py::arg("signal"), py::arg("times"), py::arg("values"),
        "Feeds numpy arrays of samples in one call: times in seconds (not decreasing, none before now), values "
        "one row per time. Each sample is pushed when the system's ticks reach its time; the system then stands "
        "at the last time. The GIL is released while it runs.");
  bind_actions(c);
  bind_reads(c);
  m.def(
      "replay",
      [](const std::string& system, const std::string& recording, const std::string& format, const std::string& mapping,
         std::optional<double> period, std::optional<double> start, std::optional<double> end) {
        replay::ReplayOptions options;
        options.system = system;
        options.input = recording;
        options.format = format;
        options.mapping = mapping;
        options.period = period;
        options.from = start;
        options.to = end;
        return System::replay(options);
      },
      py::arg("system"), py::arg("recording"), py::arg("format") = "", py::arg("mapping") = "",
      py::arg("period") = py::none(), py::arg("start") = py::none(), py::arg("end") = py::none(),
      "Opens a replay of a recording (SAFECASS's inputs, CSV, a ROS 1 or ROS 2 bag) through a system, every input "
      "checked first (SpecError otherwise); run() feeds it to the end with the GIL released.");
}

}  // namespace safecass::python
