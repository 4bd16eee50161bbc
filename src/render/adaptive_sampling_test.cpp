// The adaptive-sampling room (adaptive_sampling.hpp): a tile whose colours are smooth is filled from
// a coarse lattice (bilinear: exact on a linear ramp) with far fewer marches than pixels; a corner
// that differs is refined down to its pixels; a keyed (max-blend) image keeps the key of the pixels
// marched for it and gives an interpolated pixel its cell's smallest corner key.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <vector>

#include "render/adaptive_sampling.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

constexpr int kW = 32, kH = 32;

struct Scene {
  std::vector<PartialImage> out = std::vector<PartialImage>(2);
  int marches = 0;
  bool step = false;    // a jump in image 0 at x >= 21
  bool curved = false;  // image 0 a quadratic in x and y instead of the ramp
  Scene() {
    for (PartialImage& o : out) o.resize(kW, kH, {0, 0, kW, kH});
  }
  float ramp(int x, int y) const {
    if (curved) return 0.1f + 0.0004f * float(x * x) + 0.0003f * float(y * y) + 0.00002f * float(x * x * y);
    return step && x >= 21 ? 0.9f : 0.01f * float(x) + 0.005f * float(y);
  }
  // Image 0: an opaque ramp at entry depth 5; image 1 (keyed): a constant colour, key −(x + y).
  std::uint8_t march(int x, int y, std::uint64_t tasks) {
    ++marches;
    if (tasks & 1) {
      float* p = out[0].rgba_at(x, y);
      p[0] = p[1] = p[2] = ramp(x, y), p[3] = 1;
    }
    if (tasks & 2) {
      float* p = out[1].rgba_at(x, y);
      p[0] = 0.5f, p[1] = p[2] = 0, p[3] = 1;
      out[1].depth[std::size_t(y) * kW + std::size_t(x)] = -float(x + y);
    }
    out[0].depth[std::size_t(y) * kW + std::size_t(x)] = 5.0f;
    return 0;
  }
  void run(float tolerance = 0.1f, float linear = 0) {
    AdaptiveTile tile(4, tolerance, linear);  // corners of a cell differ by 0.06 at most on the ramp
    tile.run(PixelRect{0, 0, kW, kH}, out, [&](int x, int y, std::uint64_t m) { return march(x, y, m); },
             [](int, int, std::uint8_t) { return 5.0f; }, 0, nullptr, 0, 2);
  }
};

}  // namespace

TEST(AdaptiveSampling, ASmoothTileIsInterpolatedExactlyFromFewMarches) {
  Scene s;
  s.run();
  EXPECT_LT(s.marches, kW * kH / 4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_NEAR(s.out[0].rgba_at(x, y)[0], s.ramp(x, y), 1e-5f) << x << "," << y;
      EXPECT_EQ(s.out[0].depth[std::size_t(y) * kW + std::size_t(x)], 5.0f);  // the located entry depth
    }
}

TEST(AdaptiveSampling, KeyedImagesKeepMarchedKeysAndTakeTheCellsSmallestKeyElsewhere) {
  Scene s;
  s.run();
  // Lattice pixels (multiples of 4, and the tile's last row and column) were marched: their exact key.
  EXPECT_EQ(s.out[1].depth[std::size_t(8) * kW + 12], -20.0f);
  // An interpolated pixel: its cell's smallest corner key (the largest maximum), here the lower right
  // corner (x1 + y1) of cell [4, 8] × [8, 12].
  EXPECT_EQ(s.out[1].depth[std::size_t(9) * kW + 5], -float(8 + 12));
  EXPECT_FLOAT_EQ(s.out[1].rgba_at(5, 9)[0], 0.5f);
}

TEST(AdaptiveSampling, AJumpBetweenCornersIsRefinedToItsPixels) {
  Scene s;
  s.step = true;
  s.run();
  for (int y = 0; y < kH; ++y)
    for (int x = 18; x < 24; ++x) ASSERT_NEAR(s.out[0].rgba_at(x, y)[0], s.ramp(x, y), 1e-5f) << x << "," << y;
}

// Round 13's linear test: with a tolerance below the ramp's change across a cell, the range test splits
// every cell down to its pixels; with `linear` the first split's new points lie on the bilinear image
// of the cell's corners, so its sub-cells are filled from them (exactly, on a ramp) without splitting
// further, while a jump is still refined to its pixels.
TEST(AdaptiveSampling, ALinearRampStopsTheSplitOneLevelUp) {
  Scene full, lin;
  full.run(0.02f, 0);
  lin.run(0.02f, 0.01f);
  EXPECT_LT(lin.marches, full.marches / 2) << lin.marches << " vs " << full.marches;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_NEAR(lin.out[0].rgba_at(x, y)[0], lin.ramp(x, y), 1e-5f) << x << "," << y;
  Scene jump;
  jump.step = true;
  jump.run(0.02f, 0.01f);
  for (int y = 0; y < kH; ++y)
    for (int x = 18; x < 24; ++x) ASSERT_NEAR(jump.out[0].rgba_at(x, y)[0], jump.ramp(x, y), 1e-5f) << x << "," << y;
}

// A curved but smooth image (a quadratic in x and in y) fails the linear test in every cell; the
// biquadratic through a 4x4 cell's 3x3 marched points reproduces it, its four sub-cell centres
// (marched to check it) agree, and the cell is filled from it: 9 of its 16 inner pixels' marches
// instead of all, and the same values. A jump still fails the check and is refined.
TEST(AdaptiveSampling, ACurvedSmoothCellIsFilledFromItsBiquadratic) {
  Scene pixels, quad;
  pixels.curved = quad.curved = true;
  pixels.run(0.0f, 0);     // every cell split to its pixels: every pixel marched
  quad.run(0.0f, 1e-4f);  // the bilinear misses the curvature by >= 0.0016 at the midpoints
  EXPECT_EQ(pixels.marches, kW * kH);
  // The tile's last lattice cells are 3 pixels wide ({…, 28, 31}): those split to their pixels.
  EXPECT_LT(quad.marches, 2 * kW * kH / 3) << quad.marches;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_NEAR(quad.out[0].rgba_at(x, y)[0], quad.ramp(x, y), 2e-5f) << x << "," << y;
      EXPECT_EQ(quad.out[0].depth[std::size_t(y) * kW + std::size_t(x)], 5.0f);
    }
  Scene jump;
  jump.step = true;
  jump.run(0.0f, 1e-4f);
  for (int y = 0; y < kH; ++y)
    for (int x = 16; x < 28; ++x) ASSERT_NEAR(jump.out[0].rgba_at(x, y)[0], jump.ramp(x, y), 1e-5f) << x << "," << y;
}
