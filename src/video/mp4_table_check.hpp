#pragma once
// Bounds what an MP4's sample tables may make FFmpeg allocate, checked before FFmpeg parses them.
#include <cstdint>
#include <functional>
#include <string>

namespace panoptes::video {

/// Walks the MP4 box tree of the open file `fd` (its first `size` bytes) and throws FileError (naming
/// `path`, the box, its byte offset and the value) when a sample table promises more entries than the
/// file can hold: a `trun` whose samples carry no per-sample fields costs the file 0 bytes per sample
/// but FFmpeg ~34 bytes of index each, so 2 kB can ask for gigabytes. Every sample (trun, stsz, stz2)
/// needs at least one byte of the file, and every table with fixed-size entries (stts, ctts, stss,
/// stsc, stco, co64, elst, trun, stsz, sbgp, tfra) must fit in its box, even when the box itself is cut
/// short by its parent. Files that are not MP4 pass through.
void check_mp4_sample_tables(int fd, std::int64_t size, const std::string& path);

/// Reads n bytes at pos into buf; returns the count read (< n at the end), negative on error.
using ReadAt = std::function<std::int64_t(std::uint8_t* buf, std::size_t n, std::int64_t pos)>;
/// The same walk over a movie given by a reader (e.g. a movie stored as byte ranges of a pack).
void check_mp4_sample_tables(const ReadAt& read, std::int64_t size, const std::string& path);

}  // namespace panoptes::video
