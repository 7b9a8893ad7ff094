#pragma once
// FilterFixture plus what the behaviour tests of the built-in filters need: creation that may
// fail, every sample of an output signal, running all of C's filters at once, and where and when
// each event was processed.

#include <initializer_list>
#include <string>
#include <vector>

#include "filter_fixture.hpp"

namespace safecass::test {

/// One sample of a signal as read back from its history buffer.
struct Written {
  Time t{};
  std::vector<double> value;
};

class BuiltinFixture : public FilterFixture {
protected:
  BuiltinFixture() {
    co_.subscribe([this](const Record& r) {
      if (r.kind == RecordKind::Event && r.outcome != Outcome::Ignored) {
        machines_.push_back(co_.structure().address_of(r.machine));
        times_.push_back(r.time);
      }
    });
  }

  /// Like make(), but returns the error instead of failing the test.
  [[nodiscard]] Expected<Filter*> try_make(const std::string& type, Params params,
                                           DetectionMode mode = DetectionMode::Edge) {
    FilterConfig c;
    c.type = type;
    c.target.component = "C";
    c.detection = mode;
    c.params = std::move(params);
    return monitor_.add_filter(std::move(c));
  }

  /// Every sample written to C.<name> so far (the history buffer holds the last 1024).
  std::vector<Written> written(const std::string& name) {
    std::vector<Written> out;
    const Signal* s = monitor_.signals().find("C." + name);
    EXPECT_NE(s, nullptr) << name;
    if (s == nullptr) return out;
    SignalCursor cursor(s);  // from the oldest sample still held
    SampleView sample;
    while (cursor.next(sample)) {
      Written w;
      w.value.assign(sample.data, sample.data + sample.size);
      w.t = sample.time;
      out.push_back(std::move(w));
    }
    return out;
  }
  /// The scalar values written to C.<name>, in order.
  std::vector<double> values_of(const std::string& name) {
    std::vector<double> out;
    for (const Written& w : written(name)) out.push_back(w.value.at(0));
    return out;
  }
  /// How many samples were ever written to C.<name>.
  std::uint64_t count_of(const std::string& name) {
    const Signal* s = monitor_.signals().find("C." + name);
    EXPECT_NE(s, nullptr) << name;
    return s == nullptr ? 0 : s->count();
  }
  /// The newest sample of C.<name> as a vector.
  std::vector<double> latest_vector(const std::string& name) {
    const Signal* s = monitor_.signals().find("C." + name);
    EXPECT_NE(s, nullptr) << name;
    if (s == nullptr) return {};
    std::vector<double> v(s->size());
    Time t{};
    EXPECT_TRUE(s->latest(t, v.data())) << name << " has no sample";
    return v;
  }

  /// Writes a sample at `t` seconds without running anything.
  static void push(Signal* s, double t, double value) { s->push(seconds_to_time(t), value); }
  static void push(Signal* s, double t, const std::vector<double>& v) { s->push(seconds_to_time(t), v.data()); }
  /// Runs every ACTIVE filter of C, in creation order, at `t` seconds.
  void run_all(double t) {
    clock_.set(seconds_to_time(t));
    monitor_.run_active(component_, seconds_to_time(t));
  }

  MachineId app() const { return co_.structure().application_machine(component_); }
  MachineId framework() const { return co_.structure().framework_machine(component_); }
  /// Event records (not Transition records) in a machine's history.
  std::size_t event_records(MachineId m) const {
    std::size_t n = 0;
    for (const Record& r : co_.history(m)) n += r.kind == RecordKind::Event ? 1 : 0;
    return n;
  }

  std::vector<std::string> machines_;  ///< address of the machine of each entry of events_
  std::vector<Time> times_;            ///< processing time of each entry of events_
};

using Events = std::vector<std::string>;
using Times = std::vector<Time>;

/// Times given in seconds.
inline Times at(std::initializer_list<double> seconds) {
  Times out;
  for (double s : seconds) out.push_back(seconds_to_time(s));
  return out;
}
using Values = std::vector<double>;

}  // namespace safecass::test
