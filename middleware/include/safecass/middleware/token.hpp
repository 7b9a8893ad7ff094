#pragma once
/// @file token.hpp
/// The write token (DESIGN §7 "nothing let in"), shared by every process that serves writes (a
/// coordinator started with --allow-write, the viewer) and every tool that sends them.
///
/// A token is 32 bytes from the operating system's random source (getrandom), written as 64 hex
/// digits. The process that serves writes keeps it in a token file readable by its owner alone;
/// a tool that wants to inject, generate, broadcast or reset reads that file and sends the token
/// with the request, which the server compares in constant time.
///
/// Token files are created, never overwritten (TokenFile::create):
/// - a new file is created with O_CREAT|O_EXCL|O_NOFOLLOW and mode 0600, then locked (flock) for
///   the life of the process, then the token is written;
/// - an existing path is refused, with one exception: a token file of ours that no live process
///   holds (a regular file owned by this user, mode 0600, holding exactly a token and a newline,
///   whose lock nobody holds: its process was killed). That one is replaced. A token file held by
///   a running process is refused, so two processes given one path never overwrite each other;
/// - a symbolic link, or any other file (important.json), is never written over or removed.
/// The default place (TokenFile::create_default) is a private directory: $XDG_RUNTIME_DIR/safecass
/// (created mode 0700), or without XDG_RUNTIME_DIR a new directory made by mkdtemp under $TMPDIR or
/// /tmp (mode 0700, removed with the file); its owner and mode are checked before it is used.

#include <memory>
#include <string>
#include <string_view>

#include "safecass/core/expected.hpp"

namespace safecass::middleware {

/// A new secret: 32 random bytes (getrandom) as 64 lowercase hex digits. Errors: Io when the
/// system has no random source.
[[nodiscard]] Expected<std::string> make_token();

/// A token file created by this process and held (locked) until it is removed.
///
/// Lifecycle: create() or create_default() → the file exists, mode 0600, locked, holding secret()
/// → remove() or the destructor: the file is unlinked if it is still the one created (and the
/// mkdtemp directory with it), and the lock is released. Not copyable; not thread-safe.
class TokenFile {
public:
  /// Creates a token file at `path` with a new secret (the rules in this file's comment).
  /// Errors: Io, with the path and the reason: the path exists and is not a token file of ours
  /// (what it is), the token file of a running process, a symbolic link, a missing directory.
  [[nodiscard]] static Expected<std::unique_ptr<TokenFile>> create(const std::string& path);
  /// create() at the default place: "<private directory>/<name>-<pid>.token" (`name`: the
  /// coordinator's name, or "viewer"). Errors: Io (no usable private directory, with the reason).
  [[nodiscard]] static Expected<std::unique_ptr<TokenFile>> create_default(std::string_view name);

  ~TokenFile();
  TokenFile(const TokenFile&) = delete;
  TokenFile& operator=(const TokenFile&) = delete;

  const std::string& path() const noexcept { return path_; }
  const std::string& secret() const noexcept { return secret_; }
  /// Unlinks the file (only if the path still names the file created) and releases the lock.
  /// Idempotent.
  void remove() noexcept;

private:
  TokenFile(int fd, std::string path, std::string secret, std::string private_dir);
  int fd_;
  std::string path_;
  std::string secret_;
  std::string private_dir_;  ///< a directory made by mkdtemp for this file, removed with it
};

/// Reads a token file (a regular file of at most 4 KiB whose first line is 64 hex digits; a FIFO
/// or device is refused without blocking). Errors: Io (with the path and the reason), Parse (not
/// a token).
[[nodiscard]] Expected<std::string> read_token_file(const std::string& path);

/// Compares in time independent of where the strings differ. An empty `expected` (no token
/// configured) matches nothing.
bool token_matches(std::string_view expected, std::string_view given) noexcept;

}  // namespace safecass::middleware
