// The one action path (introspect/action.hpp): every tool checks and applies an operator's,
// scenario's or recording's action through check() and apply(). A refused action changes nothing
// and is told to no one; an applied one is told once, with its time.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "safecass/core/clock.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/spec/instance.hpp"

namespace safecass::introspect {
namespace {

using ::testing::HasSubstr;

const std::string kRobodoc = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Told final : ActionObserver {
  std::vector<std::pair<std::string, Time>> actions;
  void applied(const Action& a, Time at) override { actions.emplace_back(std::string(action_name(a)), at); }
};

class ActionPath : public ::testing::Test {
protected:
  void SetUp() override {
    spec::InstanceOptions o;
    o.clock = &clock_;
    auto opened = spec::open_instance(kRobodoc, registry_, o);
    ASSERT_TRUE(opened) << spec::to_text(opened.error());
    system_ = std::move(*opened);
  }
  Coordinator& co() { return system_->coordinator(); }
  Monitor& monitor() { return system_->monitor(); }
  /// Everything an action can change: the history's length and every signal's newest sample time.
  std::string fingerprint() {
    std::string f = std::to_string(co().history_size());
    for (const auto& s : monitor().signals().all()) f += " " + std::to_string(s->buffer().end());
    return f;
  }
  /// A refused action: check() and apply() say the same, nothing changed, no one was told.
  std::string refusal(const Action& action) {
    const std::string before = fingerprint();
    auto checked = check(action, co(), monitor());
    Told told;
    auto applied = apply(action, co(), monitor(), Time{0}, &told);
    EXPECT_FALSE(checked) << action_name(action) << " passed its check";
    EXPECT_FALSE(applied) << action_name(action) << " was applied";
    if (checked || applied) return "(accepted)";
    EXPECT_EQ(checked.error().message, applied.error().message);
    EXPECT_EQ(fingerprint(), before) << action_name(action) << " changed the system";
    EXPECT_TRUE(told.actions.empty()) << action_name(action) << " was told";
    return applied.error().message;
  }

  const FilterRegistry& registry_ = builtin_filters();
  SimulatedClock clock_;
  std::unique_ptr<spec::Instance> system_;
};

TEST_F(ActionPath, ARefusedActionOfEveryKindChangesNothingAndIsToldToNoOne) {
  EXPECT_EQ(refusal(PushSample{"JR3.Nope", {1.0}}), "no signal 'JR3.Nope' (signals are written Component.signal)");
  EXPECT_EQ(refusal(PushSample{"JR3.Fz", {1.0, 2.0}}), "sample of JR3.Fz: 2 values; the signal has size 1");
  EXPECT_THAT(refusal(GenerateEvent{"EVT_NOPE", "JR3.s_A"}), HasSubstr("EVT_NOPE"));
  EXPECT_THAT(refusal(GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_Q"}), HasSubstr("JR3.s_Q"));
  EXPECT_THAT(refusal(BroadcastEvent{"EVT_FORCE_ERROR"}), HasSubstr("broadcasts need severity 251-255"));
  EXPECT_THAT(refusal(ResetState{"JR3.s_S.ForceData", "test", "why"}), HasSubstr("it is derived"));
  EXPECT_EQ(refusal(InjectShallow{"no_filter", {{1.0}}}), "no filter 'no_filter'");
  EXPECT_EQ(refusal(InjectShallow{"force_limit", {}}), "shallow injection into filter force_limit: no samples");
  EXPECT_THAT(refusal(InjectShallow{"force_limit", {{1.0, 2.0}}}), HasSubstr("injected sample 1 has 2 values"));
  EXPECT_THAT(refusal(InjectShallow{"force_limit", {{kInf}}}), HasSubstr("injected values must be finite"));
  EXPECT_EQ(refusal(InjectDeep{"JR3.Fz", {}}), "deep injection into signal JR3.Fz: no samples");
  EXPECT_THAT(refusal(InjectDeep{"JR3.Fz", {{1.0}, {-kInf}}}), HasSubstr("sample 2 is -inf, not a finite number"));
  EXPECT_THAT(refusal(InjectDeep{"JR3.Fz", {{1.0, 2.0}}}), HasSubstr("sample 1 has 2 values"));
}

TEST_F(ActionPath, ADeepInjectionLargerThanTheSignalsHistoryIsRefusedOnEveryPath) {
  const std::size_t capacity = monitor().signals().find("JR3.Fz")->buffer().capacity();
  const std::vector<std::vector<double>> too_many(capacity + 1, std::vector<double>{1.0});
  EXPECT_THAT(refusal(InjectDeep{"JR3.Fz", too_many}), HasSubstr("would overflow its history"));
  // The Monitor's own write (a scenario, a replay, an embedding application) refuses it alike.
  EXPECT_FALSE(monitor().inject_deep("JR3.Fz", too_many, Time{0}));
}

TEST_F(ActionPath, AnAppliedActionIsToldOnceWithTheTimeItWasAppliedAt) {
  Told told;
  const Time t = std::chrono::milliseconds(7);
  clock_.set(t);
  ASSERT_TRUE(apply(PushSample{"JR3.Fz", {5.0}}, co(), monitor(), t, &told));
  EXPECT_EQ(monitor().signals().find("JR3.Fz")->buffer().end(), 1u);
  ASSERT_TRUE(apply(GenerateEvent{"EVT_FORCE_ERROR", "JR3.s_A"}, co(), monitor(), t, &told));
  EXPECT_EQ(co().state(*co().structure().find_machine("JR3.s_A")), State::Error);
  ASSERT_TRUE(apply(ResetState{"JR3", "test", "cleared"}, co(), monitor(), t, &told));
  EXPECT_EQ(co().state(*co().structure().find_machine("JR3.s_A")), State::Normal);
  ASSERT_TRUE(apply(InjectDeep{"JR3.Fz", {{50.0}}}, co(), monitor(), t, &told));
  ASSERT_TRUE(apply(InjectShallow{"force_limit", {{50.0}}}, co(), monitor(), t, &told));
  ASSERT_EQ(told.actions.size(), 5u);
  const std::vector<std::string> kinds = {"sample", "generate", "reset", "dinject", "inject"};
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    EXPECT_EQ(told.actions[i].first, kinds[i]);
    EXPECT_EQ(told.actions[i].second, t);
  }
}

}  // namespace
}  // namespace safecass::introspect
