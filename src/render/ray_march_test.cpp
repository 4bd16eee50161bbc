// The ray-march room (ray_march.hpp): one ray through one brick. Accumulators come back as opacity
// (the march's transmittance turned back), a MIP's maximum is the largest window coordinate of the
// samples the brick owns, and two bricks' samples of one ray are the whole ray's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/march_plan.hpp"
#include "render/ray_march.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

struct Ray {
  double O[3], D[3];
  Vec3 dir;
  double t0, tg1;
};

// The ray along +x through (y, z) = (8.3, 6.6) of a 25×17×13 grid of spacing 1: it enters at x = 0.
Ray along_x(const GridGeometry& g) {
  Ray r{{-5, 8.3, 6.6}, {1, 0, 0}, {1, 0, 0}, 5, 5 + double(g.dims[0] - 1)};
  return r;
}

}  // namespace

TEST(RayMarch, MipIsTheLargestWindowCoordinateOfTheOwnedSamplesAndVolumesReturnOpacity) {
  const GridGeometry g{{25, 17, 13}, {0, 0, 0}, {1, 1, 1}};
  const WaveFront fronts[] = {{{12, 8, 6}, 6, 2, 1.0}};
  const std::vector<float> f = wave_field(g, fronts);
  const std::vector<TaskSpec> tasks{TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)),
                                    TaskSpec::volume(0, TransferFunction::preset("hot", 4), ValueWindow::absolute(0, 1))};
  const Ray r = along_x(g);
  float whole_key = 0;
  for (const int parts : {1, 2, 3}) {
    float key = 0, alpha_front_to_back = 0, tr = 1;
    std::uint64_t eff = 0, marched = 0;
    for (int b = 0; b < parts; ++b) {
      const Brick brick = Brick::slab(g, 0, parts, b);
      std::vector<PreparedField> fields;
      const FieldView whole = FieldView::whole(g, f.data());
      fields.emplace_back(whole.subview(brick));
      const march::MarchPlan p = march::compile_march_plan(fields, tasks, RenderOptions{});
      const double tb0 = std::max(r.t0, r.t0 + brick.lo[0]), tb1 = std::min(r.tg1, r.t0 + brick.hi[0]);
      float acc[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
      march::march_ray(p, r.O, r.D, r.dir, r.t0, r.tg1, tb0, tb1, 3, acc, eff, marched);
      EXPECT_EQ(acc[0][3], 1.0f) << "the MIP's ray has samples in brick " << b;
      key = std::max(key, acc[0][0]);
      EXPECT_GE(acc[1][3], 0.0f);
      EXPECT_LE(acc[1][3], 1.0f);  // opacity, not transmittance
      alpha_front_to_back += tr * acc[1][3];
      tr *= 1 - acc[1][3];
    }
    if (parts == 1) {
      whole_key = key;
      // Brute force: the window coordinate of every sample of the ray (t0 + k·dt, dt = 0.5 voxel).
      float want = 0;
      const march::FieldAcc a = march::make_acc(FieldView::whole(g, f.data()));
      std::vector<PreparedField> whole_fields;
      whole_fields.emplace_back(FieldView::whole(g, f.data()));
      const march::MarchPlan p = march::compile_march_plan(whole_fields, tasks, RenderOptions{});
      const march::MarchTask& m = p.rt[0];
      for (int k = 0; 0.5 * k < r.tg1 - r.t0; ++k) {  // samples 0 … 47: x = 0 … 23.5
        const float v = march::interp_clamped(a, 0.5 * k, 8.3, 6.6);
        want = std::max(want, std::min(((m.abs1 ? std::fabs(v) : v) - m.lo1) * m.sc1, m.last1));
      }
      EXPECT_NEAR(key, want, 1e-3f * want);
      EXPECT_GT(key, 100.0f);  // the front is crossed: a real maximum, not the start value
    } else {
      EXPECT_EQ(key, whole_key) << parts << " bricks";  // max over bricks = the whole ray's
    }
    EXPECT_GT(alpha_front_to_back, 0.05f);
  }
}
