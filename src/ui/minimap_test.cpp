#include "ui/minimap.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace panoptes::ui {
namespace {

Vec3 from_lat_lon(double lat_deg, double lon_deg) {
  const double la = lat_deg * M_PI / 180, lo = lon_deg * M_PI / 180;
  return {std::cos(la) * std::cos(lo), std::cos(la) * std::sin(lo), std::sin(la)};
}

TEST(MiniMap, TheCameraAtTheViewLongitudeFacesTheViewer) {
  const double az = 40 * M_PI / 180, el = 25 * M_PI / 180;
  const MapPoint p = project_to_map(from_lat_lon(0, 40), az, el);
  EXPECT_NEAR(p.x, 0, 1e-12);
  EXPECT_GT(p.y, 0);  // on the equator, seen from above: below the centre (y grows downwards)
  EXPECT_NEAR(p.depth, std::cos(el), 1e-12);
  // The antipode is behind, the north pole above the centre, east of the view longitude is right.
  EXPECT_LT(project_to_map(from_lat_lon(0, 220), az, el).depth, 0);
  EXPECT_LT(project_to_map({0, 0, 1}, az, el).y, 0);
  EXPECT_GT(project_to_map(from_lat_lon(0, 70), az, el).x, 0);
}

TEST(MiniMap, ProjectionIsOrthographicOntoTheUnitDisc) {
  for (double lat = -90; lat <= 90; lat += 15)
    for (double lon = -180; lon < 180; lon += 20) {
      const MapPoint p = project_to_map(from_lat_lon(lat, lon), 1.0, 0.4);
      EXPECT_NEAR(p.x * p.x + p.y * p.y + p.depth * p.depth, 1, 1e-12);
    }
}

}  // namespace
}  // namespace panoptes::ui
