#include "safecass/middleware/token.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace safecass::middleware {

namespace {

constexpr std::size_t kTokenDigits = 64;
constexpr std::size_t kMaxTokenFileBytes = 4096;

std::string reason() { return std::strerror(errno); }

bool is_token_text(std::string_view text) {
  return text.size() == kTokenDigits && text.find_first_not_of("0123456789abcdef") == std::string_view::npos;
}

/// Reads at most `limit` bytes; false on a read error.
bool read_all(int fd, std::string& out, std::size_t limit) {
  char buffer[512];
  while (out.size() <= limit) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) break;
    out.append(buffer, static_cast<std::size_t>(n));
  }
  return true;
}

bool write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::write(fd, text.data(), text.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

std::string mode_text(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// Why the existing file open as `fd` is not a token file of ours; empty when it is one.
std::string not_ours(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return "cannot examine it: " + reason();
  if (!S_ISREG(st.st_mode)) return kind_of(st.st_mode);
  if (st.st_uid != ::geteuid()) return "owned by another user (uid " + std::to_string(st.st_uid) + ")";
  if ((st.st_mode & 07777) != 0600) return "mode " + mode_text(st.st_mode) + ", not 0600";
  if (st.st_size != static_cast<off_t>(kTokenDigits + 1))
    return "not a token (" + std::to_string(st.st_size) + " bytes)";
  std::string text;
  if (!read_all(fd, text, kTokenDigits + 1)) return "cannot read it: " + reason();
  if (text.size() != kTokenDigits + 1 || text.back() != '\n' ||
      !is_token_text(std::string_view(text).substr(0, kTokenDigits))) {
    return "not a token";
  }
  return {};
}

bool same_file(const struct stat& a, const struct stat& b) { return a.st_dev == b.st_dev && a.st_ino == b.st_ino; }

/// Checks that `dir` is a directory of ours that nobody else can enter (and no symbolic link).
[[nodiscard]] Expected<void> check_private_dir(const std::string& dir) {
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0) return fail(ErrorCode::Io, "token directory " + dir + ": " + reason());
  if (!S_ISDIR(st.st_mode))
    return fail(ErrorCode::Io, "token directory " + dir + " is " + kind_of(st.st_mode) + ", not a directory");
  if (st.st_uid != ::geteuid()) {
    return fail(ErrorCode::Io, "token directory " + dir + " is owned by another user (uid " +
                                   std::to_string(st.st_uid) + "): refusing to keep a token there");
  }
  if ((st.st_mode & 077) != 0) {
    return fail(ErrorCode::Io, "token directory " + dir + " has mode " + mode_text(st.st_mode) +
                                   ": others may enter it (it must be 0700): refusing to keep a token there");
  }
  return {};
}

/// The private directory for default token files: $XDG_RUNTIME_DIR/safecass (kept), or a new
/// mkdtemp directory (`made` is true: it is removed with the file).
[[nodiscard]] Expected<std::string> private_directory(bool& made) {
  made = false;
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  if (runtime != nullptr && runtime[0] == '/') {
    const std::string dir = std::string(runtime) + "/safecass";
    if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
      return fail(ErrorCode::Io, "cannot create the token directory " + dir + ": " + reason());
    }
    if (auto ok = check_private_dir(dir); !ok) return tl::unexpected(ok.error());
    return dir;
  }
  const char* tmp = std::getenv("TMPDIR");
  const std::string base = tmp != nullptr && tmp[0] == '/' ? tmp : "/tmp";
  std::string pattern = base + "/safecass-XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    return fail(ErrorCode::Io, "cannot create a private token directory in " + base + ": " + reason());
  }
  made = true;
  if (auto ok = check_private_dir(pattern); !ok) {
    ::rmdir(pattern.c_str());
    return tl::unexpected(ok.error());
  }
  return pattern;
}

std::string file_name_part(std::string_view name) {
  std::string out;
  for (const char c : name) {
    const bool plain =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
    out += plain ? c : '_';
  }
  return out.empty() || out[0] == '.' ? "_" + out : out;
}

}  // namespace

[[nodiscard]] Expected<std::string> make_token() {
  unsigned char bytes[kTokenDigits / 2];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(ErrorCode::Io, "no random source for the write token: " + reason());
    }
    got += static_cast<std::size_t>(n);
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (const unsigned char b : bytes) {
    token += kHex[b >> 4];
    token += kHex[b & 15];
  }
  return token;
}

TokenFile::TokenFile(int fd, std::string path, std::string secret, std::string private_dir)
    : fd_(fd), path_(std::move(path)), secret_(std::move(secret)), private_dir_(std::move(private_dir)) {}

TokenFile::~TokenFile() { remove(); }

void TokenFile::remove() noexcept {
  if (fd_ < 0) return;
  // Unlink only the file this process created: never one that replaced it at the same path.
  struct stat mine {};
  struct stat there {};
  if (::fstat(fd_, &mine) == 0 && ::lstat(path_.c_str(), &there) == 0 && same_file(mine, there))
    ::unlink(path_.c_str());
  ::close(fd_);  // releases the lock
  fd_ = -1;
  if (!private_dir_.empty()) ::rmdir(private_dir_.c_str());
}

Expected<std::unique_ptr<TokenFile>> TokenFile::create(const std::string& path) {
  auto secret = make_token();
  if (!secret) return tl::unexpected(secret.error());
  const std::string refuse = "token file " + path + ": ";
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd >= 0) {
      // Locked before the token is written: a file that holds a token is either held by a live
      // process or left by a dead one.
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0 || ::fchmod(fd, 0600) != 0 || !write_all(fd, *secret + "\n")) {
        const std::string why = reason();
        ::unlink(path.c_str());
        ::close(fd);
        return fail(ErrorCode::Io, "cannot write " + refuse.substr(0, refuse.size() - 2) + ": " + why);
      }
      return std::unique_ptr<TokenFile>(new TokenFile(fd, path, std::move(*secret), {}));
    }
    if (errno != EEXIST)
      return fail(ErrorCode::Io, "cannot create " + refuse.substr(0, refuse.size() - 2) + ": " + reason());
    if (attempt > 0)
      return fail(ErrorCode::Io, refuse + "created meanwhile by another process: refusing to overwrite it");

    // The path exists. Only a token file of ours that no live process holds may be replaced.
    struct stat link {};
    if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
      return fail(ErrorCode::Io, refuse + "exists and is a symbolic link: refusing to write a token through it");
    }
    const int old = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (old < 0)
      return fail(ErrorCode::Io, refuse + "exists and cannot be examined (" + reason() + "): refusing to overwrite it");
    if (const std::string why = not_ours(old); !why.empty()) {
      ::close(old);
      return fail(ErrorCode::Io, refuse + "exists and is not a SAFECASS token file of yours (" + why +
                                     "): refusing to overwrite it; remove it or choose another path");
    }
    if (::flock(old, LOCK_EX | LOCK_NB) != 0) {
      const bool held = errno == EWOULDBLOCK;
      ::close(old);
      if (held) {
        return fail(ErrorCode::Io, refuse +
                                       "is the token file of a running process (it holds the file's lock): two "
                                       "processes cannot share a token file; choose another path");
      }
      return fail(ErrorCode::Io, refuse + "cannot lock the existing file: " + reason());
    }
    // A token file left by a process that is gone: replace it, if the path still names it.
    struct stat held {};
    struct stat there {};
    const bool same = ::fstat(old, &held) == 0 && ::lstat(path.c_str(), &there) == 0 && same_file(held, there);
    if (same) ::unlink(path.c_str());
    ::close(old);
    if (!same) return fail(ErrorCode::Io, refuse + "replaced by another process meanwhile: refusing to overwrite it");
  }
  return fail(ErrorCode::Io, refuse + "cannot be created");
}

Expected<std::unique_ptr<TokenFile>> TokenFile::create_default(std::string_view name) {
  bool made = false;
  auto dir = private_directory(made);
  if (!dir) return tl::unexpected(dir.error());
  auto file = create(*dir + "/" + file_name_part(name) + "-" + std::to_string(::getpid()) + ".token");
  if (!file) {
    if (made) ::rmdir(dir->c_str());
    return file;
  }
  if (made) (*file)->private_dir_ = *dir;
  return file;
}

[[nodiscard]] Expected<std::string> read_token_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return fail(ErrorCode::Io, "cannot read token file " + path + ": " + reason());
  struct stat st {};
  std::string text;
  std::string problem;
  if (::fstat(fd, &st) != 0) {
    problem = reason();
  } else if (!S_ISREG(st.st_mode)) {
    problem = kind_of(st.st_mode) + ", not a regular file";
  } else if (st.st_size > static_cast<off_t>(kMaxTokenFileBytes) || !read_all(fd, text, kMaxTokenFileBytes)) {
    problem = st.st_size > static_cast<off_t>(kMaxTokenFileBytes) ? "larger than a token file" : reason();
  }
  ::close(fd);
  if (!problem.empty()) return fail(ErrorCode::Io, "cannot read token file " + path + ": " + problem);
  const std::string_view first = std::string_view(text).substr(0, text.find('\n'));
  if (!is_token_text(first)) {
    return fail(ErrorCode::Parse, path + ": not a SAFECASS token file (expected 64 hex digits)");
  }
  return std::string(first);
}

bool token_matches(std::string_view expected, std::string_view given) noexcept {
  if (expected.empty() || expected.size() != given.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    diff |= static_cast<unsigned char>(expected[i] ^ given[i]);
  }
  return diff == 0;
}

}  // namespace safecass::middleware
