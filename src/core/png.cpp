#include "core/png.hpp"

#include <cstring>

#include "core/error.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace panoptes {

void write_png(const std::string& path, const Image& image) {
  if (image.empty()) throw FileError(path, "cannot write an empty image as PNG");
  if (!stbi_write_png(path.c_str(), image.width, image.height, image.channels, image.pixels.data(),
                      int(image.stride())))
    throw FileError(path, "could not write PNG (directory missing or disk full?)");
}

Image read_png(const std::string& path) {
  int w = 0, h = 0, c = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &c, 4);
  if (!data) throw FileError(path, std::string("not a readable PNG: ") + stbi_failure_reason());
  Image img(w, h, 4);
  std::memcpy(img.pixels.data(), data, img.pixels.size());
  stbi_image_free(data);
  return img;
}

}  // namespace panoptes
