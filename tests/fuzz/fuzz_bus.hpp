#pragma once
/// @file fuzz_bus.hpp
/// What the bus targets (wire_events, wire_messages) share: the members of robodoc's keyring,
/// keys made at start with `safecass keys`' own code, so that a target seals and signs each input
/// as a member would and the receivers' decoders behind authentication are reached.

#include <Ice/Ice.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <unistd.h>

#include "auth.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/spec/load.hpp"

namespace safecass::fuzz {

/// Members "robot" (the sender) and "supervisor" (the receiver) of robodoc, and the keyring.
struct BusMembers {
  std::shared_ptr<Ice::Communicator> ice = Ice::initialize();
  std::optional<middleware::Keyring> keyring;
  std::optional<middleware::Signer> robot, supervisor;
};

/// Made once per process; the key files are removed once loaded.
inline BusMembers& bus_members() {
  static BusMembers* m = [] {
    auto* made = new BusMembers;
    const FilterRegistry& registry = builtin_filters();
    const spec::LoadResult loaded = spec::load_system(SAFECASS_SOURCE_DIR "/examples/robodoc/robodoc.json", registry);
    if (!loaded.system) __builtin_trap();
    const std::string dir =
        (std::filesystem::temp_directory_path() / ("safecass-bus-fuzz-" + std::to_string(::getpid()))).string();
    if (!middleware::create_bus_keys(*loaded.system, dir, middleware::KeyOptions::replacing())) __builtin_trap();
    auto keyring = middleware::Keyring::load(dir);
    if (!keyring) __builtin_trap();
    auto robot = middleware::Signer::load(dir, "robot", *keyring);
    auto supervisor = middleware::Signer::load(dir, "supervisor", *keyring);
    if (!robot || !supervisor) __builtin_trap();
    made->keyring.emplace(std::move(*keyring));
    made->robot.emplace(std::move(*robot));
    made->supervisor.emplace(std::move(*supervisor));
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    return made;
  }();
  return *m;
}

}  // namespace safecass::fuzz
