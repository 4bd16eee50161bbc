#include "player/face_action.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

using namespace panoptes;

namespace {
// A dim equirectangular frame with a bright disc around (lon, lat) in degrees.
video::YuvFrame frame_with_blob(int W, int H, double lon_deg, double lat_deg) {
  video::YuvFrame f;
  f.width = W;
  f.height = H;
  f.y.assign(std::size_t(W) * H, 20);
  f.u.assign(std::size_t((W + 1) / 2) * ((H + 1) / 2), 128);
  f.v = f.u;
  const double deg = std::numbers::pi / 180;
  const Vec3 c{std::cos(lat_deg * deg) * std::sin(lon_deg * deg), std::sin(lat_deg * deg),
               std::cos(lat_deg * deg) * std::cos(lon_deg * deg)};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double lon = (2.0 * (x + 0.5) / W - 1.0) * std::numbers::pi, lat = (0.5 - (y + 0.5) / H) * std::numbers::pi;
      const Vec3 d{std::cos(lat) * std::sin(lon), std::sin(lat), std::cos(lat) * std::cos(lon)};
      if (dot(d, c) > std::cos(8 * deg)) f.y[std::size_t(y) * W + x] = 220;
    }
  return f;
}
}  // namespace

// The blob behind-left and a little up: the face-the-action look turns there (yaw, pitch within 1.5°),
// also for a camera that faces another way; a frame with nothing standing out gives no direction.
TEST(FaceAction, TurnsTowardTheBrightestRegionOfTheFrame) {
  const player::ViewBasis cam;  // forward +y, right +x, up +z
  const auto f = frame_with_blob(768, 384, -135, 20);
  const auto d = player::strongest_signal_direction(f, cam);
  ASSERT_TRUE(d.has_value());
  const player::Look look = player::look_towards(cam, *d, 90);
  EXPECT_NEAR(look.yaw_deg, -135, 1.5);
  EXPECT_NEAR(look.pitch_deg, 20, 1.5);

  player::ViewBasis east;
  east.forward = {1, 0, 0};
  east.right = {0, -1, 0};
  east.up = {0, 0, 1};
  const auto d2 = player::strongest_signal_direction(frame_with_blob(768, 384, 60, -10), east);
  ASSERT_TRUE(d2.has_value());
  const player::Look l2 = player::look_towards(east, *d2, 90);
  EXPECT_NEAR(l2.yaw_deg, 60, 1.5);
  EXPECT_NEAR(l2.pitch_deg, -10, 1.5);

  video::YuvFrame flat = f;
  std::fill(flat.y.begin(), flat.y.end(), std::uint8_t(40));
  EXPECT_FALSE(player::strongest_signal_direction(flat, cam).has_value()) << "nothing stands out";
}
