#include "ui/drag_rotation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace panoptes::ui {
namespace {

// Camera on +z looking at the origin with up +y: screen right is +x.
TEST(DragRotation, DragRightOrbitsTheViewpointLeft) {
  DragRotation d;
  d.begin({0, 0, 3}, {0, 1, 0}, {0, 0, 0});
  EXPECT_NEAR(d.direction().z, 1, 1e-12);
  d.move(50, 0, 900);  // 50 px of a 900 px viewport = 10 degrees
  EXPECT_NEAR(d.direction().x, -std::sin(10 * M_PI / 180), 1e-12);
  EXPECT_NEAR(d.direction().z, std::cos(10 * M_PI / 180), 1e-12);
  EXPECT_NEAR(d.up().y, 1, 1e-12);
}

TEST(DragRotation, DragDownRaisesTheViewpoint) {
  DragRotation d;
  d.begin({0, 0, 3}, {0, 1, 0}, {0, 0, 0});
  d.move(0, 90, 900);  // 18 degrees
  EXPECT_NEAR(d.direction().y, std::sin(18 * M_PI / 180), 1e-12);
  EXPECT_NEAR(d.direction().z, std::cos(18 * M_PI / 180), 1e-12);
  EXPECT_NEAR(dot(d.direction(), d.up()), 0, 1e-12);
  EXPECT_NEAR(norm(d.up()), 1, 1e-12);
}

TEST(DragRotation, FullWindowHeightIsHalfATurnAndOffCentreRigsWork) {
  DragRotation d;
  d.begin({10, 0, 0}, {0, 0, 1}, {5, 0, 0});  // centre not at the origin
  for (int i = 0; i < 100; ++i) d.move(6, 0, 600);  // 600 px in small steps = 180 degrees
  EXPECT_NEAR(d.direction().x, -1, 1e-9);
}

TEST(DragRotation, DegenerateUpIsRepaired) {
  DragRotation d;
  d.begin({0, 0, 2}, {0, 0, 1}, {0, 0, 0});  // up parallel to the view direction
  EXPECT_NEAR(dot(d.direction(), d.up()), 0, 1e-12);
  EXPECT_NEAR(norm(d.up()), 1, 1e-12);
}

}  // namespace
}  // namespace panoptes::ui
