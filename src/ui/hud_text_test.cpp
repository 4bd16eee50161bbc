#include "ui/hud_text.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace panoptes::ui {
namespace {

// The round-1 screenshot read "lat -0": printf's "%+.0f" of a tiny negative number.
TEST(HudText, DegreesNeverReadMinusZero) {
  EXPECT_EQ(signed_degrees(-1e-9), "0");
  EXPECT_EQ(signed_degrees(-0.49), "0");
  EXPECT_EQ(signed_degrees(-0.0), "0");
  EXPECT_EQ(signed_degrees(0.4), "0");
  EXPECT_EQ(signed_degrees(-0.5), "-1");  // std::round: halves away from zero
  EXPECT_EQ(signed_degrees(29.6), "+30");
  EXPECT_EQ(signed_degrees(-179.9), "-180");
  EXPECT_EQ(signed_degrees(std::numeric_limits<double>::quiet_NaN()), "?");
  EXPECT_EQ(look_text({-0.3, -1e-12, 90}), "look yaw 0  pitch 0  fov 90");
  EXPECT_EQ(look_text({-90.2, 12.5, 60}), "look yaw -90  pitch +13  fov 60");
  EXPECT_EQ(lattice_position_text({4, 4, 3}, 1 + 4 * (2 + 4 * 1)), "lattice (1, 2, 1) of 4x4x3");
  EXPECT_EQ(lattice_position_text({0, 0, 0}, 3), "");
}

}  // namespace
// The HUD says where the viewer stands in world units and which way it faces on a compass, in the
// domain's sky frame (z_down: north = +x, east = +y, sky = -z).
TEST(HudText, WorldPositionAndHeading) {
  EXPECT_EQ(world_position_text({1, 2, 3}, {0, 1, 0}, false), "at (1, 2, 3)   heading 000 N   elevation 0");
  EXPECT_EQ(world_position_text({0, 0, 0}, {1, 0, 0}, false), "at (0, 0, 0)   heading 090 E   elevation 0");
  EXPECT_EQ(world_position_text({0, 0, 0}, {-1, -1, 0}, false), "at (0, 0, 0)   heading 225 SW   elevation 0");
  EXPECT_EQ(world_position_text({120, 40, -35}, {1, 1, -std::sqrt(2.0) * std::tan(10 * M_PI / 180)}, true),
            "at (120, 40, -35)   heading 045 NE   elevation +10");
  EXPECT_EQ(world_position_text({0, 0, 0}, {0, 0, 1}, false), "at (0, 0, 0)   looking up");
  EXPECT_EQ(world_position_text({0, 0, 0}, {0, 0, 1}, true), "at (0, 0, 0)   looking down");
}

}  // namespace panoptes::ui
