#include "ui/lattice_map.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace panoptes;

// The overview fits the box (and every camera) into the map, and shows the sky side at the top.
TEST(LatticeMap, BoxFitsTheMapAndTheSkyIsUp) {
  ui::LatticeMap map;
  map.set_scene({{1, 1, 1}, {9, 19, 4}}, {0, 0, 0}, {10, 20, 5});
  for (int c = 0; c < 8; ++c) {
    const ui::MapPoint m = map.project({c & 1 ? 10.0 : 0.0, c & 2 ? 20.0 : 0.0, c & 4 ? 5.0 : 0.0});
    EXPECT_LE(std::hypot(m.x, m.y), 1.0 + 1e-9);
  }
  EXPECT_LT(map.project({5, 10, 5}).y, map.project({5, 10, 0}).y);  // higher in the sky = higher on the map
  EXPECT_FALSE(map.empty());
}
