#pragma once
// A coordinator + monitor with one component "C" and an onset/completion pair, for filter tests.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"

namespace safecass::test {

class FilterFixture : public ::testing::Test {
protected:
  FilterFixture() : co_("test", &clock_), monitor_(co_, registry_) {
    register_builtin_filters(registry_);
    component_ = *co_.add_component("C");
    EXPECT_TRUE(co_.add_event(EventDef{"EVT_X", 50, {Transition::N2E, Transition::W2E}, "", false, "", ""}));
    EXPECT_TRUE(co_.add_event(EventDef{"/EVT_X", 50, {Transition::E2N, Transition::E2W}, "", false, "", ""}));
    co_.subscribe([this](const Record& r) {
      if (r.kind == RecordKind::Event && r.outcome != Outcome::Ignored) {
        events_.push_back(co_.structure().event(r.event).name);
        values_.push_back(r.root.sample.value);
      }
    });
  }

  /// Creates filter `type` on C.s_A with `params`; fails the test on error.
  Filter* make(const std::string& type, Params params, DetectionMode mode = DetectionMode::Edge) {
    FilterConfig c;
    c.type = type;
    c.target.component = "C";
    c.detection = mode;
    c.params = std::move(params);
    auto f = monitor_.add_filter(std::move(c));
    EXPECT_TRUE(f) << (f ? "" : f.error().message);
    return f ? *f : nullptr;
  }

  Signal* signal(const std::string& name, std::size_t size = 1) {
    auto s = monitor_.add_signal("C." + name, size);
    EXPECT_TRUE(s) << (s ? "" : s.error().message);
    return s ? *s : nullptr;
  }

  /// Writes `value` at time `t` seconds and runs the filter at t.
  void feed(Signal* s, Filter* f, double t, double value) {
    clock_.set(seconds_to_time(t));
    s->push(seconds_to_time(t), value);
    f->run(seconds_to_time(t));
  }
  void feed(Signal* s, Filter* f, double t, const std::vector<double>& v) {
    clock_.set(seconds_to_time(t));
    s->push(seconds_to_time(t), v.data());
    f->run(seconds_to_time(t));
  }
  /// Runs the filter at t without a new sample.
  void tick(Filter* f, double t) {
    clock_.set(seconds_to_time(t));
    f->run(seconds_to_time(t));
  }
  /// Newest value of a signal.
  double latest(const std::string& name) {
    Signal* s = monitor_.signals().find(name);
    EXPECT_NE(s, nullptr) << name;
    if (s == nullptr) return 0;
    std::vector<double> v(s->size());
    Time t{};
    EXPECT_TRUE(s->latest(t, v.data())) << name << " has no sample";
    return v[0];
  }
  State app_state() const { return co_.state(co_.structure().application_machine(component_)); }

  SimulatedClock clock_;
  Coordinator co_;
  FilterRegistry registry_;
  Monitor monitor_;
  ComponentId component_{0};
  std::vector<std::string> events_;  ///< names of the events processed on the stream, in order
  std::vector<double> values_;       ///< the sample value each carried
};

}  // namespace safecass::test
