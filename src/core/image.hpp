#pragma once
// 8-bit interleaved images: the currency between renderer, video and player.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace panoptes {

/// An 8-bit image with `channels` interleaved channels (3 = RGB, 4 = RGBA), rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 4;
  std::vector<std::uint8_t> pixels;

  Image() = default;
  Image(int w, int h, int c = 4) : width(w), height(h), channels(c), pixels(std::size_t(w) * h * c, 0) {}

  std::size_t stride() const { return std::size_t(width) * channels; }
  std::uint8_t* row(int y) { return pixels.data() + std::size_t(y) * stride(); }
  const std::uint8_t* row(int y) const { return pixels.data() + std::size_t(y) * stride(); }
  std::uint8_t* at(int x, int y) { return row(y) + std::size_t(x) * channels; }
  const std::uint8_t* at(int x, int y) const { return row(y) + std::size_t(x) * channels; }
  bool empty() const { return width == 0 || height == 0; }
};

/// Peak signal-to-noise ratio in dB over the first min(a.channels, b.channels, 3) channels.
/// Identical images give +infinity. Sizes must match (panoptes::Error otherwise).
double psnr(const Image& a, const Image& b);

}  // namespace panoptes
