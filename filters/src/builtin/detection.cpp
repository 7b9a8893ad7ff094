// Detection filters: Threshold, Range, OnOff, ChangeDetection, Debounce.

#include <cmath>

#include "banked.hpp"

namespace safecass::builtin {

Threshold::Threshold(FilterInit init) : Filter(std::move(init)) {
  ThresholdState& s = state_.own();
  s.above = text("direction") == "above";
  s.onset_level = s.above ? number("threshold") + number("tolerance") : number("threshold") - number("tolerance");
  s.clear_level = s.above ? s.onset_level - number("hysteresis") : s.onset_level + number("hysteresis");
  s.persistence = Persistence(number("persistence"), text("persistence_unit") == "seconds");
  s.out_above = number("output_above");
  s.out_below = number("output_below");
  s.output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Threshold::manifest() {
  FilterManifest m;
  m.doc = "event when a scalar crosses a threshold (with tolerance, hysteresis and persistence)";
  m.params = {
      ParamSpec::signal("input_signal", "scalar signal to check"),
      ParamSpec::number("threshold", "the limit"),
      ParamSpec::number("tolerance", "margin added to the limit before an onset", 0.0, 0, 1e300),
      ParamSpec::number("hysteresis", "how far back past the limit the value must return to clear", 0.0, 0, 1e300),
      ParamSpec::choice("direction", "which side of the limit is the fault", {"above", "below"}, "above"),
      persistence_param(),
      persistence_unit_param(),
      ParamSpec::signal("output_signal", "written every sample: output_above while detected, else output_below", true),
      ParamSpec::number("output_above", "output value while detected", 1.0),
      ParamSpec::number("output_below", "output value otherwise", 0.0)};
  add_event_params(m);
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  return m;
}

namespace {

/// Outside [min, max] → onset; back inside [min + hysteresis, max − hysteresis] → completion.
class Range final : public Filter {
public:
  explicit Range(FilterInit init)
      : Filter(std::move(init)),
        min_(number("min")),
        max_(number("max")),
        hysteresis_(number("hysteresis")),
        persistence_(number("persistence"), text("persistence_unit") == "seconds") {}

  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "event when a scalar leaves the range [min, max]";
    m.params = {
        ParamSpec::signal("input_signal", "scalar signal to check"),
        ParamSpec::number("min", "lowest allowed value"),
        ParamSpec::number("max", "highest allowed value"),
        ParamSpec::number("hysteresis", "how far inside the range the value must return to clear", 0.0, 0, 1e300),
        persistence_param(),
        persistence_unit_param(),
        ParamSpec::signal("output_signal", "1 while out of range, else 0", true)};
    add_event_params(m);
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s) {
    const double lo = std::get<double>(s.params.at("min"));
    const double hi = std::get<double>(s.params.at("max"));
    const double h = std::get<double>(s.params.at("hysteresis"));
    if (!(lo + 2 * h <= hi)) {
      return fail(ErrorCode::InvalidArgument,
                  "filter '" + s.filter + "' (Range): 'min' + 2 x 'hysteresis' must not exceed 'max'");
    }
    static const FilterManifest m = [] {
      auto x = manifest();
      x.type = "Range";
      return x;
    }();
    return scalar_shape(m, s);
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const double x = s.scalar();
    const bool outside = x < min_ || x > max_;
    const bool held = persistence_.update(outside, s.time);
    if (!detected_ && held) detected_ = true;
    if (detected_ && x >= min_ + hysteresis_ && x <= max_ - hysteresis_) detected_ = false;
    report(detected_, x, s.time);
    write(0, s.time, detected_ ? 1.0 : 0.0);
  }
  void on_reset() noexcept override {
    detected_ = false;
    persistence_.reset();
  }

private:
  double min_, max_, hysteresis_;
  Persistence persistence_;
  bool detected_ = false;
};

/// Non-zero input → event_on; zero → event_off.
class OnOff final : public Filter {
public:
  explicit OnOff(FilterInit init) : Filter(std::move(init)) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "event_on when the input becomes non-zero, event_off when it returns to zero";
    m.params = {ParamSpec::signal("input_signal", "scalar signal, 0 = off"),
                ParamSpec::signal("output_signal", "1 while on, else 0", true),
                ParamSpec::event("event_on", "event generated when the input turns on"),
                ParamSpec::event("event_off", "event generated when it turns off (default: the onset's completion)",
                                 std::nullopt, true)};
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    return m;
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const bool on = s.scalar() != 0.0;
    report(on, s.scalar(), s.time);
    write(0, s.time, on ? 1.0 : 0.0);
  }
};

/// Any element changes by more than `tolerance` from the previous sample → detected for that sample.
class ChangeDetection final : public Filter {
public:
  explicit ChangeDetection(FilterInit init)
      : Filter(std::move(init)), tolerance_(number("tolerance")), previous_(inputs()[0]->size(), 0.0) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "detects a change of the input (any element) larger than tolerance between two samples";
    m.params = {ParamSpec::signal("input_signal", "scalar or vector signal"),
                ParamSpec::number("tolerance", "largest change that is not a change", 0.0, 0, 1e300),
                ParamSpec::signal("output_signal", "1 on a sample that changed, else 0", true)};
    add_event_params(m);
    m.aliases = {{"event", "event_onset"}};  // the 2016 name
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&) {
    return std::vector<std::size_t>{1};
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    bool changed = false;
    double largest = 0.0;
    for (std::size_t i = 0; i < s.size; ++i) {
      const double d = std::fabs(s[i] - previous_[i]);
      if (d > largest) largest = d;
      previous_[i] = s[i];
    }
    changed = has_previous_ && largest > tolerance_;
    has_previous_ = true;
    report(changed, largest, s.time);
    write(0, s.time, changed ? 1.0 : 0.0);
  }
  void on_reset() noexcept override { has_previous_ = false; }

private:
  double tolerance_;
  std::vector<double> previous_;
  bool has_previous_ = false;
};

}  // namespace

Debounce::Debounce(FilterInit init) : Filter(std::move(init)) {
  DebounceState& s = state_.own();
  s.on = Persistence(number("persistence"), text("persistence_unit") == "seconds");
  s.off = Persistence(number("release"), false);
  s.output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Debounce::manifest() {
  FilterManifest m;
  m.doc = "debounces an on/off input: on must persist before the onset, off must persist before the completion";
  m.params = {ParamSpec::signal("input_signal", "scalar signal, 0 = off"), persistence_param(3),
              persistence_unit_param(),
              ParamSpec::integer("release", "consecutive off samples before the completion", 1.0, 1, 1e9),
              ParamSpec::signal("output_signal", "the debounced value, 1 or 0", true)};
  add_event_params(m, true);
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  return m;
}

void register_detection(FilterRegistry& r) {
  (void)r.add<Threshold>("Threshold");
  (void)r.add<Range>("Range");
  (void)r.add<OnOff>("OnOff");
  (void)r.add<ChangeDetection>("ChangeDetection");
  (void)r.add<Debounce>("Debounce");
}

}  // namespace safecass::builtin
