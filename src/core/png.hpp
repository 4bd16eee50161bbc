#pragma once
// PNG files through stb (screenshots, headless frames, test artefacts).
#include <string>

#include "core/image.hpp"

namespace panoptes {

/// Writes an RGB or RGBA image as PNG; throws FileError when the file cannot be written.
void write_png(const std::string& path, const Image& image);
/// Reads a PNG as RGBA; throws FileError when the file is missing or not a PNG.
Image read_png(const std::string& path);

}  // namespace panoptes
