#pragma once
// Internal: the TLS certificates of a system's members at the broker (docs/security.md "Members
// only at the broker"). `safecass keys` makes them with the bus keys: one CA per system, and for
// each member, the broker and the tools' reader a certificate signed by it (ECDSA P-256, SHA-256).

#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"

namespace safecass::middleware {

/// A certificate and its private key, both PEM.
struct Pem {
  std::string certificate;
  std::string key;
};

/// A new self-signed CA for `system_name`, valid 10 years. Errors: Io (OpenSSL failed).
[[nodiscard]] Expected<Pem> make_ca(std::string_view system_name);

/// A new key and its certificate for `name` (the subject's common name), signed by `ca`, valid 825
/// days, for TLS client and server alike. Its subjectAltName holds 127.0.0.1, localhost and each of
/// `addresses` ("IP:10.0.0.5", "DNS:robot.local").
/// Errors: InvalidArgument (`ca` is not a certificate with its key, an address is malformed), Io.
[[nodiscard]] Expected<Pem> make_certificate(const Pem& ca, const std::string& name,
                                             const std::vector<std::string>& addresses = {});

/// True when `certificate` (PEM) was issued and signed by `ca_certificate` (PEM).
bool signed_by(const std::string& certificate, const std::string& ca_certificate);

}  // namespace safecass::middleware
