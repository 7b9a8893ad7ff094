#include <chrono>
#include <thread>

#include "filter_fixture.hpp"

namespace safecass::test {
namespace {

using MonitorTest = FilterFixture;

Params threshold(const std::string& input, double limit) {
  return Params{{"input_signal", input}, {"threshold", limit}, {"event_onset", std::string("EVT_X")}};
}

TEST_F(MonitorTest, CustomFilterTypesAreAddedToTheRegistryLikeBuiltins) {
  struct Always final : Filter {
    explicit Always(FilterInit i) : Filter(std::move(i)) {}
    static FilterManifest manifest() {
      FilterManifest m;
      m.params = {ParamSpec::signal("input_signal", "in"), ParamSpec::event("event_onset", "on")};
      m.inputs = {"input_signal"};
      return m;
    }
    void on_sample(std::size_t, const SampleView& s) noexcept override { report(true, s.scalar(), s.time); }
  };
  ASSERT_TRUE(registry_.add<Always>("Always"));
  EXPECT_FALSE(registry_.add<Always>("Always")) << "a type name is registered once";
  Signal* x = signal("x");
  Filter* f = make("Always", {{"input_signal", std::string("x")}, {"event_onset", std::string("EVT_X")}});
  feed(x, f, 0.001, 0);
  EXPECT_EQ(app_state(), State::Error);
  EXPECT_EQ(registry_.find("Always")->manifest.type, "Always");
}

TEST_F(MonitorTest, The2016FilterNamesAreAliasesOfTheBuiltins) {
  EXPECT_EQ(registry_.find("FilterThreshold"), registry_.find("Threshold"));
  EXPECT_EQ(registry_.find("FilterMovingAverage"), registry_.find("MovingAverage"));
  EXPECT_EQ(registry_.manifests().size(), 17u);
}

TEST_F(MonitorTest, AFilterAddedByAnAliasIsOfTheTypeTheAliasNames) {
  signal("x");
  Filter* f = make("Heartbeat", {{"input_signal", std::string("x")}, {"timeout", 1.0}});
  EXPECT_EQ(f->type(), "Watchdog");
  EXPECT_EQ(f->config().type, "Watchdog");
  FilterConfig c;
  c.type = "FilterThreshold";
  c.target.component = "C";
  c.params = threshold("x", 1);
  auto added = monitor_.add_filter(c);
  ASSERT_TRUE(added);
  EXPECT_EQ((*added)->type(), "Threshold");
  EXPECT_EQ((*added)->name().rfind("Threshold_", 0), 0u) << (*added)->name();
}

TEST_F(MonitorTest, ActiveFiltersRunOnlyFromTheirComponentsLoop) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold("x", 1));
  ASSERT_EQ(f->execution(), ExecutionMode::Active);
  x->push(Time{1}, 5.0);
  monitor_.tick(Time{1});
  EXPECT_EQ(app_state(), State::Normal) << "a monitor tick does not run ACTIVE filters";
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Error);
}

TEST_F(MonitorTest, PassiveFiltersRunOnMonitorTicksInSimulatedTime) {
  Signal* x = signal("x");
  FilterConfig c;
  c.type = "Threshold";
  c.target.component = "C";
  c.execution = ExecutionMode::Passive;
  c.params = threshold("x", 1);
  ASSERT_TRUE(monitor_.add_filter(c));
  x->push(Time{1}, 5.0);
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(app_state(), State::Normal) << "the component loop does not run PASSIVE filters";
  monitor_.tick(Time{1});
  EXPECT_EQ(app_state(), State::Error);
}

TEST_F(MonitorTest, MonitorThreadRunsPassiveFiltersInRealTimeAndStops) {
  SteadyClock real;
  Coordinator co("rt", &real);
  ASSERT_TRUE(co.add_component("C"));
  ASSERT_TRUE(co.add_event(EventDef{"EVT_X", 50, {Transition::N2E}, "", false, "", ""}));
  ASSERT_TRUE(co.add_event(EventDef{"/EVT_X", 50, {Transition::E2N}, "", false, "", ""}));
  Monitor monitor(co, registry_);
  Signal* x = *monitor.add_signal("C.x");
  FilterConfig c;
  c.type = "Threshold";
  c.target.component = "C";
  c.execution = ExecutionMode::Passive;
  c.params = threshold("x", 1);
  ASSERT_TRUE(monitor.add_filter(c));
  monitor.start(std::chrono::milliseconds(1));
  EXPECT_TRUE(monitor.running());
  x->push(real.now(), 5.0);
  for (int i = 0; i < 2000 && co.extended(ComponentId{0}).state != State::Error; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(co.extended(ComponentId{0}).state, State::Error);
  monitor.stop();
  EXPECT_FALSE(monitor.running());
}

TEST_F(MonitorTest, DisabledFilterSkipsRunsAndDropsSamplesSeenWhileDisabled) {
  Signal* x = signal("x");
  Filter* f = make("Threshold", threshold("x", 1));
  f->set_enabled(false);
  feed(x, f, 0.001, 5);
  EXPECT_EQ(app_state(), State::Normal);
  f->set_enabled(true);
  f->run(seconds_to_time(0.002));
  EXPECT_EQ(app_state(), State::Normal) << "a sample written while disabled is not judged later";
  feed(x, f, 0.003, 5);
  EXPECT_EQ(app_state(), State::Error);
}

TEST_F(MonitorTest, FilterEventsCarryTheirRootCauseIntoExplain) {
  Signal* x = signal("force");
  Filter* f = make("Threshold", threshold("force", 10));
  feed(x, f, 0.25, 12.5);
  const auto why = explain(co_, "C.s_A");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  EXPECT_EQ((*why)[0].root.filter, f->name());
  EXPECT_EQ((*why)[0].root.signal, "C.force");
  EXPECT_DOUBLE_EQ((*why)[0].root.value, 12.5);
  EXPECT_EQ((*why)[0].root.sample_time, seconds_to_time(0.25));
}

TEST_F(MonitorTest, FilterRootCausePropagatesToConnectedClients) {
  Coordinator& co = co_;
  const ComponentId client = *co.add_component("CLIENT");
  ASSERT_TRUE(co.add_provided(component_, "Data"));
  ASSERT_TRUE(co.add_required(client, "Data"));
  ASSERT_TRUE(co.connect("CLIENT.Data", "C.Data"));
  Signal* x = signal("force");
  Filter* f = make("Threshold", threshold("force", 10));
  feed(x, f, 0.5, 20);
  const auto why = explain(co, "CLIENT");
  ASSERT_TRUE(why);
  ASSERT_EQ(why->size(), 1u);
  EXPECT_TRUE((*why)[0].mirror);
  EXPECT_EQ((*why)[0].root.filter, f->name());
  EXPECT_DOUBLE_EQ((*why)[0].root.value, 20);
  EXPECT_EQ((*why)[0].path.front(), "C.s_A");
  EXPECT_EQ((*why)[0].path.back(), "CLIENT.s_R.Data");
}

TEST_F(MonitorTest, FiltersCanTargetEachKindOfMachine) {
  ASSERT_TRUE(co_.add_provided(component_, "P"));
  ASSERT_TRUE(co_.add_required(component_, "R"));
  Signal* x = signal("x");
  const std::pair<MachineKind, std::string> targets[] = {
      {MachineKind::Framework, ""}, {MachineKind::Provided, "P"}, {MachineKind::Required, "R"}};
  for (const auto& [kind, iface] : targets) {
    FilterConfig c;
    c.type = "Threshold";
    c.target = FilterTarget{kind, "C", iface};
    c.params = threshold("x", 1);
    auto f = monitor_.add_filter(c);
    ASSERT_TRUE(f) << f.error().message;
  }
  x->push(Time{1}, 5.0);
  monitor_.run_active(component_, Time{1});
  EXPECT_EQ(co_.state(*co_.structure().find_machine("C.s_F")), State::Error);
  EXPECT_EQ(co_.state(*co_.structure().find_machine("C.s_P.P")), State::Error);
  EXPECT_EQ(co_.state(*co_.structure().find_machine("C.s_R.R")), State::Error);
  FilterConfig bad;
  bad.type = "Threshold";
  bad.target = FilterTarget{MachineKind::Provided, "C", "Nope"};
  bad.params = threshold("x", 1);
  auto f = monitor_.add_filter(bad);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("C.s_P.Nope"), std::string::npos);
}

}  // namespace
}  // namespace safecass::test
