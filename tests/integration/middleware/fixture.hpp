#pragma once
// The ctest fixture's IceStorm as the middleware integration tests reach it: its port, and the
// system's CA it admits (scripts/start-icestorm --keys, written to SAFECASS_ICESTORM_ENV as
// ICESTORM_TLS). IceStorm admits only certificates of that CA (docs/security.md), so a test that
// makes keys of its own makes them with that CA.

#include <Ice/Ice.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "auth.hpp"      // middleware/src: the product's keyring
#include "ice_util.hpp"  // middleware/src: the product's TLS properties
#include "safecass/middleware/keys.hpp"
#include "safecass/spec/file.hpp"

namespace safecass::fixture {

/// The value of KEY in the fixture's environment file, empty when it is not there.
inline std::string icestorm_env(const std::string& key) {
  const char* file = std::getenv("SAFECASS_ICESTORM_ENV");
  std::ifstream in(file != nullptr ? file : "");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
  }
  return "";
}

/// The directory of the CA the fixture's IceStorm admits.
inline std::string ca_dir() { return icestorm_env("ICESTORM_TLS"); }

/// True when `dir` already holds the bus keys of every member of `system`, made with the fixture's
/// CA in `ca` (during this run of the tests: the fixture makes a new CA every run).
inline bool has_keys(const spec::SystemSpec& system, const std::string& dir, const std::string& ca) {
  const auto ca_pem = spec::read_regular_file(ca + "/ca.pem");
  const auto ours = spec::read_regular_file(dir + "/ca.pem");
  if (!ca_pem || !ours || *ours != *ca_pem || !middleware::Keyring::load(dir)) return false;
  std::vector<std::string> members{"supervisor"};
  for (const auto& [name, _] : system.coordinators) members.push_back(name);
  return std::all_of(members.begin(), members.end(), [&](const std::string& m) {
    return std::filesystem::exists(dir + "/" + m + ".secret") && std::filesystem::exists(dir + "/" + m + ".pem");
  });
}

/// The bus keys of `system` in `dir`, their certificates signed by the fixture's CA. Keys that a
/// test of this run made there already are kept: making them writes and syncs 16 files, and on a
/// loaded machine one such sync held a test for its whole timeout.
[[nodiscard]] inline bool make_keys(const spec::SystemSpec& system, const std::string& dir) {
  const std::string ca = ca_dir();
  if (ca.empty()) {
    ADD_FAILURE() << "the fixture's IceStorm runs without the system's CA (no ICESTORM_TLS)";
    return false;
  }
  if (has_keys(system, dir, ca)) return true;
  middleware::KeyOptions options = middleware::KeyOptions::replacing();
  options.ca_dir = ca;
  auto made = middleware::create_bus_keys(system, dir, options);
  EXPECT_TRUE(made) << (made ? "" : made.error().message);
  return made.has_value();
}

/// A communicator that presents the certificate `name` of the key directory `dir` (mutual TLS, as
/// every SAFECASS process does), with Ice's defaults otherwise and the given extra properties.
inline std::shared_ptr<Ice::Communicator> communicator(
    const std::string& dir, const std::string& name,
    const std::vector<std::pair<std::string, std::string>>& extra = {}) {
  Ice::InitializationData init;
  init.properties = Ice::createProperties();
  middleware::set_tls_properties(init.properties, middleware::TlsOptions{dir, name});
  for (const auto& [key, value] : extra) init.properties->setProperty(key, value);
  return Ice::initialize(init);
}

/// The endpoint of a test's own object adapter, and the TopicManager of the fixture's members'
/// broker on `port` or of its tools' broker (on the next port: docs/security.md).
inline const char* const kAdapterEndpoint = "ssl -h 127.0.0.1";
enum class Broker { Members, Tools };
inline std::string topic_manager(const std::string& port, Broker broker = Broker::Members) {
  return broker == Broker::Members
             ? "SafecassIceStorm/TopicManager:ssl -h 127.0.0.1 -p " + port
             : "SafecassToolStorm/TopicManager:ssl -h 127.0.0.1 -p " + std::to_string(std::stoi(port) + 1);
}

}  // namespace safecass::fixture
