#include "camera/camera.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::camera;

TEST(Camera, CentreRayPointsAtLookAt) {
  Camera c({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 60, 64, 48);
  const Ray r = c.ray(32, 24);
  EXPECT_NEAR(r.direction.z, -1, 1e-12);
}

TEST(Camera, ProjectInvertsRay) {
  Camera c({3, -7, 5}, {0.5, 0.2, -0.1}, {0, 0, 1}, 40, 920, 896);
  for (double px : {0.5, 100.25, 919.5})
    for (double py : {0.5, 447.0, 895.5}) {
      const Ray r = c.ray(px, py);
      double qx, qy;
      ASSERT_TRUE(c.project(r.origin + r.direction * 4.2, qx, qy));
      EXPECT_NEAR(qx, px, 1e-9);
      EXPECT_NEAR(qy, py, 1e-9);
    }
}

TEST(Camera, UpParallelToViewFallsBackDeterministically) {
  Camera c({0, 0, 10}, {0, 0, 0}, {0, 0, 1}, 45, 16, 16);
  EXPECT_NEAR(dot(c.right(), c.forward()), 0, 1e-12);
  EXPECT_NEAR(norm(c.up()), 1, 1e-12);
}

TEST(Camera, RejectsBadParameters) {
  EXPECT_THROW(Camera({0, 0, 0}, {0, 0, 0}, {0, 0, 1}, 45, 16, 16), Error);
  EXPECT_THROW(Camera({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 180, 16, 16), Error);
  EXPECT_THROW(Camera({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 45, 0, 16), Error);
}
