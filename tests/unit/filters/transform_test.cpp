// Behaviour of the transform filters (DESIGN §3): Derivative, MovingAverage, Norm, Arithmetic,
// Vectorize, Bypass, NOP.

#include <cmath>
#include <cstdint>

#include "builtin_fixture.hpp"

namespace safecass::test {
namespace {

using DerivativeFilter = BuiltinFixture;
using MovingAverageFilter = BuiltinFixture;
using NormFilter = BuiltinFixture;
using ArithmeticFilter = BuiltinFixture;
using VectorizeFilter = BuiltinFixture;
using BypassFilter = BuiltinFixture;
using NopFilter = BuiltinFixture;

Params io(const std::string& in, const std::string& out, Params extra = {}) {
  Params p{{"input_signal", in}, {"output_signal", out}};
  for (auto& [k, v] : extra) p[k] = v;
  return p;
}

// ---- Derivative -------------------------------------------------------------------------------

TEST_F(DerivativeFilter, FirstSampleWritesNothing) {
  Signal* x = signal("x");
  Filter* f = make("Derivative", io("x", "dx"));
  feed(x, f, 1.0, 5);
  EXPECT_EQ(count_of("dx"), 0u);
  feed(x, f, 1.5, 6);
  EXPECT_EQ(count_of("dx"), 1u);
  EXPECT_TRUE(events_.empty());
}

TEST_F(DerivativeFilter, ScalarDerivativeIsTheChangePerSecond) {
  Signal* x = signal("x");
  Filter* f = make("Derivative", io("x", "dx"));
  feed(x, f, 1.0, 2);
  feed(x, f, 1.5, 3);   // +1 in 0.5 s
  feed(x, f, 2.5, 1);   // −2 in 1 s
  feed(x, f, 2.75, 1);  // no change
  const std::vector<Written> out = written("dx");
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out[0].value[0], 2.0);
  EXPECT_DOUBLE_EQ(out[1].value[0], -2.0);
  EXPECT_DOUBLE_EQ(out[2].value[0], 0.0);
  EXPECT_EQ(out[0].t, seconds_to_time(1.5));
  EXPECT_EQ(out[2].t, seconds_to_time(2.75));
}

TEST_F(DerivativeFilter, VectorDerivativeIsElementWise) {
  Signal* p = signal("p", 3);
  Filter* f = make("Derivative", io("p", "v"));
  ASSERT_EQ(monitor_.signals().find("C.v")->size(), 3u);
  feed(p, f, 1.0, {0, 10, -4});
  feed(p, f, 1.25, {1, 10, -5});
  const std::vector<Written> out = written("v");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].value[0], 4.0);
  EXPECT_DOUBLE_EQ(out[0].value[1], 0.0);
  EXPECT_DOUBLE_EQ(out[0].value[2], -4.0);
}

TEST_F(DerivativeFilter, TwoCascadedDerivativesGiveAcceleration) {
  Signal* x = signal("x");
  make("Derivative", io("x", "vel"));
  make("Derivative", io("vel", "acc"));
  for (int k = 0; k <= 4; ++k) {  // x = k², one sample a second
    push(x, 10.0 + k, static_cast<double>(k * k));
    run_all(10.0 + k);
  }
  const std::vector<Written> vel = written("vel");
  ASSERT_EQ(vel.size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(vel[k].value[0], 2.0 * k + 1) << k;
  const std::vector<Written> acc = written("acc");
  ASSERT_EQ(acc.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(acc[k].value[0], 2.0) << k;
    EXPECT_EQ(acc[k].t, seconds_to_time(12.0 + k)) << k;
  }
}

// ---- MovingAverage ----------------------------------------------------------------------------

TEST_F(MovingAverageFilter, AveragesTheLastWindowSamplesAndFewerAtStart) {
  Signal* x = signal("x");
  Filter* f = make("MovingAverage", io("x", "avg", {{"window", 3.0}}));
  for (double v : {1.0, 2.0, 3.0, 4.0, 5.0, -9.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(values_of("avg"), (Values{1, 1.5, 2, 3, 4, 0}));
}

TEST_F(MovingAverageFilter, WindowOfOneCopiesTheInput) {
  Signal* x = signal("x");
  Filter* f = make("MovingAverage", io("x", "avg", {{"window", 1.0}}));
  for (double v : {1.0, -2.0, 7.0}) feed(x, f, 1.0, v);
  EXPECT_EQ(values_of("avg"), (Values{1, -2, 7}));
}

TEST_F(MovingAverageFilter, VectorAverageIsElementWise) {
  Signal* x = signal("x", 2);
  Filter* f = make("MovingAverage", io("x", "avg", {{"window", 2.0}}));
  feed(x, f, 1.0, {1, 10});
  feed(x, f, 1.1, {3, 30});
  feed(x, f, 1.2, {5, 50});
  const std::vector<Written> out = written("avg");
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].value, (Values{1, 10}));
  EXPECT_EQ(out[1].value, (Values{2, 20}));
  EXPECT_EQ(out[2].value, (Values{4, 40}));
}

// A small window keeps its ring inside the filter, a large one on the heap: the same average.
TEST_F(MovingAverageFilter, AWindowTooLargeToKeepInsideTheFilterAveragesTheSame) {
  Signal* x = signal("x");
  make("MovingAverage", io("x", "small", {{"window", 14.0}}));
  make("MovingAverage", io("x", "large", {{"window", 15.0}}));
  for (int k = 1; k <= 40; ++k) {
    push(x, k, static_cast<double>(k));
    run_all(k);
  }
  const Values a = values_of("small");
  const Values b = values_of("large");
  ASSERT_EQ(a.size(), 40u);
  ASSERT_EQ(b.size(), 40u);
  for (int k = 1; k <= 40; ++k) {
    const auto i = static_cast<std::size_t>(k - 1);
    const int n14 = std::min(k, 14);
    const int n15 = std::min(k, 15);
    // The mean of k - n + 1 … k.
    EXPECT_DOUBLE_EQ(a[i], k - (n14 - 1) / 2.0) << k;
    EXPECT_DOUBLE_EQ(b[i], k - (n15 - 1) / 2.0) << k;
  }
}

TEST_F(MovingAverageFilter, LongRunStaysAccurateAfterAHugeValueLeavesTheWindow) {
  // A running sum alone would keep the rounding error of 1e17 forever (its ulp is 16); the
  // filter must be exact again once the spike has left the window.
  Signal* x = signal("x");
  Filter* f = make("MovingAverage", io("x", "avg", {{"window", 4.0}}));
  feed(x, f, 1.0, 0.25);
  feed(x, f, 1.0, 1e17);
  double t = 1.0;
  for (int k = 0; k < 100000; ++k) {
    t += 0.001;
    feed(x, f, t, 0.25 * (k % 8));
  }
  // The last four: k = 99996 … 99999 → 0.25 × (4, 5, 6, 7).
  EXPECT_EQ(latest("C.avg"), 0.25 * 5.5);
  const Values tail = values_of("avg");
  for (std::size_t i = tail.size() - 16; i < tail.size(); ++i) {
    // Four quarters over four: a multiple of 1/16, with no rounding error left.
    EXPECT_EQ(tail[i] * 16, std::floor(tail[i] * 16)) << i;
  }
}

TEST_F(MovingAverageFilter, LongRunOfLargeIrregularValuesStaysWithinRounding) {
  Signal* x = signal("x");
  Filter* f = make("MovingAverage", io("x", "avg", {{"window", 7.0}}));
  std::uint64_t s = 12345;
  std::vector<double> last;
  double t = 0.0;
  for (int k = 0; k < 300000; ++k) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    const double v = static_cast<double>(s >> 11) / 9007199254740992.0 * 1e9;
    last.push_back(v);
    if (last.size() > 7) last.erase(last.begin());
    t += 0.001;
    feed(x, f, t, v);
  }
  long double exact = 0;
  for (double v : last) exact += v;
  exact /= 7;
  EXPECT_NEAR(latest("C.avg"), static_cast<double>(exact), 2e-6);
}

// ---- Norm -------------------------------------------------------------------------------------

TEST_F(NormFilter, L2NormOfAThreeVectorIsAScalar) {
  Signal* v = signal("v", 3);
  Filter* f = make("Norm", io("v", "n"));
  ASSERT_EQ(monitor_.signals().find("C.n")->size(), 1u);
  feed(v, f, 1.0, {3, -4, 12});
  feed(v, f, 1.1, {0, 0, 0});
  EXPECT_EQ(values_of("n"), (Values{13, 0}));
}

TEST_F(NormFilter, L1AndLinfNorms) {
  Signal* v = signal("v", 3);
  make("Norm", io("v", "l1", {{"norm", std::string("L1")}}));
  make("Norm", io("v", "linf", {{"norm", std::string("Linf")}}));
  make("Norm", io("v", "l2", {{"norm", std::string("L2")}}));
  push(v, 1.0, {-7, 3, 5});
  run_all(1.0);
  EXPECT_EQ(values_of("l1"), Values{15});
  EXPECT_EQ(values_of("linf"), Values{7});
  EXPECT_DOUBLE_EQ(latest("C.l2"), std::sqrt(83.0));
}

TEST_F(NormFilter, UnknownNormIsRejected) {
  signal("v", 3);
  auto f = try_make("Norm", io("v", "n", {{"norm", std::string("L3")}}));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'norm'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.signals().find("C.n"), nullptr);
}

// ---- Arithmetic -------------------------------------------------------------------------------

const char* const kOperations[] = {"add", "subtract", "multiply", "divide", "min", "max"};

TEST_F(ArithmeticFilter, EachOperationWithAConstantOperand) {
  Signal* a = signal("a");
  for (const char* op : kOperations) {
    make("Arithmetic", io("a", std::string("r_") + op, {{"operation", std::string(op)}, {"operand", 4.0}}));
  }
  push(a, 1.0, 6);
  run_all(1.0);
  EXPECT_EQ(values_of("r_add"), Values{10});
  EXPECT_EQ(values_of("r_subtract"), Values{2});
  EXPECT_EQ(values_of("r_multiply"), Values{24});
  EXPECT_EQ(values_of("r_divide"), Values{1.5});
  EXPECT_EQ(values_of("r_min"), Values{4});
  EXPECT_EQ(values_of("r_max"), Values{6});
}

TEST_F(ArithmeticFilter, DefaultIsAddingTheOperand) {
  Signal* a = signal("a");
  Filter* f = make("Arithmetic", io("a", "r", {{"operand", -0.5}}));
  feed(a, f, 1.0, 2);
  EXPECT_EQ(values_of("r"), Values{1.5});
}

TEST_F(ArithmeticFilter, EachOperationOnTwoVectorSignalsElementWise) {
  Signal* a = signal("a", 2);
  Signal* b = signal("b", 2);
  for (const char* op : kOperations) {
    make("Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b"}},
                        {"output_signal", std::string("r_") + op},
                        {"operation", std::string(op)}});
  }
  push(a, 1.0, {6, 1});
  push(b, 1.0, {4, -2});
  run_all(1.0);
  EXPECT_EQ(latest_vector("r_add"), (Values{10, -1}));
  EXPECT_EQ(latest_vector("r_subtract"), (Values{2, 3}));
  EXPECT_EQ(latest_vector("r_multiply"), (Values{24, -2}));
  EXPECT_EQ(latest_vector("r_divide"), (Values{1.5, -0.5}));
  EXPECT_EQ(latest_vector("r_min"), (Values{4, -2}));
  EXPECT_EQ(latest_vector("r_max"), (Values{6, 1}));
  EXPECT_EQ(count_of("r_add"), 1u);  // a alone could not be combined yet
}

TEST_F(ArithmeticFilter, TwoSignalsWaitForBothThenUseTheNewestOfEach) {
  Signal* a = signal("a");
  Signal* b = signal("b");
  make("Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b"}},
                      {"output_signal", std::string("d")},
                      {"operation", std::string("subtract")}});
  push(a, 1.0, 10);
  run_all(1.0);
  EXPECT_EQ(count_of("d"), 0u);
  push(b, 2.0, 3);
  run_all(2.0);
  push(a, 3.0, 20);
  run_all(3.0);
  const std::vector<Written> out = written("d");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].value[0], 7);
  EXPECT_EQ(out[0].t, seconds_to_time(2.0));
  EXPECT_EQ(out[1].value[0], 17);
  EXPECT_EQ(out[1].t, seconds_to_time(3.0));
}

TEST_F(ArithmeticFilter, NeedsExactlyOneOfInputSignalAndInputSignals) {
  signal("a");
  signal("b");
  const std::size_t signals = monitor_.signals().all().size();
  auto both = try_make("Arithmetic", {{"input_signal", std::string("a")},
                                      {"input_signals", std::vector<std::string>{"a", "b"}},
                                      {"output_signal", std::string("r")}});
  ASSERT_FALSE(both);
  EXPECT_NE(both.error().message.find("'input_signal'"), std::string::npos) << both.error().message;
  EXPECT_NE(both.error().message.find("'input_signals'"), std::string::npos) << both.error().message;
  auto neither = try_make("Arithmetic", {{"output_signal", std::string("r")}, {"operand", 1.0}});
  ASSERT_FALSE(neither);
  EXPECT_NE(neither.error().message.find("'input_signal"), std::string::npos) << neither.error().message;
  auto three = try_make(
      "Arithmetic", {{"input_signals", std::vector<std::string>{"a", "b", "a"}}, {"output_signal", std::string("r")}});
  ASSERT_FALSE(three);
  EXPECT_NE(three.error().message.find("'input_signals'"), std::string::npos) << three.error().message;
  EXPECT_EQ(monitor_.filters().size(), 0u);
  EXPECT_EQ(monitor_.signals().all().size(), signals);
}

// ---- Vectorize --------------------------------------------------------------------------------

TEST_F(VectorizeFilter, ScalarsBecomeOneVectorOnceEveryInputHasASample) {
  Signal* x = signal("x");
  Signal* y = signal("y");
  Signal* z = signal("z");
  make("Vectorize",
       {{"input_signals", std::vector<std::string>{"x", "y", "z"}}, {"output_signal", std::string("xyz")}});
  ASSERT_EQ(monitor_.signals().find("C.xyz")->size(), 3u);
  push(x, 1.0, 1);
  run_all(1.0);
  push(z, 2.0, 3);
  run_all(2.0);
  EXPECT_EQ(count_of("xyz"), 0u);
  push(y, 3.0, 2);
  run_all(3.0);
  push(y, 4.0, 20);
  run_all(4.0);
  const std::vector<Written> out = written("xyz");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].value, (Values{1, 2, 3}));
  EXPECT_EQ(out[0].t, seconds_to_time(3.0));
  EXPECT_EQ(out[1].value, (Values{1, 20, 3}));
}

TEST_F(VectorizeFilter, VectorInputsAreRejected) {
  signal("x");
  signal("v", 2);
  auto f = try_make("Vectorize",
                    {{"input_signals", std::vector<std::string>{"x", "v"}}, {"output_signal", std::string("o")}});
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'C.v'"), std::string::npos) << f.error().message;
  EXPECT_EQ(monitor_.signals().find("C.o"), nullptr);
}

// ---- Bypass -----------------------------------------------------------------------------------

TEST_F(BypassFilter, CopiesVectorSamplesWithTheirTimes) {
  Signal* v = signal("v", 3);
  Filter* f = make("Bypass", io("v", "copy"));
  feed(v, f, 1.0, {1, -2, 3.5});
  feed(v, f, 1.25, {4, 5, 6});
  const std::vector<Written> out = written("copy");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].value, (Values{1, -2, 3.5}));
  EXPECT_EQ(out[0].t, seconds_to_time(1.0));
  EXPECT_EQ(out[1].value, (Values{4, 5, 6}));
  EXPECT_EQ(out[1].t, seconds_to_time(1.25));
  EXPECT_TRUE(events_.empty());
}

TEST_F(BypassFilter, ExistingOutputOfAnotherSizeIsRejected) {
  signal("v", 3);
  signal("s", 1);
  auto f = try_make("Bypass", io("v", "s"));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'output_signal'"), std::string::npos) << f.error().message;
}

// ---- NOP --------------------------------------------------------------------------------------

TEST_F(NopFilter, ConsumesItsInputWritesNothingAndRaisesNothing) {
  Signal* x = signal("x");
  const std::size_t signals = monitor_.signals().all().size();
  Filter* f = make("NOP", {{"input_signal", std::string("x")}});
  EXPECT_EQ(monitor_.signals().all().size(), signals);
  EXPECT_TRUE(f->outputs().empty());
  // One sample per run for longer than the history: every sample is read in time.
  for (int k = 0; k < 3000; ++k) feed(x, f, 1.0 + 0.001 * k, k % 2 == 0 ? 0.0 : 1e6);
  EXPECT_EQ(f->missed_samples(), 0u);
  // Left unread, the history overflows and the reader counts what it lost: it does read.
  for (int k = 0; k < 1100; ++k) push(x, 5.0, 1.0);
  f->run(seconds_to_time(5.0));
  EXPECT_EQ(f->missed_samples(), 1100u - x->buffer().capacity());
  EXPECT_TRUE(events_.empty());
  EXPECT_EQ(app_state(), State::Normal);
  EXPECT_EQ(monitor_.signals().all().size(), signals);
}

TEST_F(NopFilter, HasNoOutputOrEventParameters) {
  signal("x");
  auto f = try_make("NOP", {{"input_signal", std::string("x")}, {"output_signal", std::string("y")}});
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("'output_signal'"), std::string::npos) << f.error().message;
  auto g = try_make("NOP", {{"input_signal", std::string("x")}, {"event_onset", std::string("EVT_X")}});
  ASSERT_FALSE(g);
  EXPECT_NE(g.error().message.find("'event_onset'"), std::string::npos) << g.error().message;
}

}  // namespace
}  // namespace safecass::test
