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
}  // namespace panoptes::ui
