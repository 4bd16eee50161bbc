#include "render/equirect_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace panoptes::render {

int equirect_row_stride(double degrees, int width) {
  const double pixels = degrees * width / 360.0;
  int s = 2;
  while (2.0 * s <= pixels) s *= 2;
  return s;
}

int equirect_column_stride(int stride, int height, int y0, int y1, int max_stride) {
  if (stride < 1 || height < 1 || y0 < 0 || y1 > height || y0 >= y1)
    throw std::invalid_argument("equirect_column_stride: stride " + std::to_string(stride) + ", rows [" +
                                std::to_string(y0) + ", " + std::to_string(y1) + ") of " + std::to_string(height) +
                                "; expected stride >= 1 and a non-empty band inside the image");
  // The row nearest the equator (the middle row, or the band's edge on the middle's side): the
  // widest circle of the band sets its spacing.
  const double middle = 0.5 * height - 0.5;  // the centre's row coordinate
  const double y = std::clamp(middle, double(y0), double(y1 - 1));
  const double c = std::cos((0.5 - (y + 0.5) / height) * std::numbers::pi);
  int s = stride;
  while (2 * s <= max_stride && 2.0 * double(s / stride) * c <= 1.0) s *= 2;
  return s;
}

}  // namespace panoptes::render
