// The one factory that puts a system together (spec/include/safecass/spec/instance.hpp) and the
// native runtime's system over it (extensions/native/include/safecass/native/system.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "safecass/native/system.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/instance.hpp"

#include "../../../examples/custom_filter/frozen_filter.hpp"

namespace safecass::runner {
namespace {

using native::kDefaultTick;
using native::open_system;
using native::System;
using native::SystemOptions;
using spec::to_text;
using ::testing::HasSubstr;

const std::string kRobodoc = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json";
const std::string kStory = std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/story.json";

FilterRegistry builtin() {
  FilterRegistry registry;
  register_builtin_filters(registry);
  return registry;
}

const std::string kEncoders = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/custom_filter/encoders.json";

TEST(SystemFactory, BuildsAFilterTypeThatOnlyTheApplicationsRegistryKnows) {
  FilterRegistry registry = builtin();
  ASSERT_TRUE(registry.add<Frozen>("Frozen"));
  auto built = spec::open_instance(kEncoders, registry);
  ASSERT_TRUE(built) << to_text(built.error());
  spec::Instance& instance = **built;
  EXPECT_EQ(&instance.registry(), &registry);
  EXPECT_EQ(instance.coordinator().structure().name(), "encoders");
  ASSERT_NE(instance.monitor().find_filter("frozen_angle"), nullptr);
  EXPECT_EQ(instance.monitor().find_filter("frozen_angle")->type(), "Frozen");
}

TEST(SystemFactory, AFilterTypeTheRegistryDoesNotKnowIsAnErrorAtItsPositionAndNothingIsBuilt) {
  const FilterRegistry registry = builtin();
  auto built = spec::open_instance(kEncoders, registry);
  ASSERT_FALSE(built);
  EXPECT_THAT(to_text(built.error()), HasSubstr("encoders.json:13:"));
  EXPECT_THAT(to_text(built.error()), HasSubstr("Frozen"));
}

TEST(SystemFactory, AnInstanceIsNamedAfterItsCoordinatorThenTheGivenNameThenTheSystem) {
  const FilterRegistry registry = builtin();
  auto system = spec::load_valid_system(kRobodoc, registry);
  ASSERT_TRUE(system) << to_text(system.error());
  spec::InstanceOptions options;
  EXPECT_EQ(spec::coordinator_name(*system, options), system->name);
  options.name = "supervisor";
  EXPECT_EQ(spec::coordinator_name(*system, options), "supervisor");
  options.coordinator = "ui";
  EXPECT_EQ(spec::coordinator_name(*system, options), "ui");
  auto ui = spec::build_instance(*system, registry, options);
  ASSERT_TRUE(ui) << to_text(ui.error());
  EXPECT_EQ((*ui)->coordinator().structure().name(), "ui");
  EXPECT_TRUE((*ui)->coordinator().structure().find_component("PENDANT"));
  EXPECT_FALSE((*ui)->coordinator().structure().find_component("JR3")) << "another coordinator's component";
}

TEST(SystemFactory, OpensTheWholeSystemWithOneTaskPerComponentOnItsOwnSimulatedClock) {
  const FilterRegistry registry = builtin();
  auto opened = open_system(kRobodoc, registry);
  ASSERT_TRUE(opened) << to_text(opened.error());
  System& system = **opened;
  EXPECT_EQ(system.runtime().task_count(), system.spec().components.size());
  ASSERT_NE(system.simulated_clock(), nullptr);
  for (const char* name : {"JR3", "BMM", "CONTROL", "SERVO", "PENDANT"}) {
    EXPECT_TRUE(system.coordinator().structure().find_component(name)) << name;
  }
}

TEST(SystemFactory, OneCoordinatorOfAMultiProcessSystemBuildsOnlyItsComponentsOnTheGivenClock) {
  const FilterRegistry registry = builtin();
  SimulatedClock host;
  SystemOptions options;
  options.coordinator = "ui";
  options.clock = &host;
  auto opened = open_system(kRobodoc, registry, options);
  ASSERT_TRUE(opened) << to_text(opened.error());
  System& system = **opened;
  EXPECT_EQ(system.coordinator().structure().name(), "ui");
  EXPECT_EQ(system.simulated_clock(), nullptr) << "the system reads the clock it was given";
  EXPECT_TRUE(system.coordinator().structure().find_component("PENDANT"));
  EXPECT_FALSE(system.coordinator().structure().find_component("JR3")) << "another coordinator's component";
  EXPECT_EQ(system.runtime().task_count(), 1u);
}

TEST(SystemFactory, AnUnknownCoordinatorIsAnErrorThatNamesItAndNothingIsBuilt) {
  const FilterRegistry registry = builtin();
  SystemOptions options;
  options.coordinator = "nowhere";
  auto opened = open_system(kRobodoc, registry, options);
  ASSERT_FALSE(opened);
  EXPECT_THAT(to_text(opened.error()), HasSubstr("nowhere"));
}

TEST(SystemFactory, AnInvalidSystemFileReturnsEveryErrorWithItsPosition) {
  const FilterRegistry registry = builtin();
  const std::string bad = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/bad_specs/unknown_key.json";
  auto opened = open_system(bad, registry);
  ASSERT_FALSE(opened);
  ASSERT_FALSE(opened.error().empty());
  EXPECT_THAT(to_text(opened.error()), HasSubstr("unknown_key.json:4:3: error:"));
}

TEST(SystemFactory, AScenarioRunnerIsOpenedInOneStepAndRunsTheStory) {
  const FilterRegistry registry = builtin();
  auto opened = ScenarioRunner::open(ScenarioSource{kStory, ""}, registry);
  ASSERT_TRUE(opened) << to_text(opened.error());
  RunOptions options;
  options.quiet = true;
  const RunResult result = (*opened)->run(options);
  EXPECT_GT(result.checks, 0);
  EXPECT_TRUE(result.passed());
}

TEST(SystemFactory, ASystemWithNoScenarioTicksAtTheDefaultTickAndSoDoItsComponentsWithNoPeriod) {
  const FilterRegistry registry = builtin();
  auto opened = ScenarioRunner::open(ScenarioSource{"", kRobodoc}, registry);
  ASSERT_TRUE(opened) << to_text(opened.error());
  EXPECT_EQ(seconds_to_time((*opened)->scenario().period), kDefaultTick);
  EXPECT_EQ((*opened)->scenario().duration, 0.0);
}

TEST(SystemFactory, AScenarioWhoseSystemHasErrorsReportsThoseErrorsAndNothingElse) {
  const FilterRegistry registry = builtin();
  const std::string bad = std::string(SAFECASS_SOURCE_DIR) + "/tests/data/bad_specs/unknown_key.json";
  auto opened = ScenarioRunner::open(ScenarioSource{"", bad}, registry);
  ASSERT_FALSE(opened);
  const std::string text = to_text(opened.error());
  EXPECT_THAT(text, HasSubstr("unknown_key.json:4:3: error:"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("cannot load system"))) << "one mistake, one diagnostic";
}

TEST(SystemFactory, NoSystemAndNoScenarioIsAnErrorThatSaysWhatIsNeeded) {
  const FilterRegistry registry = builtin();
  auto opened = ScenarioRunner::open(ScenarioSource{}, registry);
  ASSERT_FALSE(opened);
  EXPECT_THAT(to_text(opened.error()), HasSubstr("a system file is needed"));
}

}  // namespace
}  // namespace safecass::runner
