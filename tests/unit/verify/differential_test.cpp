// The model is the engine (docs/verify.md §5): seeded random runs of the Promela model (SPIN's
// random simulation) and the same steps applied to a coordinator built from the same
// specification must agree on the state of every address (SYSTEM, components, machines,
// services) after every step. Thousands of steps in all, over systems with propagation levels,
// service dependencies, a cycle of connections, latched onsets, level rules that depend on the
// state and broadcasts.

#include <gtest/gtest.h>

#include <string>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/named.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/verify.hpp"
#include "verify_test_support.hpp"

namespace safecass::verify {
namespace {

/// A tree of `n` components (Ck requires the Out of C((k-1)/3)), each with an Error onset, a
/// Warning onset that turns into an Error from Warning ({N2W, W2E}), a latched onset on every
/// third component, services passing warnings on every other one, and a connection back from
/// the last component to the root (a cycle), plus a broadcast.
std::string tree(int n) {
  std::string s = R"({"safecass": 1, "system": "tree", "components": [)";
  for (int k = 0; k < n; ++k) {
    const std::string c = "C" + std::to_string(k);
    s += std::string(k ? ",\n" : "\n") + R"({"component": ")" + c +
         R"(", "interfaces": {"provided": ["Out", "Back"], "required": [)" + (k ? R"("In")" : R"("Loop")") +
         R"(]}, "event": [)";
    s += R"({"name": "EVT_)" + c + R"(_FAULT", "severity": 50, "state_transition": ["N2E", "W2E"]},
            {"name": "/EVT_)" +
         c + R"(_FAULT", "severity": 50, "state_transition": ["E2N", "E2W"]},
            {"name": "EVT_)" +
         c + R"(_SLOW", "severity": 30, "state_transition": ["N2W", "W2E"]},
            {"name": "/EVT_)" +
         c + R"(_SLOW", "severity": 30, "state_transition": ["W2N", "E2N", "E2W"]})";
    if (k % 3 == 0) {
      s += R"(, {"name": "EVT_)" + c + R"(_LOST", "severity": 90, "state_transition": ["N2E"], "latched": true})";
    }
    if (k == 0) {
      s += R"(, {"name": "EVT_STOP", "severity": 255, "state_transition": ["N2E", "W2E"]},
              {"name": "/EVT_STOP", "severity": 255, "state_transition": ["E2N", "E2W"]})";
    }
    s += R"(], "service": [{"name": "Out", "dependency": {"s_F": true, "s_A": true, "s_R": [)" +
         std::string(k ? R"("In")" : R"("Loop")") + "]}" + (k % 2 ? R"(, "propagate": "warning")" : "") +
         R"(}, {"name": "Back", "dependency": {"s_A": true}}]})";
  }
  s += "], \"connections\": [";
  for (int k = 1; k < n; ++k) {
    s += std::string(k > 1 ? ",\n" : "\n") + R"({"required": "C)" + std::to_string(k) + R"(.In", "provided": "C)" +
         std::to_string((k - 1) / 3) + R"(.Out"})";
  }
  s += R"(, {"required": "C0.Loop", "provided": "C)" + std::to_string(n - 1) + R"(.Out"}]})";
  return s;
}

/// Runs `seeds` random simulations of `steps` steps and replays each on a fresh coordinator.
void compare(const spec::SystemSpec& system, unsigned seeds, std::size_t steps, std::size_t& total) {
  for (unsigned seed = 1; seed <= seeds; ++seed) {
    auto sim = simulate(system, builtin_filters(), seed, steps);
    ASSERT_TRUE(sim) << sim.error().message;
    ASSERT_FALSE(sim->steps.empty());
    Coordinator co(system.name);
    Monitor monitor(co, builtin_filters());
    ASSERT_TRUE(spec::instantiate(system, co, monitor));
    std::vector<Address> addresses;
    for (const std::string& a : sim->addresses) {
      auto resolved = co.structure().resolve(a);
      ASSERT_TRUE(resolved) << a;
      addresses.push_back(*resolved);
    }
    for (std::size_t k = 0; k < sim->steps.size(); ++k) {
      const Step& s = sim->steps[k];
      if (s.kind == Step::Kind::Reset) {
        ASSERT_TRUE(reset(co, s.target, "test", "differential"));
      } else {
        ASSERT_TRUE(generate(co, s.event, s.target)) << s.event << " " << s.target;
      }
      for (std::size_t a = 0; a < addresses.size(); ++a) {
        ASSERT_EQ(co.state_of(addresses[a]), sim->states[k][a])
            << system.name << ", seed " << seed << ", step " << k << " ("
            << (s.kind == Step::Kind::Reset ? "reset " : s.event + " on ") << s.target << "): " << sim->addresses[a];
      }
      ++total;
    }
  }
}

TEST(ModelIsTheEngine, RandomRunsOfTheModelAndTheCoordinatorAgreeOnEveryAddressAfterEveryStep) {
  std::size_t total = 0;
  for (const char* path : {"examples/robodoc/robodoc.json", "tests/data/verify/missing_dependency.fixed.json",
                           "tests/data/verify/propagation_level.json", "tests/data/verify/level_rule.json",
                           "tests/data/verify/broadcast.fixed.json", "tests/data/verify/invariant.json"}) {
    const spec::LoadResult r = spec::load_system(path, builtin_filters());
    ASSERT_TRUE(r.ok()) << path;
    compare(*r.system, 3, 250, total);
  }
  const spec::LoadResult t = spec::load_system_from_text(tree(13), "tree.json", builtin_filters());
  ASSERT_TRUE(t.ok()) << spec::format(t.diagnostics.at(0));
  compare(*t.system, 4, 300, total);
  EXPECT_GE(total, 5000u) << "thousands of steps";
}

}  // namespace
}  // namespace safecass::verify
