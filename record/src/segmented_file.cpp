#include "segmented_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace safecass::detail {

Expected<SegmentedFile> SegmentedFile::open(std::string path, FileLimits options) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return fail(ErrorCode::Io, std::strerror(errno));  // the caller names the file
  SegmentedFile f;
  f.fd_ = fd;
  f.path_ = std::move(path);
  f.options_ = options;
  return f;
}

SegmentedFile::SegmentedFile(SegmentedFile&& o) noexcept { *this = std::move(o); }

SegmentedFile& SegmentedFile::operator=(SegmentedFile&& o) noexcept {
  if (this != &o) {
    close();
    fd_ = std::exchange(o.fd_, -1);
    path_ = std::move(o.path_);
    options_ = o.options_;
    preamble_ = std::move(o.preamble_);
    error_ = std::move(o.error_);
    segment_bytes_ = o.segment_bytes_;
    bytes_ = o.bytes_;
    rotations_ = o.rotations_;
    discarded_ = o.discarded_;
  }
  return *this;
}

SegmentedFile::~SegmentedFile() { close(); }

bool SegmentedFile::write_all(std::string_view data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd_, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      error_ = std::strerror(errno);
      return false;
    }
    if (n == 0) {
      error_ = std::strerror(EIO);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  segment_bytes_ += data.size();
  bytes_ += data.size();
  return true;
}

bool SegmentedFile::rotate(std::string_view resume) {
  if (::close(fd_) != 0) {
    fd_ = -1;
    error_ = std::strerror(errno);
    return false;
  }
  fd_ = -1;
  const auto numbered = [this](unsigned i) { return path_ + "." + std::to_string(i); };
  struct stat st {};
  if (options_.keep == 0) {
    ++discarded_;
  } else {
    if (::stat(numbered(options_.keep).c_str(), &st) == 0) ++discarded_;
    for (unsigned i = options_.keep; i > 1; --i) (void)std::rename(numbered(i - 1).c_str(), numbered(i).c_str());
    if (std::rename(path_.c_str(), numbered(1).c_str()) != 0) {
      error_ = std::string("cannot rotate: ") + std::strerror(errno);
      return false;
    }
  }
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    error_ = std::strerror(errno);
    return false;
  }
  ++rotations_;
  segment_bytes_ = 0;
  return write_all(preamble_) && write_all(resume);
}

bool SegmentedFile::write(std::string_view chunk, std::string_view resume) {
  if (fd_ < 0 || !error_.empty()) return false;
  if (options_.max_bytes != 0 && segment_bytes_ > preamble_.size() &&
      segment_bytes_ + chunk.size() > options_.max_bytes && !rotate(resume)) {
    return false;
  }
  return write_all(chunk);
}

bool SegmentedFile::close() {
  if (fd_ < 0) return error_.empty();
  const bool ok = ::close(fd_) == 0;
  const int error = errno;
  fd_ = -1;
  if (!ok && error_.empty()) error_ = std::strerror(error);
  return ok;
}

}  // namespace safecass::detail
