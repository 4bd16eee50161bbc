#pragma once
// The camera table sidecar (schema 2): the per-camera part of a manifest — position, look_at, up,
// fov, labels and the navigation graph — in a compact little-endian binary columnar file next to
// panoptes.json, so that a database of 10^5–10^6 cameras opens in milliseconds (JSON parsing of one
// row per camera took 1.3 s at 10^5 cameras). Layout: docs/formats.md, "Camera table".
//
// The file name is content-addressed ("cameras.<crc32 hex>.bin"): a rewrite with other cameras writes
// a new file before the manifest that names it is renamed into place, so a crash between the two
// leaves the old manifest with its old, intact table.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "store/manifest.hpp"

namespace panoptes::store {

/// Magic bytes at the start of a camera table file.
inline constexpr std::string_view kCameraTableMagic{"PNPTCAMS", 8};
/// Binary layout version this build writes and reads.
inline constexpr std::uint32_t kCameraTableVersion = 1;

/// Largest camera table a reader loads (kMaxCameras rows of every column fit in a quarter of it).
inline constexpr std::uint64_t kMaxCameraTableBytes = std::uint64_t(1) << 30;

/// CRC-32 (ISO-HDLC / zlib polynomial 0xEDB88320, reflected, init and final xor 0xFFFFFFFF) of
/// `size` bytes, continuing from `crc` (0 to start). crc32("123456789") = 0xCBF43926.
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

/// Serializes manifest.cameras and manifest.graph to the binary table (whole file contents).
std::string encode_camera_table(const Manifest& manifest);

/// Parses a table file's contents into manifest.cameras and manifest.graph (replacing them), checking
/// magic, version, sizes, checksum, column layout, values (finite, fov in (0,180), position ≠ look_at,
/// patch indices) and neighbour ranges. `expected` is what the manifest recorded (count, size, crc).
/// Throws FileError naming `source`, the field and the value.
void decode_camera_table(std::string_view bytes, const CameraTableRef& expected, const std::string& source,
                         Manifest& manifest);

/// The content-addressed file name of a table whose checksum is crc, e.g. "cameras.1a2b3c4d.bin".
std::string camera_table_file_name(std::uint32_t crc);
/// Checks a table file name from a manifest: a plain name "cameras*.bin" of letters, digits, '.', '_'
/// and '-' (no directory part). Throws Error with the reason.
void validate_camera_table_name(const std::string& name);

/// Writes the table of `manifest` into `dir` atomically (temp file, fsync, rename); returns its
/// reference for the manifest. Throws FileError on failure (nothing is replaced then).
CameraTableRef write_camera_table(const std::filesystem::path& dir, const Manifest& manifest);

/// Reads `dir / ref.file` (one read) and decodes it into manifest.cameras / manifest.graph. Refuses a
/// link that resolves outside `dir`. Throws FileError naming the table file.
void read_camera_table(const std::filesystem::path& dir, const CameraTableRef& ref, Manifest& manifest);

}  // namespace panoptes::store
