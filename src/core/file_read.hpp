#pragma once
// Reading a whole input file safely: only regular files (a FIFO, a device such as /dev/zero or a
// directory is refused at once, without blocking on it) of bounded size.
#include <cstdint>
#include <string>

namespace panoptes {

/// Reads `path` into memory. Throws FileError naming the path when it cannot be opened, is not a
/// regular file (opened with O_NONBLOCK, so a FIFO does not block), is larger than `max_bytes`
/// ("<what> of N bytes is larger than the limit of M bytes"), or a read fails.
std::string read_regular_file(const std::string& path, std::uint64_t max_bytes, const std::string& what = "file");

/// Size of a regular file (same checks as read_regular_file, without reading it).
std::uint64_t regular_file_size(const std::string& path, std::uint64_t max_bytes, const std::string& what = "file");

}  // namespace panoptes
