// The sample-block room (sample_blocks.hpp): a block of samples is the scalar interpolation of each
// of its samples, LUT bins of a block are lut_bin() lane by lane, and bins clamp (NaN to bin 0).
// Compiled with the renderer's hot-loop flags (src/render/CMakeLists.txt), so where the renderer has
// AVX2 these test its vector paths, not the scalar fallbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
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

// The 8-lane interpolation (trilinear8(): every isosurface block, hit gradient and footprint filter)
// lane by lane against the scalar one, with its corner range, for a field whose x neighbours are
// adjacent (corner pairs gathered as one 64-bit element each) and for a strided one (a caller's own
// layout: eight 32-bit gathers), at positions up to the last cell on every axis.
TEST(SampleBlocks, EightLaneInterpolationIsTheScalarOneLaneByLane) {
#ifndef PANOPTES_RENDER_AVX2
  GTEST_SKIP() << "built without AVX2 and FMA: the renderer interpolates with the scalar path";
#else
  const GridGeometry g{{21, 17, 13}, {0, 0, 0}, {1, 1, 1}};
  const WaveFront fronts[] = {{{10, 8, 6}, 5, 2, 1.0}, {{3, 12, 9}, 4, 1.5, -0.7}};
  const std::vector<float> f = wave_field(g, fronts);
  std::vector<float> every_other(2 * f.size());  // the same values at every other float
  for (std::size_t i = 0; i < f.size(); ++i) every_other[2 * i] = f[i], every_other[2 * i + 1] = 1e6f;
  FieldView strided = FieldView::whole(g, every_other.data());
  strided.stride = {2, 2 * 21, 2 * 21 * 17};
  std::mt19937 rng(7);
  for (const FieldView& view : {FieldView::whole(g, f.data()), strided}) {
    const FieldAcc a = make_acc(view);
    ASSERT_TRUE(a.gather32);
    const float top[3] = {20.0f, 16.0f, 12.0f};
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int round = 0; round < 300; ++round) {
      alignas(32) float x[8], y[8], z[8], out[8], range[8];
      for (int l = 0; l < 8; ++l) {
        float* p[3] = {&x[l], &y[l], &z[l]};
        for (int ax = 0; ax < 3; ++ax)  // every 4th coordinate on the domain's last point or a grid plane
          *p[ax] = (round + l + ax) % 4 == 0 ? (l % 2 ? top[ax] : std::floor(u(rng) * top[ax])) : u(rng) * top[ax];
      }
      __m256 r;
      _mm256_store_ps(out, trilinear8(a, _mm256_load_ps(x), _mm256_load_ps(y), _mm256_load_ps(z), &r));
      _mm256_store_ps(range, r);
      for (int l = 0; l < 8; ++l) {
        EXPECT_NEAR(out[l], interp_clamped(a, x[l], y[l], z[l]), 1e-5f)
            << "stride " << a.sx << ", lane " << l << " at " << x[l] << " " << y[l] << " " << z[l];
        const int i = std::min(int(x[l]), 19), j = std::min(int(y[l]), 15), k = std::min(int(z[l]), 11);
        float lo = view.at(i, j, k), hi = lo;
        for (int c = 1; c < 8; ++c) {
          const float w = view.at(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
          lo = std::min(lo, w), hi = std::max(hi, w);
        }
        EXPECT_EQ(range[l], hi - lo) << "stride " << a.sx << ", lane " << l;
      }
    }
  }
#endif
}
