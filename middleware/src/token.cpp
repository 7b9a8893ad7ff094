#include "safecass/middleware/token.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>

namespace safecass::middleware {

Expected<std::string> create_token_file(const std::string& path) {
  std::random_device random;  // /dev/urandom on Linux
  static constexpr char kHex[] = "0123456789abcdef";
  std::string secret;
  for (int i = 0; i < 8; ++i) {
    std::uint32_t word = random();
    for (int j = 0; j < 8; ++j) {
      secret += kHex[word & 0xf];
      word >>= 4;
    }
  }
  ::unlink(path.c_str());  // a previous token file, maybe with other permissions
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, S_IRUSR | S_IWUSR);
  if (fd < 0) return fail(ErrorCode::Io, "cannot create token file " + path + ": " + std::strerror(errno));
  const std::string line = secret + "\n";
  const bool written = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  ::fchmod(fd, S_IRUSR | S_IWUSR);
  ::close(fd);
  if (!written) return fail(ErrorCode::Io, "cannot write token file " + path);
  return secret;
}

Expected<std::string> read_token_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return fail(ErrorCode::Io, "cannot read token file " + path + ": " + std::strerror(errno));
  std::string token;
  std::getline(in, token);
  if (token.size() != 64 || token.find_first_not_of("0123456789abcdef") != std::string::npos) {
    return fail(ErrorCode::Parse, path + ": not a SAFECASS token file (expected 64 hex digits)");
  }
  return token;
}

std::string default_token_path(std::string_view coordinator) {
  const char* dir = std::getenv("XDG_RUNTIME_DIR");
  std::string base = dir != nullptr && *dir != '\0' ? dir : "/tmp";
  return base + "/safecass-" + std::string(coordinator) + "-" + std::to_string(::getpid()) + ".token";
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
