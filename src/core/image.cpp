#include "core/image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace panoptes {

double psnr(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw Error("psnr: image sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                std::to_string(b.width) + "x" + std::to_string(b.height));
  const int c = std::min({a.channels, b.channels, 3});
  double sum = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const auto* pa = a.at(x, y);
      const auto* pb = b.at(x, y);
      for (int k = 0; k < c; ++k) {
        const double d = double(pa[k]) - double(pb[k]);
        sum += d * d;
      }
    }
  const double mse = sum / (double(a.width) * a.height * c);
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace panoptes
