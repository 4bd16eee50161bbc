// The sample-block room (sample_blocks.hpp): a block of samples is the scalar interpolation of each
// of its samples, LUT bins of a block are lut_bin() lane by lane, and bins clamp (NaN to bin 0).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/sample_blocks.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;
using namespace panoptes::render;
using namespace panoptes::render::march;

TEST(SampleBlocks, LutBinClampsTakesAbsoluteValuesAndSendsNanToTheFirstBin) {
  // window [lo, lo + 1023/sc]: u = (v − lo)·sc, clamped to [0, last]
  EXPECT_EQ(lut_bin(0.5f, 0.0f, 100.0f, 1023.0f, false), 50);
  EXPECT_EQ(lut_bin(-0.5f, 0.0f, 100.0f, 1023.0f, false), 0);
  EXPECT_EQ(lut_bin(-0.5f, 0.0f, 100.0f, 1023.0f, true), 50);
  EXPECT_EQ(lut_bin(1e9f, 0.0f, 100.0f, 1023.0f, false), 1023);
  EXPECT_EQ(lut_bin(NAN, 0.0f, 100.0f, 1023.0f, false), 0);
}

TEST(SampleBlocks, ABlockOfBinsIsLutBinLaneByLane) {
  const float v[kBlock] = {-2.0f, -0.25f, 0.0f, 0.3f, 0.999f, 1.5f, NAN, 0.5f};
  for (const bool absv : {false, true}) {
    alignas(32) int bin[kBlock];
    lut_bin_block<4>(v, -1.0f, 511.5f, 1023.0f, absv, bin);
    for (int l = 0; l < kBlock; ++l) EXPECT_EQ(bin[l], lut_bin(v[l], -1.0f, 511.5f, 1023.0f, absv) << 4) << "lane " << l;
  }
}

TEST(SampleBlocks, ABlockIsTheScalarInterpolationOfItsSamples) {
  const GridGeometry g{{21, 17, 13}, {0, 0, 0}, {1, 1, 1}};
  const WaveFront fronts[] = {{{10, 8, 6}, 5, 2, 1.0}};
  const std::vector<float> f = wave_field(g, fronts);
  const FieldAcc a = make_acc(FieldView::whole(g, f.data()));
  // An oblique ray through the grid; the last block is partial (lanes past n repeat sample n − 1).
  const RayPos P{0.5f, 1.25f, 0.75f, 0.61f, 0.47f, 0.33f};
  for (std::int64_t k0 = 0; k0 < 24; k0 += kBlock) {
    const int n = k0 == 16 ? 5 : kBlock;
    alignas(32) float v[kBlock];
    interp_block(a, P, k0, n, false, v);
    for (int l = 0; l < kBlock; ++l) {
      const float fk = float(k0 + std::min(l, n - 1));
      const float want = interp_clamped(a, P.bx + fk * P.sx, P.by + fk * P.sy, P.bz + fk * P.sz);
      EXPECT_NEAR(v[l], want, 1e-6f) << "sample " << k0 + l;
    }
  }
}
