#pragma once
// Camera::ray for every pixel centre of a rectangle of the image, with its per-column and per-row
// terms computed once: the renderers' pixel loops take several rays per pixel row (marched pixels,
// located interpolated pixels, adaptive cells' entry depths), and Camera::ray spends most of its time
// on terms that depend on the column or the row alone.
#include <cmath>
#include <cstddef>
#include <vector>

#include "camera/camera.hpp"

namespace panoptes::camera {

/// The rays of pixel centres (x + 0.5, y + 0.5) over [x0, x1) × [y0, y1) of a camera's image, equal
/// to Camera::ray's bit for bit (the same expressions in the same order, pixel_rays_test.cpp checks
/// every pixel of perspective and equirectangular cameras). Camera::ray stays the definition: a
/// change there must be mirrored here, and the test fails until it is. Read-only after reset(), so
/// threads may share one.
class PixelRays {
 public:
  PixelRays() = default;
  PixelRays(const Camera& cam, int x0, int y0, int x1, int y1) { reset(cam, x0, y0, x1, y1); }
  /// Recomputes the tables for `cam` and the rectangle (reusing their capacity). Throws
  /// panoptes::Error naming the rectangle when it is not inside the image.
  void reset(const Camera& cam, int x0, int y0, int x1, int y1);

  const Vec3& origin() const { return origin_; }
  /// The unit direction of pixel (x, y) of the rectangle: Camera::ray(x + 0.5, y + 0.5).direction.
  Vec3 direction(int x, int y) const {
    const Vec3 v = unnormalized(x, y);
    if (equirect_) return v;
    const double n = length(v);
    return n > 0 ? v / n : v;
  }
  /// Component `a` of direction(x, y), the same bits, without dividing the other two.
  double direction(int x, int y, int a) const {
    const Vec3 v = unnormalized(x, y);
    if (equirect_) return v[a];
    const double n = length(v);
    return n > 0 ? v[a] / n : v[a];
  }
  Ray ray(int x, int y) const { return {origin_, direction(x, y)}; }

 private:
  // Rounds a product to double where it stands. A caller compiled with FMA (the renderer's -march=native)
  // would otherwise fuse x·x + y·y into one rounding, and Camera::ray (camera module, no FMA) rounds
  // every product: fused, the directions differ in the last bit. An empty asm costs nothing.
  static double unfused(double v) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    asm("" : "+x"(v));
#endif
    return v;
  }
  static double length(const Vec3& v) {  // norm(v) of vec3.hpp, product by product
    return std::sqrt(unfused(v.x * v.x) + unfused(v.y * v.y) + unfused(v.z * v.z));
  }
  // Perspective: (forward + right·sx) + up·sy, both terms from the tables (additions only). Equirectangular:
  // forward·(c·cos lon) + right·(c·sin lon) + up·sin lat, the last term from the table.
  Vec3 unnormalized(int x, int y) const {
    const std::size_t i = std::size_t(x - x0_), j = std::size_t(y - y0_);
    const Vec3& r = row_[j];
    if (!equirect_) return col_[i] + r;
    const double c = row_cos_[j], p = unfused(c * col_cos_[i]), q = unfused(c * col_sin_[i]);
    return {unfused(forward_.x * p) + unfused(right_.x * q) + r.x, unfused(forward_.y * p) + unfused(right_.y * q) + r.y,
            unfused(forward_.z * p) + unfused(right_.z * q) + r.z};
  }

  int x0_ = 0, y0_ = 0;
  bool equirect_ = false;
  Vec3 origin_, forward_, right_;
  // Perspective: col_ = forward + right·sx of each column, row_ = up·sy of each row. Equirectangular:
  // row_ = up·sin(lat) of each row, row_cos_ = cos(lat); col_cos_/col_sin_ = cos/sin of each column's longitude.
  std::vector<Vec3> col_, row_;
  std::vector<double> col_cos_, col_sin_, row_cos_;
};

}  // namespace panoptes::camera
