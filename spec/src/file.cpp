#include "safecass/spec/file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace safecass::spec {

namespace {

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

std::string size_text(std::size_t bytes) {
  if (bytes % (std::size_t{1} << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

/// Closes the descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

[[nodiscard]] Expected<std::string> read_regular_file(const std::string& path, std::size_t max_bytes) {
  const std::string what = "cannot read file '" + path + "': ";
  // O_NONBLOCK: opening a FIFO that has no writer returns at once instead of waiting for one.
  Fd file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (file.fd < 0) {
    const int e = errno;
    return fail(ErrorCode::Io, what + (e == ENOENT ? std::string("no such file") : std::string(std::strerror(e))));
  }
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) return fail(ErrorCode::Io, what + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) return fail(ErrorCode::Io, what + "not a regular file (" + kind_of(st.st_mode) + ")");
  if (st.st_size < 0 || static_cast<std::size_t>(st.st_size) > max_bytes) {
    return fail(ErrorCode::Io,
                what + "larger than " + size_text(max_bytes) + " (" + std::to_string(st.st_size) + " bytes)");
  }
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char buffer[64 * 1024];
  for (;;) {
    const ssize_t n = ::read(file.fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(ErrorCode::Io, what + std::strerror(errno));
    }
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > max_bytes) {  // it grew while being read
      return fail(ErrorCode::Io, what + "larger than " + size_text(max_bytes));
    }
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

}  // namespace safecass::spec
