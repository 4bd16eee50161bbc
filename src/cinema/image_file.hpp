#pragma once
// The images of a Cinema database, read as hostile input: opened inside their directory without
// following links (FIFOs and devices refused, size bounded), the size checked from the header before
// any pixel is decoded, PNG decoded by Debian's libpng and JPEG by Debian's libjpeg-turbo. (stb_image,
// which the rest of Panoptes uses for its own files, is not used here: Debian's copy lacks the JPEG
// Huffman-table bound check of upstream stb issues #1289/#1291, and a crafted JPEG writes out of
// bounds.)
#include <cstdint>
#include <filesystem>

#include "core/image.hpp"

namespace panoptes::cinema {

/// Largest image file read (bytes).
inline constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t(256) << 20;

/// Width and height of a PNG or JPEG image, from its header. Throws FileError naming the file when it
/// is not a regular file, not a PNG or JPEG, malformed, or larger than a Panoptes database allows.
void image_size(const std::filesystem::path& path, int& width, int& height);

/// Decodes a PNG or JPEG (by content) as RGBA; rotate180 turns it by 180 degrees. Throws FileError like
/// image_size, or on corrupt data.
Image decode_image(const std::filesystem::path& path, bool rotate180 = false);

/// Decodes PNG or JPEG bytes in memory (the fuzz target's entry). `source` names them in messages.
Image decode_image_bytes(const std::uint8_t* data, std::size_t size, const std::string& source);

}  // namespace panoptes::cinema
