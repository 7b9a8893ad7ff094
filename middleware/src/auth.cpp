// Bus keys and signed messages (see keys.hpp, auth.hpp and docs/security.md).

#include "auth.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "certificates.hpp"
#include "safecass/middleware/keys.hpp"

namespace safecass::middleware {

namespace {

constexpr std::string_view kContext = "safecass.bus.v1";       // signed messages
constexpr std::string_view kSealContext = "safecass.bus.v2";   // sealed messages
constexpr std::string_view kPairContext = "safecass.pair.v1";  // pairwise keys
constexpr std::size_t kTagBytes = 16;
constexpr std::size_t kDigestBytes = 32;
constexpr std::size_t kPairKeyBytes = 32;
constexpr std::string_view kSecretTag = "ed25519-secret";
constexpr std::size_t kMaxKeyFile = std::size_t{64} * 1024;

bool sodium_ready() noexcept {
  static const bool ready = ::sodium_init() >= 0;
  return ready;
}

std::string to_hex(const unsigned char* data, std::size_t size) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(size * 2);
  for (std::size_t i = 0; i < size; ++i) {
    out += kHex[data[i] >> 4];
    out += kHex[data[i] & 0xf];
  }
  return out;
}

bool from_hex(std::string_view hex, std::string& out, std::size_t size) {
  if (hex.size() != size * 2) return false;
  out.assign(size, '\0');
  for (std::size_t i = 0; i < size; ++i) {
    int v = 0;
    for (int k = 0; k < 2; ++k) {
      const char c = hex[2 * i + static_cast<std::size_t>(k)];
      int d = -1;
      if (c >= '0' && c <= '9') d = c - '0';
      if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
      if (d < 0) return false;
      v = v * 16 + d;
    }
    out[i] = static_cast<char>(v);
  }
  return true;
}

/// Writes the bytes a signature covers into `text` (its storage is reused).
void signed_bytes(std::string& text, std::string_view kind, std::string_view signer, const Ice::ByteSeq& body) {
  text.clear();
  text.reserve(kContext.size() + kind.size() + signer.size() + body.size() + 3);
  text.append(kContext).push_back('\0');
  text.append(kind).push_back('\0');
  text.append(signer).push_back('\0');
  text.append(reinterpret_cast<const char*>(body.data()), body.size());
}

std::string signed_bytes(std::string_view kind, std::string_view signer, const Ice::ByteSeq& body) {
  std::string text;
  signed_bytes(text, kind, signer, body);
  return text;
}

/// Reads a small regular file (no FIFO, no device: a key file is never either).
[[nodiscard]] Expected<std::string> read_small_file(const std::string& path, struct stat* info = nullptr) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) {
    const ErrorCode code = errno == ENOENT ? ErrorCode::NotFound : ErrorCode::Io;
    return fail(code, path + ": " + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || static_cast<std::size_t>(st.st_size) > kMaxKeyFile) {
    ::close(fd);
    return fail(ErrorCode::Io, path + ": not a regular file of at most 64 KiB");
  }
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  const ssize_t n = ::read(fd, text.data(), text.size());
  ::close(fd);
  if (n != static_cast<ssize_t>(text.size())) return fail(ErrorCode::Io, path + ": short read");
  if (info != nullptr) *info = st;
  return text;
}

bool valid_signer_name(std::string_view name) {
  return !name.empty() && name.size() <= 128 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

/// Writes `text` to a new file `path` with `mode`; an existing file is replaced only when
/// `replace` and it is a regular file of ours that `is_ours` recognises.
[[nodiscard]] Expected<void> write_new_file(const std::string& path, const std::string& text, mode_t mode, bool replace,
                                            std::string_view what) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!replace) return fail(ErrorCode::Duplicate, path + ": exists (pass --replace to create new keys)");
    auto old = read_small_file(path);
    const bool ours =
        S_ISREG(st.st_mode) && st.st_uid == ::geteuid() && old &&
        (old->rfind(std::string(kSecretTag), 0) == 0 || old->rfind("# SAFECASS bus keyring", 0) == 0 ||
         old->rfind("-----BEGIN CERTIFICATE-----", 0) == 0 || old->rfind("-----BEGIN PRIVATE KEY-----", 0) == 0);
    if (!ours)
      return fail(ErrorCode::Io, path + ": exists and is not a SAFECASS " + std::string(what) + "; not replaced");
    if (::unlink(path.c_str()) != 0) return fail(ErrorCode::Io, path + ": " + std::strerror(errno));
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, mode);
  if (fd < 0) return fail(ErrorCode::Io, "cannot create " + path + ": " + std::strerror(errno));
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) &&
                  ::fchmod(fd, mode) == 0 && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) return fail(ErrorCode::Io, "cannot write " + path + ": " + std::strerror(errno));
  return {};
}

/// "IP:ADDRESS" (IPv4 or IPv6) or "DNS:NAME" (letters, digits, '-' and '.').
bool valid_address(std::string_view a) {
  if (a.rfind("IP:", 0) == 0) {
    const std::string ip(a.substr(3));
    unsigned char buffer[sizeof(in6_addr)];
    return ::inet_pton(AF_INET, ip.c_str(), buffer) == 1 || ::inet_pton(AF_INET6, ip.c_str(), buffer) == 1;
  }
  if (a.rfind("DNS:", 0) != 0 || a.size() == 4 || a.size() > 4 + 253) return false;
  return std::all_of(a.begin() + 4, a.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '.';
  });
}

/// The CA of `dir` (ca.pem and ca.key), or NotFound when it holds neither.
[[nodiscard]] Expected<Pem> read_ca(const std::string& dir) {
  auto certificate = read_small_file(dir + "/ca.pem");
  struct stat st {};
  auto key = read_small_file(dir + "/ca.key", &st);
  if (key && (st.st_uid != ::geteuid() || (st.st_mode & 077) != 0)) {
    // Whoever reads the CA's key can make a member: refused as every other private key is.
    return fail(ErrorCode::Denied, dir + "/ca.key: a private key must be owned by its user and have mode 0600");
  }
  if (certificate && key) return Pem{*certificate, *key};
  if (!certificate && certificate.error().code == ErrorCode::NotFound && !key &&
      key.error().code == ErrorCode::NotFound) {
    return fail(ErrorCode::NotFound, dir + " holds no CA (ca.pem, ca.key)");
  }
  return fail(ErrorCode::Io, (certificate ? key.error() : certificate.error()).message +
                                 " (ca.pem and ca.key go together: restore the missing one, give the directory of "
                                 "the CA's key with --ca DIR, or remove ca.pem to make a new CA, and then every "
                                 "certificate)");
}

/// The system's CA for `dir`: that of `ca_dir` when given (its ca.pem copied to `dir`); else kept
/// when `dir` holds one (so that the certificates made again stay trusted); else made.
[[nodiscard]] Expected<Pem> system_ca(const std::string& dir, std::string_view system_name, const std::string& ca_dir) {
  if (!ca_dir.empty()) {
    auto ca = read_ca(ca_dir);
    if (!ca) return ca;
    if (auto r = write_new_file(dir + "/ca.pem", ca->certificate, 0644, true, "CA"); !r) {
      return tl::unexpected(r.error());
    }
    return ca;
  }
  auto kept = read_ca(dir);
  if (kept || kept.error().code != ErrorCode::NotFound) return kept;
  auto ca = make_ca(system_name);
  if (!ca) return ca;
  if (auto r = write_new_file(dir + "/ca.key", ca->key, 0600, false, "CA key"); !r) return tl::unexpected(r.error());
  if (auto r = write_new_file(dir + "/ca.pem", ca->certificate, 0644, false, "CA"); !r) {
    return tl::unexpected(r.error());
  }
  return ca;
}

/// A certificate signed by the system's CA for each of `names`, as NAME.pem and NAME.key.
[[nodiscard]] Expected<void> write_certificates(const std::string& dir, const Pem& ca,
                                                const std::vector<std::string>& names,
                                                const std::vector<std::string>& addresses) {
  for (const std::string& name : names) {
    auto made = make_certificate(ca, name, addresses);
    if (!made) return tl::unexpected(made.error());
    if (auto r = write_new_file(dir + "/" + name + ".key", made->key, 0600, true, "TLS key"); !r) return r;
    if (auto r = write_new_file(dir + "/" + name + ".pem", made->certificate, 0644, true, "certificate"); !r) return r;
  }
  return {};
}

}  // namespace

// ---- public: keys.hpp -------------------------------------------------------------------------

[[nodiscard]] Expected<std::vector<std::string>> create_bus_keys(const spec::SystemSpec& system, const std::string& dir,
                                                                 const KeyOptions& options) {
  if (!sodium_ready()) return fail(ErrorCode::Io, "libsodium could not be initialised");
  const bool replace = options.replace;
  for (const std::string& a : options.addresses) {
    if (!valid_address(a)) {
      return fail(ErrorCode::InvalidArgument,
                  "address '" + printable(a) + "': expected IP:ADDRESS or DNS:NAME (e.g. IP:10.0.0.5)");
    }
  }
  if (!options.ca_dir.empty()) {
    if (auto ca = read_ca(options.ca_dir); !ca) return tl::unexpected(ca.error());
  }
  std::vector<std::string> names;
  for (const auto& [name, _] : system.coordinators) {
    if (name == kSupervisorSigner || name == kBrokerCertificate || name == kReaderCertificate || name == "ca") {
      return fail(ErrorCode::InvalidArgument, "coordinator name '" + name +
                                                  "' is reserved (supervisor, icestorm, reader and ca name the "
                                                  "system's other keys and certificates)");
    }
    if (!valid_signer_name(name)) {
      return fail(ErrorCode::InvalidArgument,
                  "coordinator name '" + printable(name) + "' cannot name a key (letters, digits, '_' and '-' only)");
    }
    names.push_back(name);
  }
  if (names.empty()) return fail(ErrorCode::InvalidArgument, "system '" + system.name + "' declares no coordinators");
  names.emplace_back(kSupervisorSigner);
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    return fail(ErrorCode::Io, "cannot create " + dir + ": " + std::strerror(errno));
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return fail(ErrorCode::Io, dir + ": not a directory");
  if (!replace) {
    for (const std::string& name : names) {
      const std::string path = dir + "/" + name + ".secret";
      if (::lstat(path.c_str(), &st) == 0) {
        return fail(ErrorCode::Duplicate, path + ": exists (pass --replace to create new keys)");
      }
    }
  }
  auto ca = system_ca(dir, system.name, options.ca_dir);
  if (!ca) return tl::unexpected(ca.error());
  std::string keyring = "# SAFECASS bus keyring of system '" + system.name + "': NAME ed25519 PUBLIC-KEY\n";
  for (const std::string& name : names) {
    unsigned char pk[crypto_sign_PUBLICKEYBYTES];
    unsigned char sk[crypto_sign_SECRETKEYBYTES];
    ::crypto_sign_keypair(pk, sk);
    std::string secret = std::string(kSecretTag) + " " + to_hex(sk, sizeof sk) + "\n";
    ::sodium_memzero(sk, sizeof sk);
    auto written = write_new_file(dir + "/" + name + ".secret", secret, 0600, replace, "secret key");
    ::sodium_memzero(secret.data(), secret.size());
    if (!written) return tl::unexpected(written.error());
    keyring += name + " ed25519 " + to_hex(pk, sizeof pk) + "\n";
  }
  if (auto r = write_new_file(dir + "/keyring", keyring, 0644, true, "keyring"); !r) return tl::unexpected(r.error());
  std::vector<std::string> certified = names;
  certified.emplace_back(kBrokerCertificate);
  certified.emplace_back(kReaderCertificate);
  if (auto r = write_certificates(dir, *ca, certified, options.addresses); !r) return tl::unexpected(r.error());
  return names;
}

[[nodiscard]] Expected<std::string> bus_keys_dir(std::string_view given) {
  if (!given.empty()) return std::string(given);
  const char* env = std::getenv("SAFECASS_KEYS");
  if (env != nullptr && *env != '\0') return std::string(env);
  return fail(ErrorCode::NotFound,
              "the bus is authenticated and no keys were given: create them with `safecass keys SYSTEM --out DIR` "
              "(or scripts/setup-keys) and pass --keys DIR or set SAFECASS_KEYS=DIR");
}

bool is_loopback_host(std::string_view host) noexcept {
  if (host == "localhost" || host == "::1" || host == "[::1]") return true;
  in_addr addr{};
  const std::string text(host);
  return ::inet_pton(AF_INET, text.c_str(), &addr) == 1 && (ntohl(addr.s_addr) >> 24) == 127;
}

// ---- internal: auth.hpp -----------------------------------------------------------------------

Expected<Keyring> Keyring::load(const std::string& dir) {
  if (!sodium_ready()) return fail(ErrorCode::Io, "libsodium could not be initialised");
  const std::string path = dir + "/keyring";
  auto text = read_small_file(path);
  if (!text) {
    return fail(text.error().code,
                "bus keyring: " + text.error().message + " (create keys with `safecass keys SYSTEM --out DIR`)");
  }
  Keyring ring;
  std::map<std::string, std::string> keys;  // sorted: every process numbers the members alike
  std::istringstream lines(*text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string name, algorithm, hex, extra;
    words >> name >> algorithm >> hex;
    std::string key;
    if (!valid_signer_name(name) || algorithm != "ed25519" || (words >> extra) ||
        !from_hex(hex, key, crypto_sign_PUBLICKEYBYTES)) {
      return fail(ErrorCode::Parse, path + ":" + std::to_string(number) + ": expected 'NAME ed25519 HEX-PUBLIC-KEY'");
    }
    if (!ring.index_.emplace(name, 0).second) {
      return fail(ErrorCode::Parse, path + ":" + std::to_string(number) + ": '" + name + "' listed twice");
    }
    keys.emplace(name, std::move(key));
  }
  for (auto& [name, key] : keys) {
    ring.index_[name] = ring.names_.size();
    ring.names_.push_back(name);
    ring.keys_.push_back(std::move(key));
  }
  return ring;
}

bool Keyring::verify(std::string_view signer, std::string_view kind, const Ice::ByteSeq& body,
                     const Ice::ByteSeq& signature) const noexcept {
  const auto at = index_.find(signer);
  if (at == index_.end() || signature.size() != crypto_sign_BYTES) return false;
  const std::string& key = keys_[at->second];
  try {
    // One buffer per receiving thread, reused: checking a message allocates nothing once it has
    // grown to the largest message seen.
    thread_local std::string bytes;
    signed_bytes(bytes, kind, signer, body);
    return ::crypto_sign_verify_detached(signature.data(), reinterpret_cast<const unsigned char*>(bytes.data()),
                                         bytes.size(), reinterpret_cast<const unsigned char*>(key.data())) == 0;
  } catch (...) {
    return false;
  }
}

Expected<Signer> Signer::load(const std::string& dir, std::string_view name, const Keyring& keyring) {
  if (!sodium_ready()) return fail(ErrorCode::Io, "libsodium could not be initialised");
  const std::string path = dir + "/" + std::string(name) + ".secret";
  struct stat st {};
  auto text = read_small_file(path, &st);
  if (!text) {
    if (text.error().code == ErrorCode::NotFound) {
      return fail(ErrorCode::NotFound, "no bus key for '" + std::string(name) + "': " + path +
                                           " does not exist (create keys with `safecass keys SYSTEM --out DIR`)");
    }
    return tl::unexpected(text.error());
  }
  if (st.st_uid != ::geteuid() || (st.st_mode & 077) != 0) {
    ::sodium_memzero(text->data(), text->size());
    return fail(ErrorCode::Denied, path + ": a secret key must be owned by its user and have mode 0600");
  }
  Signer s;
  s.name_ = std::string(name);
  const std::string_view body(*text);
  const bool ok = body.rfind(kSecretTag, 0) == 0 && body.size() >= kSecretTag.size() + 1 &&
                  from_hex(body.substr(kSecretTag.size() + 1, crypto_sign_SECRETKEYBYTES * 2), s.secret_,
                           crypto_sign_SECRETKEYBYTES);
  ::sodium_memzero(text->data(), text->size());
  if (!ok) return fail(ErrorCode::Parse, path + ": not a SAFECASS secret key");
  const auto me = keyring.index_.find(name);
  if (me == keyring.index_.end()) {
    return fail(ErrorCode::InvalidArgument, "'" + s.name_ + "' is not in the keyring of " + dir);
  }
  s.index_ = me->second;
  s.members_ = keyring.index_;
  // The key shared with each member: X25519 of this secret and that member's public key (both
  // Ed25519 keys, mapped to Curve25519), hashed with both names. The other member derives the same.
  unsigned char curve_sk[crypto_scalarmult_curve25519_BYTES];
  if (::crypto_sign_ed25519_sk_to_curve25519(curve_sk, reinterpret_cast<const unsigned char*>(s.secret_.data())) != 0) {
    return fail(ErrorCode::InvalidArgument, path + ": the key cannot be used for pairwise keys");
  }
  s.pair_.resize(keyring.size());
  for (std::size_t i = 0; i < keyring.size(); ++i) {
    if (i == s.index_) continue;
    unsigned char curve_pk[crypto_scalarmult_curve25519_BYTES];
    unsigned char shared[crypto_scalarmult_BYTES];
    if (::crypto_sign_ed25519_pk_to_curve25519(curve_pk,
                                               reinterpret_cast<const unsigned char*>(keyring.keys_[i].data())) != 0 ||
        ::crypto_scalarmult(shared, curve_sk, curve_pk) != 0) {
      ::sodium_memzero(curve_sk, sizeof curve_sk);
      return fail(ErrorCode::InvalidArgument, dir + "/keyring: the key of '" + keyring.names_[i] + "' is unusable");
    }
    const std::string& low = std::min(s.name_, keyring.names_[i]);
    const std::string& high = std::max(s.name_, keyring.names_[i]);
    std::string info(kPairContext);
    info.append(1, '\0').append(low).append(1, '\0').append(high);
    s.pair_[i].assign(kPairKeyBytes, '\0');
    ::crypto_generichash(reinterpret_cast<unsigned char*>(s.pair_[i].data()), kPairKeyBytes,
                         reinterpret_cast<const unsigned char*>(info.data()), info.size(), shared, sizeof shared);
    ::sodium_memzero(shared, sizeof shared);
  }
  ::sodium_memzero(curve_sk, sizeof curve_sk);
  return s;
}

namespace {
/// The digest a seal's tags authenticate: BLAKE2b-256 of context, kind, signer and body.
void seal_digest(unsigned char* digest, std::string_view kind, std::string_view signer, const Ice::ByteSeq& body) {
  crypto_generichash_state h;
  ::crypto_generichash_init(&h, nullptr, 0, kDigestBytes);
  const auto add = [&h](std::string_view part) {
    ::crypto_generichash_update(&h, reinterpret_cast<const unsigned char*>(part.data()), part.size());
  };
  add(kSealContext);
  add(std::string_view("\0", 1));
  add(kind);
  add(std::string_view("\0", 1));
  add(signer);
  add(std::string_view("\0", 1));
  ::crypto_generichash_update(&h, body.data(), body.size());
  ::crypto_generichash_final(&h, digest, kDigestBytes);
}
void seal_tag(unsigned char* tag, const unsigned char* digest, const std::string& pair_key) {
  ::crypto_generichash(tag, kTagBytes, digest, kDigestBytes, reinterpret_cast<const unsigned char*>(pair_key.data()),
                       pair_key.size());
}
}  // namespace

wire::Signed Signer::seal(std::string_view kind, Ice::ByteSeq body) const {
  wire::Signed m;
  m.signer = name_;
  m.kind = std::string(kind);
  unsigned char digest[kDigestBytes];
  seal_digest(digest, kind, name_, body);
  m.tags.assign(pair_.size() * kTagBytes, 0);
  for (std::size_t i = 0; i < pair_.size(); ++i) {
    if (i != index_) seal_tag(m.tags.data() + i * kTagBytes, digest, pair_[i]);
  }
  m.body = std::move(body);
  return m;
}

Ice::ByteSeq Signer::digest_of(const wire::Signed& m) {
  Ice::ByteSeq digest(kDigestBytes);
  seal_digest(digest.data(), m.kind, m.signer, m.body);
  return digest;
}

bool Signer::opens(const wire::Signed& m) const noexcept {
  const auto from = members_.find(m.signer);
  if (from == members_.end() || from->second == index_ || m.tags.size() != pair_.size() * kTagBytes) return false;
  unsigned char digest[kDigestBytes];
  unsigned char tag[kTagBytes];
  seal_digest(digest, m.kind, m.signer, m.body);
  seal_tag(tag, digest, pair_[from->second]);
  return ::sodium_memcmp(tag, m.tags.data() + index_ * kTagBytes, kTagBytes) == 0;
}

wire::Signed Signer::sign(std::string_view kind, Ice::ByteSeq body) const {
  wire::Signed m;
  m.signer = name_;
  m.kind = std::string(kind);
  const std::string bytes = signed_bytes(kind, name_, body);
  m.signature.resize(crypto_sign_BYTES);
  ::crypto_sign_detached(m.signature.data(), nullptr, reinterpret_cast<const unsigned char*>(bytes.data()),
                         bytes.size(), reinterpret_cast<const unsigned char*>(secret_.data()));
  m.body = std::move(body);
  return m;
}

void DropLog::line(const std::string& raw_source, const std::string& what, bool refused) {
  constexpr std::size_t kMaxSource = 64;
  const std::string source = raw_source.size() <= kMaxSource ? raw_source : printable(raw_source, kMaxSource);
  const std::int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  std::string line;
  {
    std::lock_guard lock(mutex_);
    if (refused) ++count_;
    // Sources are signer names taken from messages: bounded, so forged names cannot grow the map.
    Source& s = sources_.size() < 256 || sources_.count(source) != 0 ? sources_[source] : sources_["(other)"];
    if (s.last_logged != 0 && now - s.last_logged < 1'000'000'000) {
      ++s.suppressed;
      return;
    }
    if (now - second_start_ >= 1'000'000'000) {
      second_start_ = now;
      lines_this_second_ = 0;
    }
    if (lines_this_second_ >= kLinesPerSecond) {
      ++over_budget_;  // the source may speak again at its next message
      return;
    }
    ++lines_this_second_;
    line = what.size() <= kMaxLine ? what : what.substr(0, kMaxLine) + "...(cut)";
    if (s.suppressed > 0) line += " (" + std::to_string(s.suppressed) + " more from this source in the last second)";
    if (over_budget_ > 0) {
      line += " (" + std::to_string(over_budget_) + " more line(s) of every source suppressed: at most " +
              std::to_string(kLinesPerSecond) + " a second)";
      over_budget_ = 0;
    }
    s.last_logged = now;
    s.suppressed = 0;
  }
  if (log_) log_(line);
}

void DropLog::flush(std::string_view who, std::int64_t now) {
  constexpr std::int64_t kSecond = 1'000'000'000;
  std::string held;
  {
    std::lock_guard lock(mutex_);
    for (auto& [source, s] : sources_) {
      if (s.suppressed == 0 || now - s.last_logged < kSecond) continue;
      held += (held.empty() ? "" : ", ") + std::to_string(s.suppressed) + " from '" + source + "'";
      s.suppressed = 0;
    }
    if (over_budget_ > 0 && now - second_start_ >= kSecond) {
      held += (held.empty() ? "" : ", ") + std::to_string(over_budget_) + " over the budget of " +
              std::to_string(kLinesPerSecond) + " a second";
      over_budget_ = 0;
    }
  }
  if (held.empty() || !log_) return;
  if (held.size() > kMaxLine) held = held.substr(0, kMaxLine) + "...(cut)";
  log_(std::string(who) + ": lines held back by the rate limit and not said since: " + held);
}

std::uint64_t DropLog::count() const {
  std::lock_guard lock(mutex_);
  return count_;
}

std::string printable(std::string_view text, std::size_t max) {
  std::string out;
  const std::string_view shown = text.substr(0, max);
  out.reserve(shown.size() + 24);
  for (const char c : shown) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\\') {
      out += "\\\\";
    } else if (u < 0x20 || u == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xf];
    } else {
      out += c;
    }
  }
  if (shown.size() < text.size()) out += "...(+" + std::to_string(text.size() - shown.size()) + " bytes)";
  return out;
}

std::int64_t new_incarnation() noexcept {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now).count();
  return ns > 0 ? ns : 1;
}

}  // namespace safecass::middleware
