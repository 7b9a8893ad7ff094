// In-process and remote answers are equal for every console read command (DESIGN §6, the read
// model of docs/architecture.md): the robodoc story runs in this process to its end; then one
// console reads it through introspect::LocalQuery, another through the middleware (a
// CoordinatorNode serving that same coordinator on the fixture's IceStorm, reached by
// RemoteClient), stopped at 1.62 s of the story. Each command's text and JSON answers must be
// equal, with only times and process (coordinator) names normalised. One ctest case per command.
//
// Environment (set by CMake): SAFECASS_SOURCE_DIR, SAFECASS_ICESTORM_ENV (the fixture's
// scripts/start-icestorm --env file), SAFECASS_KEYS (the robodoc keys).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "console.hpp"
#include "console_shell.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/node.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? v : "";
}

std::string env_file_value(const std::string& file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
  }
  return "";
}

/// Times (scenario seconds or wall-clock time) and the process's name replaced by placeholders.
std::string normalised(std::string text, const std::string& process) {
  text = std::regex_replace(text, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}[+-]\d\d:\d\d)"), "<time>");
  text = std::regex_replace(text, std::regex(R"(t=-?\d+\.\d{6})"), "t=<time>");
  text = std::regex_replace(text, std::regex(R"(-?\d+\.\d{6} s\b)"), "<time> s");
  text = std::regex_replace(text, std::regex(R"re("(t|root_t|sample_t|first|last)":-?[0-9.e+-]+)re"), "\"$1\":<time>");
  return std::regex_replace(text, std::regex("'" + process + "'"), "'<process>'");
}

/// The robodoc story run to its end in this process, served on IceStorm as coordinator "robot".
class Story {
public:
  Story() {
    register_builtin_filters(registry_);
    const std::string root = env("SAFECASS_SOURCE_DIR");
    spec::ScenarioLoad load = spec::load_scenario(root + "/examples/robodoc/story.json");
    EXPECT_TRUE(load.scenario.has_value());
    if (!load.scenario) return;
    spec::Scenario scenario = std::move(*load.scenario);
    spec::LoadResult a = spec::load_system(scenario.system, registry_);
    spec::LoadResult b = spec::load_system(scenario.system, registry_);
    EXPECT_TRUE(a.ok() && b.ok());
    if (!a.system || !b.system) return;
    system_ = std::move(*b.system);
    period_ = scenario.period;
    duration_ = scenario.duration;
    auto opened = runner::ScenarioRunner::open(std::move(scenario), std::move(*a.system), registry_);
    EXPECT_TRUE(opened.has_value());
    if (!opened) return;
    runner_ = std::move(*opened);
    // 1.62 s: JR3's force is stale (a filter's root with its sample), the force error, the bone
    // motion and its reset are in the history.
    runner::RunResult result;
    runner_->advance_to(seconds_to_time(1.62), result);
  }

  /// Starts the node; false (with a message) when it cannot.
  bool serve(std::string& why) {
    middleware::NodeOptions o;
    auto ice =
        middleware::parse_ice_endpoint("127.0.0.1:" + env_file_value(env("SAFECASS_ICESTORM_ENV"), "ICESTORM_PORT"));
    if (!ice) {
      why = ice.error().message;
      return false;
    }
    o.ice = *ice;
    o.clock.base = introspect::TimeBase::Simulated;  // the story's seconds on both sides
    o.clock.period = period_;
    o.clock.duration = duration_;
    o.lost_after = std::chrono::milliseconds(60000);
    o.log = [](const std::string&) {};
    auto node =
        middleware::CoordinatorNode::create(runner_->coordinator(), runner_->monitor(), registry_, system_, "robot", o);
    if (!node) {
      why = node.error().message;
      return false;
    }
    node_ = std::move(*node);
    if (auto r = node_->start(); !r) {
      why = r.error().message;
      return false;
    }
    return true;
  }

  std::unique_ptr<tools::Console> local_console(bool json) {
    tools::Target t;
    introspect::LocalOptions o;
    o.name = "robot";
    o.period = period_;
    o.duration = duration_;
    t.query = std::make_unique<introspect::LocalQuery>(runner_->coordinator(), runner_->monitor(), registry_, o);
    t.subject = "in-process";
    auto backend = tools::make_backend(std::move(t), tools::ConsoleOptions{json, false});
    EXPECT_TRUE(backend.has_value());
    return std::make_unique<tools::Console>(std::move(*backend), tools::ConsoleOptions{json, false});
  }

  std::unique_ptr<tools::Console> remote_console(bool json, std::string& why) {
    middleware::ClientOptions o;
    o.ice =
        *middleware::parse_ice_endpoint("127.0.0.1:" + env_file_value(env("SAFECASS_ICESTORM_ENV"), "ICESTORM_PORT"));
    o.coordinator = "robot";
    o.timeout = std::chrono::milliseconds(5000);
    auto client = middleware::RemoteClient::connect(o);
    if (!client) {
      why = client.error().message;
      return nullptr;
    }
    tools::Target t;
    t.query = std::move(*client);
    t.subject = "live";
    auto backend = tools::make_backend(std::move(t), tools::ConsoleOptions{json, false});
    if (!backend) {
      why = backend.error().message;
      return nullptr;
    }
    return std::make_unique<tools::Console>(std::move(*backend), tools::ConsoleOptions{json, false});
  }

  ~Story() {
    if (node_) node_->stop();
  }

private:
  FilterRegistry registry_;
  spec::SystemSpec system_;
  std::unique_ptr<runner::ScenarioRunner> runner_;
  std::unique_ptr<middleware::CoordinatorNode> node_;
  double period_ = 0.001;
  double duration_ = 0.0;
};

struct ReadCommand {
  const char* name;  ///< the ctest case
  const char* line;  ///< the console command
};

class ConsoleReadCommand : public ::testing::TestWithParam<ReadCommand> {};

TEST_P(ConsoleReadCommand, AnswersTheSameInProcessAndRemote) {
  ASSERT_FALSE(env("SAFECASS_ICESTORM_ENV").empty()) << "no IceStorm fixture";
  Story story;
  std::string why;
  ASSERT_TRUE(story.serve(why)) << why;
  for (const bool json : {false, true}) {
    auto local = story.local_console(json);
    auto remote = story.remote_console(json, why);
    ASSERT_TRUE(remote) << why;
    const tools::ConsoleReply want = local->execute(GetParam().line);
    const tools::ConsoleReply got = remote->execute(GetParam().line);
    if (!json) {
      EXPECT_FALSE(want.out.empty() && want.err.empty()) << "the command answers something";
    }
    EXPECT_EQ(got.ok, want.ok) << GetParam().line;
    EXPECT_EQ(normalised(got.out, "robot"), normalised(want.out, "robot"))
        << GetParam().line << (json ? " (--json)" : "");
    EXPECT_EQ(normalised(got.err, "robot"), normalised(want.err, "robot"))
        << GetParam().line << (json ? " (--json)" : "");
  }
}

INSTANTIATE_TEST_SUITE_P(
    Robodoc, ConsoleReadCommand,
    ::testing::Values(
        ReadCommand{"state_list", "state list"}, ReadCommand{"state_list_component", "state list CONTROL"},
        ReadCommand{"state_summary", "state summary"}, ReadCommand{"analyze_now", "analyze now"},
        ReadCommand{"state_history", "state history 200"},
        ReadCommand{"state_history_component", "state history CONTROL 100"},
        ReadCommand{"state_history_machine", "state history JR3.s_A 100"},
        ReadCommand{"state_history_service", "state history CONTROL.s_S.Command 100"},
        ReadCommand{"event_history", "event history 200"}, ReadCommand{"filter_list", "filter list"},
        ReadCommand{"filter_info", "filter info force_limit"}, ReadCommand{"filter_info_type", "filter info Threshold"},
        ReadCommand{"event_list", "event list"}, ReadCommand{"connection_list", "connection list"},
        ReadCommand{"service_list", "service list"}, ReadCommand{"explain_component", "explain SERVO"},
        ReadCommand{"explain_system", "explain SYSTEM"}, ReadCommand{"explain_machine", "explain JR3.s_A"},
        ReadCommand{"explain_service", "explain CONTROL.s_S.Command"}, ReadCommand{"time", "time"},
        ReadCommand{"unknown_name", "explain NOPE"}),
    [](const ::testing::TestParamInfo<ReadCommand>& command) { return std::string(command.param.name); });

}  // namespace
}  // namespace safecass
