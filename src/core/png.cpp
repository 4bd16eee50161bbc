#include "core/png.hpp"

#include <cstring>
#include <string>
#include <vector>

#include "core/error.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace panoptes {

void write_png(const std::string& path, const Image& image) {
  if (image.empty()) throw FileError(path, "cannot write an empty image as PNG");
  if (!stbi_write_png(path.c_str(), image.width, image.height, image.channels, image.pixels.data(),
                      int(image.stride())))
    throw FileError(path, "could not write PNG (directory missing or disk full?)");
}

void write_jpg(const std::string& path, const Image& image, int quality) {
  if (image.empty()) throw FileError(path, "cannot write an empty image as JPEG");
  if (quality < 1 || quality > 100)
    throw FileError(path, "JPEG quality " + std::to_string(quality) + "; expected 1..100");
  // stb writes the first three channels of RGBA as RGB only through a 3-channel buffer.
  std::vector<std::uint8_t> rgb;
  const std::uint8_t* data = image.pixels.data();
  if (image.channels == 4) {
    rgb.resize(std::size_t(image.width) * image.height * 3);
    for (std::size_t i = 0, n = std::size_t(image.width) * image.height; i < n; ++i)
      std::memcpy(&rgb[3 * i], &image.pixels[4 * i], 3);
    data = rgb.data();
  }
  if (!stbi_write_jpg(path.c_str(), image.width, image.height, image.channels == 4 ? 3 : image.channels, data, quality))
    throw FileError(path, "could not write JPEG (directory missing or disk full?)");
}

Image read_image(const std::string& path) {
  int w = 0, h = 0, c = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &c, 4);
  if (!data) throw FileError(path, std::string("not a readable PNG or JPEG image: ") + stbi_failure_reason());
  Image img(w, h, 4);
  std::memcpy(img.pixels.data(), data, img.pixels.size());
  stbi_image_free(data);
  return img;
}

void image_file_size(const std::string& path, int& width, int& height) {
  int c = 0;
  if (!stbi_info(path.c_str(), &width, &height, &c))
    throw FileError(path, std::string("not a readable PNG or JPEG image: ") + stbi_failure_reason());
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
