#pragma once
// A user-defined filter: flags a scalar that stays at exactly the same value (a frozen sensor).
#include <cstdio>
#include "safecass/filters/monitor.hpp"
using namespace safecass;

class Frozen final : public Filter {
public:
  explicit Frozen(FilterInit init) : Filter(std::move(init)), limit_(number("samples")) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "event when the input repeats the same value for `samples` samples";
    m.params = {ParamSpec::signal("input_signal", "scalar signal"),
                ParamSpec::integer("samples", "identical samples that mean frozen", 5.0, 2, 1e6),
                ParamSpec::event("event_onset", "event when frozen")};
    m.inputs = {"input_signal"};
    return m;
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    same_ = (s.scalar() == last_) ? same_ + 1 : 1;
    last_ = s.scalar();
    report(same_ >= limit_, s.scalar(), s.time);
  }

private:
  double limit_, last_ = 0, same_ = 0;
};
