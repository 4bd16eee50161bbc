#include "player/step_toward.hpp"

#include <gtest/gtest.h>

using namespace panoptes;

// Three cameras on a line, all looking north (+y): a double-click right of the centre steps east, one
// left of it steps west, the centre (looking north) has nobody ahead; Shift (the opposite direction)
// of a click right steps west.
TEST(StepToward, TheClickedDirectionPicksTheNeighbourThatWay) {
  store::Manifest m;
  for (int i = 0; i < 3; ++i) {
    store::CameraEntry c;
    c.id = i;
    c.position = {i == 1 ? 1.0 : i == 2 ? -1.0 : 0.0, 0, 0};
    c.look_at = c.position + Vec3{0, 1, 0};
    c.up = {0, 0, 1};
    m.cameras.push_back(c);
  }
  m.graph.neighbours.resize(3);
  m.graph.neighbours[0].right = 1;
  m.graph.neighbours[0].left = 2;
  const player::ViewBasis cam = player::camera_basis(m.cameras[0]);
  const player::Look look{0, 0, 90};
  const Vec3 centre = player::cutout_direction(cam, look, 680, 340, 1360, 680);
  EXPECT_NEAR(dot(centre, Vec3{0, 1, 0}), 1, 1e-9) << "the centre is the view's forward";
  EXPECT_EQ(player::neighbour_toward(m, 0, centre), -1);
  const Vec3 right = player::cutout_direction(cam, look, 1300, 340, 1360, 680);  // ~62° right of ahead
  EXPECT_GT(right.x, 0.8);
  EXPECT_EQ(player::neighbour_toward(m, 0, right), 1);
  EXPECT_EQ(player::neighbour_toward(m, 0, -right), 2);
  // Turned to face east, the centre now steps east.
  const Vec3 east_centre = player::cutout_direction(cam, player::Look{90, 0, 90}, 680, 340, 1360, 680);
  EXPECT_EQ(player::neighbour_toward(m, 0, east_centre), 1);
}
