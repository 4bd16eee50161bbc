#pragma once
// PNG and JPEG files through stb (screenshots, headless frames, Cinema image databases, test artefacts).
#include <string>

#include "core/image.hpp"

namespace panoptes {

/// Writes an RGB or RGBA image as PNG; throws FileError when the file cannot be written.
void write_png(const std::string& path, const Image& image);
/// Reads a PNG as RGBA; throws FileError when the file is missing or not a PNG.
Image read_png(const std::string& path);
/// Writes an RGB or RGBA image as baseline JPEG (alpha dropped), quality 1..100; throws FileError when
/// the file cannot be written.
void write_jpg(const std::string& path, const Image& image, int quality = 95);
/// Reads a PNG or JPEG (by content, not by name) as RGBA; throws FileError when the file is missing or
/// neither.
Image read_image(const std::string& path);
/// Width and height of a PNG or JPEG from its header (no decoding); throws FileError like read_image.
void image_file_size(const std::string& path, int& width, int& height);

}  // namespace panoptes
