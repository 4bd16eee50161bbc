#include "camera/pixel_rays.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::camera;

namespace {
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every pixel of [x0, x1) × [y0, y1): PixelRays' ray and its single components against Camera::ray.
void expect_identical(const Camera& cam, int x0, int y0, int x1, int y1) {
  const PixelRays rays(cam, x0, y0, x1, y1);
  int mismatches = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const Ray want = cam.ray(x + 0.5, y + 0.5);
      const Ray got = rays.ray(x, y);
      for (int a = 0; a < 3; ++a) {
        const bool ok = same_bits(got.origin[a], want.origin[a]) && same_bits(got.direction[a], want.direction[a]) &&
                        same_bits(rays.direction(x, y, a), want.direction[a]);
        if (!ok && ++mismatches <= 5)
          ADD_FAILURE() << "pixel (" << x << ", " << y << ") axis " << a << ": " << got.direction[a] << " / "
                        << rays.direction(x, y, a) << " vs Camera::ray " << want.direction[a];
      }
    }
  EXPECT_EQ(mismatches, 0);
}
}  // namespace

TEST(PixelRays, PerspectiveRaysAreCameraRaysBitForBit) {
  // The demo's image size, an oblique camera, a narrow and a wide field of view, odd sizes.
  expect_identical(Camera({3, -7, 5}, {0.5, 0.2, -0.1}, {0, 0, 1}, 40, 528, 512), 0, 0, 528, 512);
  expect_identical(Camera({-12800, 90000, -30000}, {12800, 25600, 8000}, {0, 0, -1}, 30, 920, 896), 0, 0, 920, 896);
  expect_identical(Camera({0, 0, 10}, {0, 0, 0}, {0, 0, 1}, 150, 33, 17), 0, 0, 33, 17);  // up falls back
  // A sub-rectangle, as render_brick takes for a brick's footprint.
  expect_identical(Camera({1, 2, 3}, {4, -5, 6}, {0, 1, 0}, 60, 300, 200), 37, 11, 251, 190);
}

TEST(PixelRays, EquirectangularRaysAreCameraRaysBitForBit) {
  expect_identical(Camera({1, 2, 3}, {1, 12, 3}, {0, 0, 1}, 45, 360, 180, Projection::equirectangular), 0, 0, 360, 180);
  expect_identical(Camera({-4, 0.5, 9}, {2, 2, 2}, {0, 0, -1}, 45, 528, 512, Projection::equirectangular), 5, 7, 400, 300);
}

TEST(PixelRays, ResetReusesTheObjectForAnotherCamera) {
  PixelRays rays(Camera({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 45, 64, 48, Projection::equirectangular), 0, 0, 64, 48);
  const Camera cam({3, -7, 5}, {0.5, 0.2, -0.1}, {0, 0, 1}, 40, 64, 48);
  rays.reset(cam, 0, 0, 64, 48);
  const Ray want = cam.ray(10.5, 20.5), got = rays.ray(10, 20);
  EXPECT_TRUE(got.direction == want.direction && got.origin == want.origin);
}

TEST(PixelRays, RejectsARectangleOutsideTheImage) {
  const Camera cam({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 45, 64, 48);
  EXPECT_THROW(PixelRays(cam, -1, 0, 10, 10), Error);
  EXPECT_THROW(PixelRays(cam, 0, 0, 65, 10), Error);
  EXPECT_THROW(PixelRays(cam, 5, 0, 4, 10), Error);
  EXPECT_NO_THROW(PixelRays(cam, 64, 48, 64, 48));  // empty
}
