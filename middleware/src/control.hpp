#pragma once
// Internal: the Control servant (remote operations served by every coordinator process).

#include <functional>
#include <memory>
#include <string>

#include "ice_util.hpp"
#include "safecass/filters/monitor.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/local_query.hpp"

namespace safecass::middleware {

struct ControlContext {
  Coordinator& co;
  Monitor& monitor;
  const FilterRegistry& registry;
  std::string name;
  bool allow_write;
  std::string token;
  std::function<void(const std::string&)> log;
  std::string read_token;          ///< empty: reads are open to every local client
  introspect::LocalOptions clock;  ///< how its times read (NodeOptions::clock)
  /// The process's signed proof of life for a receiver's nonce (Alive::prove).
  std::function<wire::Signed(const Ice::ByteSeq& nonce)> prove;
};

/// The request-context key that carries the read credential.
inline constexpr const char* kReadCredentialKey = "safecass-read";

std::shared_ptr<wire::Control> make_control(ControlContext context);

}  // namespace safecass::middleware
