#pragma once
// A file written in whole chunks, rotated at a size limit: the one place where the recorders
// (history and inputs) touch the disk.
//
// - Each chunk goes to the file in one write() loop and never straddles two segments, so a killed
//   process leaves whole chunks (records, lines) except, at most, a torn last one.
// - With a size limit, a chunk that would take the current segment past it first rotates:
//   PATH.(keep-1) -> PATH.keep, ..., PATH -> PATH.1, and a new PATH starts with the preamble (the
//   format's header). The segment pushed out past PATH.keep is deleted and counted: the disk holds
//   at most (keep + 1) segments. A chunk larger than the limit still goes whole into a fresh segment.
// - The first error (errno) is kept; after it nothing more is written.

#include <cstdint>
#include <string>
#include <string_view>

#include "safecass/core/expected.hpp"
#include "safecass/record/file_limits.hpp"

namespace safecass::detail {

class SegmentedFile {
public:
  /// Creates or truncates `path`. Errors: Io, with the reason alone (the caller names the file).
  [[nodiscard]] static Expected<SegmentedFile> open(std::string path, FileLimits options);
  SegmentedFile() = default;
  SegmentedFile(SegmentedFile&& other) noexcept;
  SegmentedFile& operator=(SegmentedFile&& other) noexcept;
  SegmentedFile(const SegmentedFile&) = delete;
  SegmentedFile& operator=(const SegmentedFile&) = delete;
  ~SegmentedFile();

  /// Bytes that start every segment after a rotation (the first one is written by the caller).
  void set_preamble(std::string preamble) { preamble_ = std::move(preamble); }
  /// Writes `chunk` whole into one segment (rotating first when needed; a new segment starts with
  /// the preamble, then `resume`: the state a reader needs to read the chunk alone). False after an
  /// error; error() says why.
  bool write(std::string_view chunk, std::string_view resume = {});
  /// Closes the file; false if close() reported an error (kept in error()).
  bool close();

  const std::string& path() const noexcept { return path_; }
  const std::string& error() const noexcept { return error_; }
  std::uint64_t bytes() const noexcept { return bytes_; }  ///< written, every segment
  std::uint64_t rotations() const noexcept { return rotations_; }
  std::uint64_t discarded() const noexcept { return discarded_; }  ///< old segments deleted

private:
  bool rotate(std::string_view resume);
  bool write_all(std::string_view data);

  int fd_ = -1;
  std::string path_;
  FileLimits options_;
  std::string preamble_;
  std::string error_;
  std::uint64_t segment_bytes_ = 0;
  std::uint64_t bytes_ = 0;
  std::uint64_t rotations_ = 0;
  std::uint64_t discarded_ = 0;
};

}  // namespace safecass::detail
