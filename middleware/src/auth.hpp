#pragma once
// Internal: authenticating and checking the bus's messages (wire::Signed), see keys.hpp and
// docs/security.md. Only .cpp files of this module include it.
//
// Two kinds of authentication, both over "context NUL kind NUL signer NUL body", where body is
// the Ice encoding of the payload (the kind binds a body to its topic, the signer to a key):
// - signed (heartbeats, proofs of life): an Ed25519 signature that anyone with the keyring can
//   check: tools follow the heartbeats and check proofs with the keyring alone;
// - sealed (state updates, event records, resync requests): one 16-byte tag per member of the
//   keyring, each a BLAKE2b keyed with the key the sender shares with that member, of one
//   BLAKE2b digest of the message. The pairwise key of two members is derived from their
//   Ed25519 keys (X25519 of one's secret and the other's public key): nothing is exchanged, and
//   only those two hold it. So a member can check that a message comes from its signer, and no
//   member can make another accept a message as coming from a third (DESIGN §7); it costs a few
//   microseconds instead of an Ed25519 verification's fifty.
// Freshness (replays of genuine messages) is the receiver's part (receiver.hpp).

#include <Ice/Ice.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ice_sequences.hpp"  // before the generated header: its sequences' reader
#include "safecass.h"
#include "safecass/core/expected.hpp"

namespace safecass::middleware {

/// Message kinds (wire::Signed::kind).
inline constexpr std::string_view kKindState = "state";
inline constexpr std::string_view kKindEvents = "events";
inline constexpr std::string_view kKindHeartbeat = "heartbeat";
inline constexpr std::string_view kKindResync = "resync";

/// The public keys of a system's members (the keyring file), in the file's name order.
class Keyring {
public:
  /// Errors: Io (unreadable), Parse (a malformed line, with file:line).
  [[nodiscard]] static Expected<Keyring> load(const std::string& dir);
  bool knows(std::string_view signer) const { return index_.find(signer) != index_.end(); }
  /// True when `signature` is `signer`'s signature of (kind, body).
  bool verify(std::string_view signer, std::string_view kind, const Ice::ByteSeq& body,
              const Ice::ByteSeq& signature) const noexcept;
  std::size_t size() const noexcept { return names_.size(); }

private:
  friend class Signer;
  std::vector<std::string> names_;  // sorted
  std::vector<std::string> keys_;   // 32-byte Ed25519 public keys, by names_' index
  std::map<std::string, std::size_t, std::less<>> index_;
};

/// One member's credential: its secret key (signatures) and the pairwise keys it shares with
/// every member of the keyring (seals).
class Signer {
public:
  /// Loads DIR/NAME.secret and derives the pairwise keys with every member of `keyring`.
  /// Errors: NotFound (no key for NAME: how to create one), Denied (the file is readable by others
  /// than its owner, or owned by someone else), Parse, Io; InvalidArgument when NAME is not in
  /// the keyring or a key of it is unusable.
  [[nodiscard]] static Expected<Signer> load(const std::string& dir, std::string_view name, const Keyring& keyring);
  const std::string& name() const noexcept { return name_; }
  /// Ed25519-signed (heartbeats, proofs of life).
  wire::Signed sign(std::string_view kind, Ice::ByteSeq body) const;
  /// Sealed: one tag per member of the keyring (state updates, event records, resync requests).
  wire::Signed seal(std::string_view kind, Ice::ByteSeq body) const;
  /// True when `m` is sealed by `m.signer` for this member: its tag here is the one computed with
  /// the key this member shares with the signer.
  bool opens(const wire::Signed& m) const noexcept;
  /// The digest a sealed message's tags authenticate: what a heartbeat lists (Heartbeat::sentEvents)
  /// to vouch for a batch to the readers that hold only the keyring.
  static Ice::ByteSeq digest_of(const wire::Signed& m);

private:
  std::string name_;
  std::string secret_;                                       // 64-byte Ed25519 secret key
  std::size_t index_ = 0;                                    // this member's place in the keyring
  std::map<std::string, std::size_t, std::less<>> members_;  // the keyring's names -> place
  std::vector<std::string> pair_;  // 32-byte keys shared with each member, by place (own: empty)
};

/// The most bytes of one string from a message that printable() shows by default.
inline constexpr std::size_t kMaxPrintable = 160;
/// Escapes control characters and backslashes so that a string from a message can be printed on
/// one line (a forged or odd name cannot inject lines into a log or a terminal), and caps it: at
/// most `max` bytes of it are shown, then "...(+N bytes)" (a 128 KB name is not a 128 KB line).
std::string printable(std::string_view text, std::size_t max = kMaxPrintable);

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

/// Checks a signed message of `kind` (heartbeats, proofs) and decodes its payload. Returns the
/// reason it is refused (empty when accepted).
template <class T>
std::string open_signed(const Keyring& keys, const std::shared_ptr<Ice::Communicator>& ic, const wire::Signed& m,
                        std::string_view kind, T& out) {
  if (m.kind != kind) return "a '" + printable(m.kind) + "' message on the " + std::string(kind) + " topic";
  if (!keys.knows(m.signer)) return "signer '" + printable(m.signer) + "' is not in the keyring";
  if (!keys.verify(m.signer, kind, m.body, m.signature)) return "bad signature (forged or corrupted)";
  if (!decode(ic, m.body, out)) return "signed body is malformed";
  return {};
}

/// Checks a sealed message of `kind` (state updates, records, resync requests) for member `me`
/// and decodes its payload. Returns the reason it is refused (empty when accepted).
template <class T>
std::string open_sealed(const Signer& me, const std::shared_ptr<Ice::Communicator>& ic, const wire::Signed& m,
                        std::string_view kind, T& out) {
  if (m.kind != kind) return "a '" + printable(m.kind) + "' message on the " + std::string(kind) + " topic";
  if (!me.opens(m)) return "bad seal (forged, corrupted, or from outside the keyring)";
  if (!decode(ic, m.body, out)) return "sealed body is malformed";
  return {};
}

/// Counts refused messages and logs them, and every line that what arrives can repeat: at most
/// one line per source per second (a flood of forgeries must not become a flood of log lines),
/// with the number suppressed since, and at most kLinesPerSecond lines a second in all, whatever
/// the number of sources (the next line says how many were suppressed meanwhile). Sources are
/// kept capped (printable(source, 64)) and at most 256 of them, lines at most 1,024 bytes: memory
/// stays bounded, and the log grows by at most kLinesPerSecond lines of 1,024 bytes (and their
/// counts) a second, whatever arrives. What the limit held back and no later line of its source
/// said is said by flush(), once its second is over: no count is lost when a source falls silent.
class DropLog {
public:
  static constexpr std::uint64_t kLinesPerSecond = 8;
  static constexpr std::size_t kMaxLine = 1024;  ///< bytes of a line's text, cut beyond
  explicit DropLog(std::function<void(const std::string&)> log) : log_(std::move(log)) {}
  /// A refused message: counted (count()) and logged, rate-limited.
  void drop(const std::string& source, const std::string& what) { line(source, what, true); }
  /// A line something from outside can make repeat (not a refusal): logged, rate-limited.
  void note(const std::string& source, const std::string& what) { line(source, what, false); }
  std::uint64_t count() const;
  /// At `now` (steady ns), one line from `who` with the lines held back more than a second ago
  /// and not said since (each source's count, and those over the total budget); none if none.
  /// Called by a receiver's watch loop.
  void flush(std::string_view who, std::int64_t now);

private:
  void line(const std::string& source, const std::string& what, bool refused);
  struct Source {
    std::int64_t last_logged = 0;
    std::uint64_t suppressed = 0;
  };
  std::function<void(const std::string&)> log_;
  mutable std::mutex mutex_;
  std::map<std::string, Source, std::less<>> sources_;
  std::uint64_t count_ = 0;
  std::int64_t second_start_ = 0;        ///< the start of the current second of the total budget
  std::uint64_t lines_this_second_ = 0;  ///< lines logged since second_start_
  std::uint64_t over_budget_ = 0;        ///< lines suppressed by the total budget, not said yet
};

/// An incarnation for a process starting now: its start time in ns since the epoch, so a
/// restart always has a larger one than any earlier run.
std::int64_t new_incarnation() noexcept;

}  // namespace safecass::middleware
