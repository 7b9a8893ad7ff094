#pragma once
/// @file file.hpp
/// Reading a file that a person named (a system, a scenario, a `filter dinload` sample file, a
/// console script, a recorded history): regular files only, with a size limit, never blocking.
///
/// A FIFO, a device such as /dev/zero, a directory or a socket is refused before a byte is read
/// (the file is opened with O_NONBLOCK and examined with fstat, so opening a FIFO without a writer
/// does not hang and reading a device does not run forever); a file larger than the limit is
/// refused from its size, and one that grows past the limit while it is read is refused too.

#include <cstddef>
#include <string>

#include "safecass/core/expected.hpp"

namespace safecass::spec {

/// The limit for scenarios, sample files, console scripts and histories: 64 MiB. (System and
/// component files have their own, smaller limit: 16 MiB, docs/spec-format.md.)
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{64} << 20;

/// The whole content of `path` when it is a regular file (symbolic links are followed) of at most
/// `max_bytes` bytes. Errors (Io), each "cannot read file 'PATH': why": "no such file", the
/// system's reason ("Permission denied"), "not a regular file (a directory|a FIFO|a character
/// device|a block device|a socket)", "larger than 64 MiB (N bytes)". Thread-safe.
[[nodiscard]] Expected<std::string> read_regular_file(const std::string& path,
                                                      std::size_t max_bytes = kMaxInputFileBytes);

}  // namespace safecass::spec
