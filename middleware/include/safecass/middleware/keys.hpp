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
/// - the TLS credentials of the members at the broker (docs/security.md "Members only at the
///   broker"): `ca.pem` (the system's CA) and `ca.key` (its key, mode 0600, needed only to make
///   certificates), and `NAME.pem` / `NAME.key` (mode 0600) for every signer, for IceStorm
///   (`kBrokerCertificate`) and for the tools (`kReaderCertificate`).
/// The signers are the system's coordinators and the supervisor (`kSupervisorSigner`). A process
/// finds the directory through `--keys DIR` or, without it, the environment variable
/// `SAFECASS_KEYS`, and when it holds `ca.pem` speaks to IceStorm and to its peers only over mutual
/// TLS (tls_from_keys). `safecass keys SYSTEM --out DIR` (or `scripts/setup-keys`) creates it.

#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::middleware {

/// The name the supervisor signs with. No coordinator may use it.
inline constexpr std::string_view kSupervisorSigner = "supervisor";
/// The certificate IceStorm presents (scripts/start-icestorm --keys DIR).
inline constexpr std::string_view kBrokerCertificate = "icestorm";
/// The certificate the tools present (console, watch, viewer, timeline): members at the broker
/// that hold no signing key.
inline constexpr std::string_view kReaderCertificate = "reader";

/// How create_bus_keys makes a key directory.
struct KeyOptions {
  /// Replace existing keys and certificates (the CA is kept).
  bool replace = false;
  /// Other addresses the processes are reached at, for the certificates' subjectAltName
  /// ("IP:10.0.0.5", "DNS:robot.local"); 127.0.0.1 and localhost are always there.
  std::vector<std::string> addresses;
  /// Sign with the CA of this directory (its ca.pem and ca.key) instead of the key directory's
  /// own: systems that share one IceStorm share its CA. Only ca.pem is copied: the CA's key stays
  /// where it is.
  std::string ca_dir;

  /// Options that replace existing keys (what tests and benchmarks use).
  static KeyOptions replacing() {
    KeyOptions o;
    o.replace = true;
    return o;
  }
};

/// Creates, in `dir` (made with mode 0700 when missing), a key pair for every coordinator of
/// `system` and for the supervisor, the keyring listing their public keys, and the TLS
/// certificates: the system's CA (that of `options.ca_dir`; else kept when `dir` holds one; else
/// made) and a certificate signed by it for every signer, IceStorm and the reader. Returns the
/// signers' names. An existing secret key is never overwritten unless `options.replace`; a file at
/// one of the paths that is not a key or certificate written by this function is never overwritten.
/// Errors: InvalidArgument (no coordinators, a coordinator named supervisor, icestorm, reader or
/// ca, a malformed address), Duplicate (keys exist and not `replace`), Io (with the path and the
/// reason, e.g. a ca.pem without its ca.key). An error in the arguments or the CA writes nothing.
[[nodiscard]] Expected<std::vector<std::string>> create_bus_keys(const spec::SystemSpec& system, const std::string& dir,
                                                                 const KeyOptions& options = {});

/// The key directory: `given` when not empty, else $SAFECASS_KEYS.
/// Errors: NotFound (neither, with how to create keys).
[[nodiscard]] Expected<std::string> bus_keys_dir(std::string_view given);

/// True when `host` is a loopback address or "localhost" (a message to it does not leave the host).
bool is_loopback_host(std::string_view host) noexcept;

}  // namespace safecass::middleware
