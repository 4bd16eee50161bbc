#include "camera/pixel_rays.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace panoptes::camera {

void PixelRays::reset(const Camera& cam, int x0, int y0, int x1, int y1) {
  const int w = cam.width_, h = cam.height_;
  if (x0 < 0 || y0 < 0 || x1 < x0 || y1 < y0 || x1 > w || y1 > h)
    throw Error("pixel rays: rectangle [" + std::to_string(x0) + ", " + std::to_string(x1) + ") x [" +
                std::to_string(y0) + ", " + std::to_string(y1) + "); expected one inside the " + std::to_string(w) +
                "x" + std::to_string(h) + " image");
  x0_ = x0, y0_ = y0;
  equirect_ = cam.projection_ == Projection::equirectangular;
  origin_ = cam.position_, forward_ = cam.forward_, right_ = cam.right_;
  const Vec3 up = cam.up_;
  const std::size_t nx = std::size_t(x1 - x0), ny = std::size_t(y1 - y0);
  col_.resize(equirect_ ? 0 : nx);
  row_.resize(ny);
  col_cos_.resize(equirect_ ? nx : 0);
  col_sin_.resize(equirect_ ? nx : 0);
  row_cos_.resize(equirect_ ? ny : 0);
  // Camera::ray's expressions, term by term (px = x + 0.5, py = y + 0.5), compiled as camera.cpp is.
  if (equirect_) {
    for (int x = x0; x < x1; ++x) {
      const double px = x + 0.5;
      const double lon = (2.0 * px / w - 1.0) * std::numbers::pi;
      col_cos_[std::size_t(x - x0)] = std::cos(lon);
      col_sin_[std::size_t(x - x0)] = std::sin(lon);
    }
    for (int y = y0; y < y1; ++y) {
      const double py = y + 0.5;
      const double lat = (0.5 - py / h) * std::numbers::pi;
      row_cos_[std::size_t(y - y0)] = std::cos(lat);
      row_[std::size_t(y - y0)] = up * std::sin(lat);
    }
    return;
  }
  const double aspect = double(w) / h;
  for (int x = x0; x < x1; ++x) {
    const double px = x + 0.5;
    const double sx = (2.0 * px / w - 1.0) * cam.tan_half_ * aspect;
    col_[std::size_t(x - x0)] = forward_ + right_ * sx;
  }
  for (int y = y0; y < y1; ++y) {
    const double py = y + 0.5;
    const double sy = (1.0 - 2.0 * py / h) * cam.tan_half_;
    row_[std::size_t(y - y0)] = up * sy;
  }
}

}  // namespace panoptes::camera
