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

TEST(Equirectangular, RaysAndProjectionAgreeAndCoverTheSphere) {
  const Camera cam({1, 2, 3}, {1, 12, 3}, {0, 0, 1}, 45, 360, 180, Projection::equirectangular);
  // The centre column looks forward, the right quarter to the right, the top row up, the edges behind.
  EXPECT_NEAR(cam.ray(180, 90).direction.y, 1, 1e-12);
  EXPECT_NEAR(cam.ray(270, 90).direction.x, 1, 1e-12);
  EXPECT_NEAR(cam.ray(90, 90).direction.x, -1, 1e-12);
  EXPECT_NEAR(cam.ray(0, 90).direction.y, -1, 1e-12);
  EXPECT_NEAR(cam.ray(123, 0).direction.z, 1, 1e-12);
  for (double px : {0.5, 17.25, 180.0, 300.5, 359.5})
    for (double py : {0.5, 45.0, 90.5, 179.5}) {
      const Ray r = cam.ray(px, py);
      EXPECT_NEAR(norm(r.direction), 1, 1e-12);
      double qx = 0, qy = 0;
      ASSERT_TRUE(cam.project(r.origin + r.direction * 7.5, qx, qy));
      EXPECT_NEAR(qx, px, 1e-9);
      EXPECT_NEAR(qy, py, 1e-9);
    }
  double qx, qy;
  EXPECT_FALSE(cam.project({1, 2, 3}, qx, qy));
  EXPECT_EQ(parse_projection("equirectangular"), Projection::equirectangular);
  EXPECT_EQ(to_string(Projection::perspective), "perspective");
  EXPECT_THROW(parse_projection("fisheye"), Error);
}
