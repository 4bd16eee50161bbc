// Test helper for cli.demo_colours: counts the coloured pixels of PNG frames and how many of them are
// orange (p-waves: red above green) or green (s-waves: green at least red). Grey (the domain outline,
// unsaturated) and dark (background) pixels are not coloured. Prints one line:
//   coloured N orange N green N orange_share F
#include <cstdio>
#include <algorithm>
#include <cstdint>
#include <exception>

#include "core/png.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: png_colour_share FRAME.png...\n");
    return 2;
  }
  long long coloured = 0, orange = 0, green = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      const panoptes::Image img = panoptes::read_png(argv[i]);
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
          const std::uint8_t* p = img.at(x, y);
          const int r = p[0], g = p[1], b = p[2];
          const int hi = std::max({r, g, b}), lo = std::min({r, g, b});
          if (hi < 40 || hi - lo < 25) continue;
          ++coloured;
          (r > g ? orange : green) += 1;
        }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "png_colour_share: %s\n", e.what());
    return 1;
  }
  std::printf("coloured %lld orange %lld green %lld orange_share %.4f\n", coloured, orange, green,
              coloured ? double(orange) / double(coloured) : 0.0);
  return 0;
}
