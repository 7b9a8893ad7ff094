// Signal transforms: Derivative, MovingAverage, Norm, Arithmetic, Vectorize, Bypass, NOP.

#include <algorithm>
#include <cmath>

#include "banked.hpp"

namespace safecass::builtin {

[[nodiscard]] Expected<std::vector<std::size_t>> same_size_shape(const FilterManifest& m, const FilterShape& s) {
  const std::size_t size = s.inputs.empty() ? 1 : s.inputs[0]->size();
  for (const Signal* in : s.inputs) {
    if (in->size() != size) {
      return fail(ErrorCode::InvalidArgument, "filter '" + s.filter + "' (" + m.type + "): input '" + in->name() +
                                                  "' has size " + std::to_string(in->size()) + " but '" +
                                                  s.inputs[0]->name() + "' has size " + std::to_string(size));
    }
  }
  return std::vector<std::size_t>(m.outputs.size(), size);
}

namespace {

template <class T>
[[nodiscard]] Expected<std::vector<std::size_t>> same_size(const FilterShape& s) {
  static const FilterManifest m = [] {
    FilterManifest x = T::manifest();
    x.type = T::kType;
    return x;
  }();
  return same_size_shape(m, s);
}

/// (x_k − x_{k−1}) / (t_k − t_{k−1}), element-wise; cascade two for acceleration. Without time
/// scaling, the difference x_k − x_{k−1} (the 2016 TrendVel's `time_scaling: false`).
class Derivative final : public Filter {
public:
  static constexpr const char* kType = "Derivative";
  explicit Derivative(FilterInit init)
      : Filter(std::move(init)),
        time_scaling_(flag("time_scaling")),
        previous_(inputs()[0]->size(), 0.0),
        out_(inputs()[0]->size(), 0.0) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "rate of change of the input per second (element-wise)";
    m.params = {
        ParamSpec::signal("input_signal", "scalar or vector signal"),
        ParamSpec::boolean(
            "time_scaling",
            "divide the difference of two samples by their time difference (false: the difference alone)", true),
        ParamSpec::signal("output_signal",
                          "the derivative, same size as the input (default: the signal named after the filter)", true)};
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    m.generates_events = false;
    m.default_output = true;
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s) {
    return same_size<Derivative>(s);
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const double dt = to_seconds(s.time - previous_time_);
    if (has_previous_ && dt > 0) {
      const double scale = time_scaling_ ? dt : 1.0;
      for (std::size_t i = 0; i < s.size; ++i) out_[i] = (s[i] - previous_[i]) / scale;
      write(0, s.time, out_.data());
    }
    std::copy(s.data, s.data + s.size, previous_.begin());
    previous_time_ = s.time;
    has_previous_ = true;
  }
  void on_reset() noexcept override { has_previous_ = false; }

private:
  bool time_scaling_;
  std::vector<double> previous_;
  std::vector<double> out_;
  Time previous_time_{};
  bool has_previous_ = false;
};

}  // namespace

MovingAverage::MovingAverage(FilterInit init)
    : Filter(std::move(init)), window_(static_cast<std::size_t>(number("window"))), size_(inputs()[0]->size()) {
  Signal* output = outputs().empty() ? nullptr : outputs()[0];
  if (size_ == 1) {
    if (window_ > kInline) heap_.assign(window_, 0.0);
    AverageState& s = scalar_.own();
    s.ring = window_ > kInline ? heap_.data() : inline_;
    s.window = static_cast<std::uint32_t>(window_);
    s.output = output;
    return;
  }
  heap_.assign(VectorAverageState::block_size(window_, size_), 0.0);
  VectorAverageState& v = vector_.own();
  v.block = heap_.data();
  v.output = output;
  v.window = static_cast<std::uint32_t>(window_);
  v.width = static_cast<std::uint32_t>(size_);
}

FilterManifest MovingAverage::manifest() {
  FilterManifest m;
  m.doc = "moving average over the last window samples (element-wise)";
  m.params = {
      ParamSpec::signal("input_signal", "scalar or vector signal"),
      ParamSpec::integer("window", "number of samples averaged", 10.0, 1, 1e6),
      ParamSpec::signal("output_signal",
                        "the average, same size as the input (default: the signal named after the filter)", true)};
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  m.generates_events = false;
  m.default_output = true;
  return m;
}

Expected<std::vector<std::size_t>> MovingAverage::output_sizes(const FilterShape& s) {
  return same_size<MovingAverage>(s);
}

Norm::Norm(FilterInit init) : Filter(std::move(init)) {
  const std::string& norm = text("norm");
  state_.own().kind = norm == "L1" ? 1 : norm == "Linf" ? 2 : 0;
  state_.own().output = outputs().empty() ? nullptr : outputs()[0];
}

FilterManifest Norm::manifest() {
  FilterManifest m;
  m.doc = "norm of a vector signal";
  m.params = {
      ParamSpec::signal("input_signal", "vector (or scalar) signal"),
      ParamSpec::choice("norm", "which norm", {"L2", "L1", "Linf"}, "L2"),
      ParamSpec::signal("output_signal", "the norm (scalar; default: the signal named after the filter)", true)};
  m.inputs = {"input_signal"};
  m.outputs = {"output_signal"};
  m.generates_events = false;
  m.default_output = true;
  return m;
}

namespace {

/// Element-wise a (op) b, where b is a second signal or the constant `operand`.
class Arithmetic final : public Filter {
public:
  static constexpr const char* kType = "Arithmetic";
  explicit Arithmetic(FilterInit init)
      : Filter(std::move(init)),
        op_(op_of(text("operation"))),
        operand_(number("operand")),
        out_(inputs()[0]->size(), 0.0) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "element-wise add, subtract, multiply, divide, min or max of two signals, or of a signal and a constant";
    m.params = {
        ParamSpec::signal("input_signal", "first operand (with 'operand' as the second)", true),
        ParamSpec::signals("input_signals", "two signals of the same size", true),
        ParamSpec::choice("operation", "the operation", {"add", "subtract", "multiply", "divide", "min", "max"}, "add"),
        ParamSpec::number("operand", "constant second operand when there is one input", 0.0),
        ParamSpec::signal("output_signal",
                          "the result, same size as the inputs (default: the signal named after the filter)", true)};
    m.inputs = {"input_signal", "input_signals"};
    m.outputs = {"output_signal"};
    m.generates_events = false;
    m.default_output = true;
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s) {
    const bool one = s.params.count("input_signal") > 0;
    const bool two = s.params.count("input_signals") > 0;
    if (one == two) {
      return fail(ErrorCode::InvalidArgument,
                  "filter '" + s.filter +
                      "' (Arithmetic): give either 'input_signal' (with 'operand') or 'input_signals' (two signals)");
    }
    if (two && s.inputs.size() != 2) {
      return fail(ErrorCode::InvalidArgument,
                  "filter '" + s.filter + "' (Arithmetic): 'input_signals' must list exactly two signals, not " +
                      std::to_string(s.inputs.size()));
    }
    return same_size<Arithmetic>(s);
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    const double* a = held(0);
    const double* b = inputs().size() > 1 ? held(1) : nullptr;
    if (a == nullptr || (inputs().size() > 1 && b == nullptr)) return;
    for (std::size_t i = 0; i < out_.size(); ++i) out_[i] = apply(a[i], b != nullptr ? b[i] : operand_);
    write(0, s.time, out_.data());
  }

private:
  enum class Op { Add, Subtract, Multiply, Divide, Min, Max };
  static Op op_of(const std::string& s) {
    if (s == "subtract") return Op::Subtract;
    if (s == "multiply") return Op::Multiply;
    if (s == "divide") return Op::Divide;
    if (s == "min") return Op::Min;
    if (s == "max") return Op::Max;
    return Op::Add;
  }
  double apply(double a, double b) const noexcept {
    switch (op_) {
      case Op::Add: return a + b;
      case Op::Subtract: return a - b;
      case Op::Multiply: return a * b;
      case Op::Divide: return a / b;  // a zero divisor gives ±inf/NaN: consumers raise EVT_INVALID_SAMPLE
      case Op::Min: return std::min(a, b);
      case Op::Max: return std::max(a, b);
    }
    return a;
  }
  Op op_;
  double operand_;
  std::vector<double> out_;
};

/// Scalars → one vector, in the order listed; written when any input has a new sample and all
/// have at least one.
class Vectorize final : public Filter {
public:
  explicit Vectorize(FilterInit init) : Filter(std::move(init)), out_(inputs().size(), 0.0) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "combines scalar signals into one vector signal";
    m.params = {
        ParamSpec::signal("input_signal", "one scalar signal (a vector of one)", true),
        ParamSpec::signals("input_signals", "scalar signals, in vector order", true),
        ParamSpec::signal("output_signal",
                          "vector of the inputs' latest values (default: the signal named after the filter)", true)};
    m.inputs = {"input_signal", "input_signals"};
    m.outputs = {"output_signal"};
    m.generates_events = false;
    m.default_output = true;
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s) {
    if ((s.params.count("input_signal") > 0) == (s.params.count("input_signals") > 0)) {
      return fail(ErrorCode::InvalidArgument,
                  "filter '" + s.filter + "' (Vectorize): give either 'input_signals' or 'input_signal'");
    }
    for (const Signal* in : s.inputs) {
      if (in->size() != 1) {
        return fail(ErrorCode::InvalidArgument, "filter '" + s.filter + "' (Vectorize): input '" + in->name() +
                                                    "' has size " + std::to_string(in->size()) +
                                                    "; Vectorize takes scalars");
      }
    }
    return std::vector<std::size_t>{s.inputs.size()};
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    for (std::size_t i = 0; i < inputs().size(); ++i) {
      const double* v = held(i);
      if (v == nullptr) return;
      out_[i] = v[0];
    }
    write(0, s.time, out_.data());
  }

private:
  std::vector<double> out_;
};

/// Copies its input to its output unchanged; with `event_on`, also reports a non-zero input as
/// OnOff does (the 2016 Bypass).
class Bypass final : public Filter {
public:
  static constexpr const char* kType = "Bypass";
  explicit Bypass(FilterInit init) : Filter(std::move(init)) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc =
        "copies the input to the output (a tap for injection and observation); with event_on, a non-zero input is an "
        "onset";
    m.params = {
        ParamSpec::signal("input_signal", "scalar or vector signal"),
        ParamSpec::signal("output_signal", "the same samples (default: the signal named after the filter)", true),
        ParamSpec::event("event_on", "event generated when the input turns non-zero (any element)", std::nullopt, true),
        ParamSpec::event("event_off", "event generated when it is zero again (default: the onset's completion)",
                         std::nullopt, true)};
    m.inputs = {"input_signal"};
    m.outputs = {"output_signal"};
    m.default_output = true;
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape& s) {
    return same_size<Bypass>(s);
  }

protected:
  void on_sample(std::size_t, const SampleView& s) noexcept override {
    write(0, s.time, s.data);
    bool on = false;
    for (std::size_t i = 0; i < s.size; ++i) on = on || s[i] != 0.0;
    report(on, s[0], s.time);
  }
};

/// Reads its input and does nothing: a placeholder and a carrier for fault-injection tests.
class Nop final : public Filter {
public:
  explicit Nop(FilterInit init) : Filter(std::move(init)) {}
  static FilterManifest manifest() {
    FilterManifest m;
    m.doc = "reads its input and does nothing (placeholder, injection carrier)";
    m.params = {ParamSpec::signal("input_signal", "any signal")};
    m.inputs = {"input_signal"};
    m.generates_events = false;
    return m;
  }
  [[nodiscard]] static Expected<std::vector<std::size_t>> output_sizes(const FilterShape&) {
    return std::vector<std::size_t>{};
  }

protected:
  void on_sample(std::size_t, const SampleView&) noexcept override {}
};

}  // namespace

void register_transforms(FilterRegistry& r) {
  (void)r.add<Derivative>("Derivative");
  (void)r.add<MovingAverage>("MovingAverage");
  (void)r.add<Norm>("Norm");
  (void)r.add<Arithmetic>("Arithmetic");
  (void)r.add<Vectorize>("Vectorize");
  (void)r.add<Bypass>("Bypass");
  (void)r.add<Nop>("NOP");
}

}  // namespace safecass::builtin
