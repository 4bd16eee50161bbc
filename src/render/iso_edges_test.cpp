// Isosurface anti-aliasing (iso_edges.hpp): silhouettes against an analytic coverage, bricks still
// composite to the single-brick image, surfaces away from silhouettes are unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "render/iso_edges.hpp"
#include "render/render_test_util.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;
using namespace panoptes::render;
using panoptes::render::testing::max_diff;
using panoptes::render::testing::render_bricked;

namespace {

// A sphere of radius R around c as the zero isosurface of R − |p − c| (a distance field: the
// trilinear surface stays within a few hundredths of a voxel of the sphere).
struct SphereScene {
  GridGeometry grid{{40, 40, 40}, {-19.5, -19.5, -19.5}, {1, 1, 1}};
  Vec3 c{1.3, -0.7, 0.4};
  double R = 11.2;
  std::vector<float> f;
  SphereScene() {
    f.resize(std::size_t(40 * 40 * 40));
    for (int k = 0; k < 40; ++k)
      for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) {
          const Vec3 p{grid.origin[0] + i, grid.origin[1] + j, grid.origin[2] + k};
          f[std::size_t(i + 40 * (j + 40 * k))] = float(R - norm(p - c));
        }
  }
  // The fraction of pixel (x, y) whose rays meet the sphere: 8 × 8 sub-pixel rays.
  double coverage(const camera::Camera& cam, int x, int y) const {
    int hits = 0;
    for (int sy = 0; sy < 8; ++sy)
      for (int sx = 0; sx < 8; ++sx) {
        const camera::Ray r = cam.ray(x + (sx + 0.5) / 8, y + (sy + 0.5) / 8);
        const Vec3 d = normalize(r.direction), oc = r.origin - c;
        const double b = dot(oc, d), q = dot(oc, oc) - R * R;
        const double disc = b * b - q;
        if (disc >= 0 && -b + std::sqrt(disc) > 0) ++hits;
      }
    return hits / 64.0;
  }
};

struct EdgeError {
  double mean = 0;  // mean |alpha − coverage| over the pixels the silhouette crosses
  int edge_pixels = 0;
  double interior_max = 0;  // largest |alpha − 1| where the pixel and its 4 neighbours are covered
};

EdgeError edge_error(const SphereScene& sc, const camera::Camera& cam, bool aa) {
  const FieldView v = FieldView::whole(sc.grid, sc.f.data());
  std::vector<PreparedField> fields;
  fields.emplace_back(v);
  const std::vector<TaskSpec> tasks = {TaskSpec::isosurface(0, 0.0f, {0.9f, 0.8f, 0.6f})};
  std::vector<PartialImage> out(1);
  RenderOptions opt;
  opt.iso_antialias = aa;
  render_brick(cam, fields, tasks, out, opt);
  EdgeError e;
  double sum = 0;
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const double alpha = out[0].rect.contains(x, y) ? out[0].rgba_at(x, y)[3] : 0.0;
      const double cov = sc.coverage(cam, x, y);
      if (cov > 0 && cov < 1) {
        sum += std::abs(alpha - cov);
        ++e.edge_pixels;
      } else if (cov == 1) {
        if (sc.coverage(cam, x - 1, y) == 1 && sc.coverage(cam, x + 1, y) == 1 && sc.coverage(cam, x, y - 1) == 1 &&
            sc.coverage(cam, x, y + 1) == 1)
          e.interior_max = std::max(e.interior_max, std::abs(alpha - 1));
        else
          sum += 1 - alpha;  // covered by all 64 sub-rays, next to the silhouette
      } else {
        sum += alpha;  // a halo outside the silhouette counts as error too
      }
    }
  e.mean = sum / std::max(1, e.edge_pixels);
  return e;
}

}  // namespace

// The stair-step measure: with anti-aliasing the silhouette's pixels carry the coverage the
// sphere really has (8 × 8 sub-pixel rays against the analytic sphere) within a few hundredths;
// without it every silhouette pixel is 0 or 1 (mean error ≈ 0.25). Outside and perspective,
// and from inside the domain in an equirectangular frame (the lattice rigs' view).
TEST(IsoEdges, SilhouetteCoverageFollowsTheAnalyticSphere) {
  const SphereScene sc;
  const camera::Camera cams[] = {
      camera::Camera({40, -55, 25}, {0, 0, 0}, {0, 0, 1}, 30, 72, 64),
      camera::Camera({-8, 9, -6}, {1.3, -0.7, 0.4}, {0, 0, 1}, 60, 160, 80, camera::Projection::equirectangular),
  };
  for (const camera::Camera& cam : cams) {
    const EdgeError off = edge_error(sc, cam, false), on = edge_error(sc, cam, true);
    SCOPED_TRACE(cam.projection() == camera::Projection::perspective ? "perspective" : "equirectangular");
    ASSERT_GT(off.edge_pixels, 40);
    EXPECT_GT(off.mean, 0.15);  // the stair steps that are measured here
    EXPECT_LT(on.mean, 0.075);         // measured 0.052 (perspective), 0.058 (equirectangular)
    EXPECT_LT(on.mean * 3, off.mean);  // at least 3x less edge error (measured 3.8x, 4.0x)
    EXPECT_LT(on.interior_max, 1e-6);  // opaque inside the silhouette, as before
    std::printf("edge error %s: off %.4f, on %.4f (%d silhouette pixels)\n",
                cam.projection() == camera::Projection::perspective ? "perspective" : "equirectangular", off.mean,
                on.mean, on.edge_pixels);
    RecordProperty(cam.projection() == camera::Projection::perspective ? "persp_off_on" : "equirect_off_on",
                   std::to_string(off.mean) + " " + std::to_string(on.mean));
  }
}

// Anti-aliased contributions are samples of one ray at positions one brick owns: a brick
// decomposition (slabs along each axis, cameras outside and inside) still composites to the
// single-brick image.
TEST(IsoEdges, BricksCompositeToTheSingleBrickImage) {
  const GridGeometry grid{{41, 37, 33}, {-20, -21.6, -12.8}, {1.0, 1.2, 0.8}};
  const WaveFront pf[] = {{{-4, 3, 1}, 14, 2.5, 1.0}, {{6, -5, -2}, 8, 2, -0.8}};
  const std::vector<float> p = wave_field(grid, pf);
  const std::vector<FieldView> views = {FieldView::whole(grid, p.data())};
  const std::vector<TaskSpec> tasks = {
      TaskSpec::isosurface(0, 0.4f, {1, 0.6f, 0.2f}), TaskSpec::isosurface(0, -0.2f, {0.3f, 0.9f, 0.4f}),
      TaskSpec::volume(0, TransferFunction::preset("p-wave", 2), ValueWindow::absolute(0, 1))};
  RenderOptions opt;
  opt.iso_antialias = true;
  opt.equirect_adaptive = false;  // exact compositing is asked of the full march; adaptive 360° frames: Compositing.CamerasInside…
  const camera::Camera cams[] = {
      camera::Camera({45, -60, 30}, {0, 0, 0}, {0, 0, 1}, 40, 64, 60),
      camera::Camera({2, -1, 0.5}, {10, 0, 0}, {0, 0, 1}, 60, 96, 48, camera::Projection::equirectangular),
  };
  for (const camera::Camera& cam : cams) {
    const std::vector<Brick> one = {Brick::slab(grid, 0, 1, 0)};
    const std::vector<Image> ref = render_bricked(cam, views, tasks, one, opt);
    RenderOptions off;
    const std::vector<Image> plain = render_bricked(cam, views, tasks, one, off);
    EXPECT_GT(max_diff(ref[0], plain[0]), 8);  // anti-aliasing changed the silhouettes
    for (int axis = 0; axis < 3; ++axis)
      for (int n : {2, 3}) {
        std::vector<Brick> bricks;
        for (int i = 0; i < n; ++i) bricks.push_back(Brick::slab(grid, axis, n, i));
        const std::vector<Image> img = render_bricked(cam, views, tasks, bricks, opt);
        for (std::size_t t = 0; t < tasks.size(); ++t)
          EXPECT_LE(max_diff(img[t], ref[t]), 1) << "axis " << axis << ", " << n << " bricks, task " << t;
      }
  }
}

TEST(IsoEdges, PixelPitchIsTheAngleBetweenNeighbouringRows) {
  const camera::Camera persp({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 90, 200, 100);
  EXPECT_NEAR(march::pixel_pitch(persp), 2.0 / 100, 1e-4);  // 2·tan(45°) / 100 rows at the centre
  const camera::Camera eq({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 90, 360, 180, camera::Projection::equirectangular);
  EXPECT_NEAR(march::pixel_pitch(eq), M_PI / 180, 1e-9);
}
