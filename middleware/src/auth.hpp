#pragma once
// Internal: signing and checking the bus's messages (wire::Signed), see keys.hpp and
// docs/security.md. Only .cpp files of this module include it.
//
// What is signed: "safecass.bus.v1" NUL kind NUL signer NUL body, where body is the Ice encoding
// of the payload. The kind binds a body to its topic (a heartbeat cannot be replayed as a state
// update); the signer binds it to a key. Freshness (replays of genuine messages) is the
// receiver's part: incarnations only grow (a process's start time), and each stream's sequence
// numbers only grow within an incarnation.

#include <Ice/Ice.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "safecass.h"
#include "safecass/core/expected.hpp"

namespace safecass::middleware::detail {

/// Message kinds (wire::Signed::kind).
inline constexpr std::string_view kKindState = "state";
inline constexpr std::string_view kKindEvents = "events";
inline constexpr std::string_view kKindHeartbeat = "heartbeat";
inline constexpr std::string_view kKindResync = "resync";

/// The public keys of a system's signers (the keyring file).
class Keyring {
public:
  /// Errors: Io (unreadable), Parse (a malformed line, with file:line).
  [[nodiscard]] static Expected<Keyring> load(const std::string& dir);
  bool knows(std::string_view signer) const { return keys_.find(signer) != keys_.end(); }
  /// True when `signature` is `signer`'s signature of (kind, body).
  bool verify(std::string_view signer, std::string_view kind, const Ice::ByteSeq& body,
              const Ice::ByteSeq& signature) const noexcept;

private:
  std::map<std::string, std::string, std::less<>> keys_;  // name -> 32-byte public key
};

/// One signer's secret key.
class Signer {
public:
  /// Loads DIR/NAME.secret. Errors: NotFound (no key for NAME: how to create one), Denied (the
  /// file is readable by others than its owner, or owned by someone else), Parse, Io.
  [[nodiscard]] static Expected<Signer> load(const std::string& dir, std::string_view name);
  const std::string& name() const noexcept { return name_; }
  wire::Signed sign(std::string_view kind, Ice::ByteSeq body) const;

private:
  std::string name_;
  std::string secret_;  // 64-byte Ed25519 secret key
};

/// The Ice encoding of a payload.
template <class T>
Ice::ByteSeq encode(const std::shared_ptr<Ice::Communicator>& ic, const T& value) {
  Ice::OutputStream out(ic);
  out.write(value);
  Ice::ByteSeq bytes;
  out.finished(bytes);
  return bytes;
}

/// Reads a payload; false when the bytes are not exactly one T.
template <class T>
bool decode(const std::shared_ptr<Ice::Communicator>& ic, const Ice::ByteSeq& bytes, T& out) noexcept {
  try {
    Ice::InputStream in(ic, bytes);
    in.read(out);
    return in.pos() == bytes.size();
  } catch (...) {
    return false;
  }
}

/// Checks a signed message of `kind` and decodes its payload. Returns the reason it is refused
/// (empty when accepted).
template <class T>
std::string open_signed(const Keyring& keys, const std::shared_ptr<Ice::Communicator>& ic, const wire::Signed& m,
                        std::string_view kind, T& out) {
  if (m.kind != kind) return "a '" + m.kind + "' message on the " + std::string(kind) + " topic";
  if (!keys.knows(m.signer)) return "signer '" + m.signer + "' is not in the keyring";
  if (!keys.verify(m.signer, kind, m.body, m.signature)) return "bad signature (forged or corrupted)";
  if (!decode(ic, m.body, out)) return "signed body is malformed";
  return {};
}

/// Counts refused messages and logs them, at most one line per source per second (a flood of
/// forgeries must not become a flood of log lines), with the number suppressed since. Sources are
/// kept capped (printable(source, 64)) and at most 256 of them, lines at most 1,024 bytes: memory
/// and log growth stay bounded whatever arrives.
class DropLog {
public:
  explicit DropLog(std::function<void(const std::string&)> log) : log_(std::move(log)) {}
  void drop(const std::string& source, const std::string& what);
  std::uint64_t count() const;

private:
  struct Source {
    std::int64_t last_logged = 0;
    std::uint64_t suppressed = 0;
  };
  std::function<void(const std::string&)> log_;
  mutable std::mutex mutex_;
  std::map<std::string, Source, std::less<>> sources_;
  std::uint64_t count_ = 0;
};

/// The most bytes of one string from a message that printable() shows by default.
inline constexpr std::size_t kMaxPrintable = 160;
/// Escapes control characters and backslashes so that a string from a message can be printed on
/// one line (a forged or odd name cannot inject lines into a log or a terminal), and caps it: at
/// most `max` bytes of it are shown, then "...(+N bytes)" (a 128 KB name is not a 128 KB line).
std::string printable(std::string_view text, std::size_t max = kMaxPrintable);

/// The freshness rule for incarnations, shared by every receiver: a message of an incarnation older
/// than the newest seen from `who` is a replay, or a second process with that name. Returns why it
/// is refused, or empty when `seen` is not older than `newest`.
std::string older_incarnation(std::string_view what, std::string_view who, std::int64_t seen, std::int64_t newest);

/// An incarnation for a process starting now: its start time in ns since the epoch, so a
/// restart always has a larger one than any earlier run.
std::int64_t new_incarnation() noexcept;

}  // namespace safecass::middleware::detail
