#pragma once
/// @file keys.hpp
/// The keys of an authenticated bus (DESIGN §7, docs/security.md): every message on every topic is
/// authenticated as coming from the member it names: heartbeats and proofs of life signed with its
/// Ed25519 key, every other message sealed with the keys it shares with each other member (derived
/// from the same Ed25519 keys: nothing else to create).
///
/// A system's key directory holds
/// - `keyring`: one line per signer, `NAME ed25519 HEX-PUBLIC-KEY` (readable by every process of
///   the system and by the tools: it holds no secret);
/// - `NAME.secret`: the signer's secret key, mode 0600, owned by the user who runs it.
/// The signers are the system's coordinators and the supervisor (`kSupervisorSigner`). A process
/// finds the directory through `--keys DIR` or, without it, the environment variable
/// `SAFECASS_KEYS`. `safecass keys SYSTEM --out DIR` (or `scripts/setup-keys`) creates it.

#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

/// The name the supervisor signs with. No coordinator may use it.
inline constexpr std::string_view kSupervisorSigner = "supervisor";

/// Creates, in `dir` (made with mode 0700 when missing), a key pair for every coordinator of
/// `system` and for the supervisor, and the keyring listing their public keys. Returns the
/// signers' names. An existing secret key is never overwritten unless `replace`; a file at one
/// of the paths that is not a key written by this function is never overwritten.
/// Errors: InvalidArgument (no coordinators, a coordinator named "supervisor"), Duplicate (keys
/// exist and not `replace`), Io (with the path and the reason).
[[nodiscard]] Expected<std::vector<std::string>> create_bus_keys(const spec::SystemSpec& system, const std::string& dir,
                                                                 bool replace = false);

/// The key directory: `given` when not empty, else $SAFECASS_KEYS.
/// Errors: NotFound (neither, with how to create keys).
[[nodiscard]] Expected<std::string> bus_keys_dir(std::string_view given);

/// True when `host` is a loopback address or "localhost" (a message to it does not leave the host).
bool is_loopback_host(std::string_view host) noexcept;

}  // namespace safecass::middleware
