#include "core/vec3.hpp"

#include <gtest/gtest.h>

#include <numbers>

using namespace panoptes;

TEST(Vec3, CrossFollowsRightHandRule) {
  EXPECT_EQ(cross(Vec3(1, 0, 0), Vec3(0, 1, 0)), Vec3(0, 0, 1));
}

TEST(Vec3, AngleBetweenIsAccurateForTinyAngles) {
  EXPECT_NEAR(angle_between(Vec3(1, 0, 0), Vec3(1, 1e-9, 0)), 1e-9, 1e-18);
  EXPECT_NEAR(angle_between(Vec3(1, 0, 0), Vec3(-1, 0, 0)), std::numbers::pi, 1e-15);
}
