// The Control servant (middleware/src/control.cpp) called directly, without IceStorm: the remote
// injection paths follow the one rule of every injection path (injected values are finite).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "control.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::middleware {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const std::string kToken(64, 'a');

/// The robot coordinator of the robodoc example with its Control servant (writes allowed).
struct Robot {
  FilterRegistry registry;
  SimulatedClock clock;
  Coordinator co{"robot", &clock};
  Monitor monitor{co, registry};
  std::shared_ptr<wire::Control> control;
  std::size_t injections = 0;

  Robot() {
    register_builtin_filters(registry);
    const spec::LoadResult load =
        spec::load_system(std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json", registry);
    EXPECT_TRUE(load.ok());
    EXPECT_TRUE(spec::instantiate(*load.system, co, monitor, "robot"));
    co.subscribe([this](const Record& r) { injections += r.kind == RecordKind::Injection ? 1 : 0; });
    control = make_control(
        ControlContext{co, monitor, registry, "robot", true, kToken, [](const std::string&) {}, {}, {}, {}});
  }

  /// The message of the OperationError `call` throws, or "(accepted)".
  template <class F>
  std::string refusal(F call) {
    try {
      call();
    } catch (const wire::OperationError& e) {
      return e.message;
    }
    return "(accepted)";
  }
};

TEST(ControlServant, RefusesToInjectANonFiniteValueOnEveryWritePathAndChangesNothing) {
  Robot r;
  const Ice::Current current{};
  EXPECT_EQ(r.refusal([&] {
    r.control->filterInject(kToken, "force_limit", {{10.0}, {kInf}}, current);
  }),
            "shallow injection into filter force_limit: sample 2 is inf, not a finite number: injected values must be "
            "finite");
  EXPECT_EQ(r.refusal([&] { r.control->filterInject(kToken, "force_limit", {{-kInf}}, current); }),
            "shallow injection into filter force_limit: sample 1 is -inf, not a finite number: injected values must be "
            "finite");
  EXPECT_EQ(r.refusal([&] {
    r.control->filterDinject(kToken, "JR3.Force", {{0.0, kNaN, 0.0}}, current);
  }),
            "deep injection into signal JR3.Force: sample 1 value 2 is nan, not a finite number: injected values must "
            "be finite");
  EXPECT_EQ(r.injections, 0u) << "nothing was injected";
  // Finite values go through.
  EXPECT_EQ(r.refusal([&] { r.control->filterInject(kToken, "force_limit", {{10.0}}, current); }), "(accepted)");
  EXPECT_EQ(r.injections, 1u);
  EXPECT_EQ(r.refusal([&] {
    r.control->filterDinject(kToken, "JR3.Force", {{0.0, 0.0, 10.0}}, current);
  }),
            "(accepted)");
  EXPECT_GT(r.injections, 1u) << "one injection record per filter reading the signal";
}

}  // namespace
}  // namespace safecass::middleware
