// Known-answer tests of the ray caster.
#include "render/renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <omp.h>

#include "render/iso_shading.hpp"
#include "render/render_test_util.hpp"
#include "render/synthetic_fields.hpp"
#include "render/tile_schedule.hpp"

using namespace panoptes;
using namespace panoptes::render;
using panoptes::render::testing::max_diff;

namespace {

std::vector<PartialImage> render_whole(const camera::Camera& cam, const FieldView& f, const std::vector<TaskSpec>& tasks,
                                       const RenderOptions& opt = {}) {
  std::vector<PreparedField> fields{PreparedField(f)};
  std::vector<PartialImage> out(tasks.size());
  render_brick(cam, fields, tasks, out, opt);
  return out;
}

// World path length of a ray through an axis-aligned box (0 if it misses).
double path_length(const camera::Ray& r, const Vec3& lo, const Vec3& hi) {
  double t0 = 0, t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (r.direction[a] == 0) continue;
    double ta = (lo[a] - r.origin[a]) / r.direction[a], tb = (hi[a] - r.origin[a]) / r.direction[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return std::max(0.0, t1 - t0);
}

}  // namespace

TEST(Renderer, HomogeneousSlabHasOpacityOneMinusExpSigmaL) {
  // Anisotropic spacing: the voxel (unit of extinction and sample distance) is the smallest, 0.5.
  const GridGeometry g{{12, 10, 7}, {-2.75, -3.6, -1.5}, {0.5, 0.8, 0.5}};
  std::vector<float> v(12 * 10 * 7, 1.0f);
  const FieldView f = FieldView::whole(g, v.data());
  const float sigma = 0.35f;  // per voxel length
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::constant({1, 1, 1}, sigma), ValueWindow::absolute(0, 2))};
  const camera::Camera cams[] = {camera::Camera({0, 0, 40}, {0, 0, 0}, {0, 1, 0}, 10, 33, 33),
                                 camera::Camera({9, -14, 20}, {0.3, 0.2, -0.1}, {0, 0, 1}, 30, 40, 36)};
  for (const auto& cam : cams)
    for (double step : {0.5, 0.37, 1.0, 0.1}) {
      RenderOptions opt;
      opt.sample_distance = step;
      opt.termination_alpha = 1.01f;  // no early termination: compare the full integral
      const auto out = render_whole(cam, f, tasks, opt);
      int checked = 0;
      for (int y = 0; y < cam.height(); ++y)
        for (int x = 0; x < cam.width(); ++x) {
          const double L = path_length(cam.ray(x + 0.5, y + 0.5), g.domain_lo(), g.domain_hi()) / g.voxel();
          if (L < 1) continue;  // grazing rays: the tolerance is relative
          const double expected = 1 - std::exp(-sigma * L);
          const float alpha = out[0].rgba_at(x, y)[3];
          ASSERT_NEAR(alpha, expected, 0.01 * expected) << "pixel " << x << "," << y << " step " << step;
          ++checked;
        }
      EXPECT_GT(checked, 50);
    }
}

TEST(Renderer, SampleDistanceCorrectionMakesImagesNearlyStepIndependent) {
  const GridGeometry g{{48, 40, 36}, {-23.5, -19.5, -17.5}, {1, 1, 1}};
  const WaveFront wf[] = {{{2, -1, 0}, 12, 3, 1.0}};
  const auto v = wave_field(g, wf);
  const FieldView f = FieldView::whole(g, v.data());
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1))};
  const camera::Camera cam({50, 40, 30}, {0, 0, 0}, {0, 0, 1}, 40, 64, 64);
  auto image = [&](double step) {
    RenderOptions opt;
    opt.sample_distance = step;
    const auto out = render_whole(cam, f, tasks, opt);
    return finish_image(out[0], cam, g, {0, 0, 0}, {false});
  };
  const Image ref = image(0.125);
  for (double step : {0.25, 0.5, 1.0}) {
    const Image img = image(step);
    EXPECT_GT(psnr(img, ref), step < 1 ? 38.0 : 32.0) << "step " << step;
  }
}

TEST(Renderer, SphereIsosurfaceProjectsToThePredictedCircle) {
  const int n = 48;
  const GridGeometry g{{n, n, n}, {-23.5, -23.5, -23.5}, {1, 1, 1}};
  std::vector<float> v(std::size_t(n) * n * n);
  const Vec3 c{1.3, -0.7, 0.4};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        v[std::size_t(i + n * (j + n * k))] = float(norm(Vec3{i - 23.5, j - 23.5, k - 23.5} - c));
  const FieldView f = FieldView::whole(g, v.data());
  const double R = 15;
  const std::vector<TaskSpec> tasks{TaskSpec::isosurface(0, float(R))};
  const Vec3 dir = normalize(Vec3{0.6, -0.5, 0.62});
  const double D = 70;
  const camera::Camera cam(c + dir * D, c, {0, 0, 1}, 40, 96, 90);
  const auto out = render_whole(cam, f, tasks);
  double cx, cy;
  ASSERT_TRUE(cam.project(c, cx, cy));
  // The silhouette of a sphere seen from its axis is a circle of angular radius asin(R/D).
  const double r_px = std::tan(std::asin(R / D)) / std::tan(cam.fov_y_degrees() * std::numbers::pi / 360) * cam.height() / 2;
  int inside = 0, mismatches = 0;
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const bool hit = out[0].rect.contains(x, y) && out[0].rgba_at(x, y)[3] > 0.5f;
      inside += hit;
      if (std::abs(d - r_px) <= 1.0) continue;  // within one pixel of the circle
      if (hit != (d < r_px)) ++mismatches;
    }
  EXPECT_EQ(mismatches, 0);
  EXPECT_NEAR(inside, std::numbers::pi * r_px * r_px, 2 * std::numbers::pi * r_px);
}

namespace {
struct RotScene {
  static constexpr int n = 24, m = 17;
  GridGeometry g{{n, n, m}, {-11.5, -11.5, -8}, {1, 1, 1}};
  std::vector<float> f, rot;
  RotScene() {
    // An asymmetric field: two fronts off-centre.
    const WaveFront wf[] = {{{4, 2, 1}, 6, 2, 1.0}, {{-5, 3, -2}, 3, 1.5, -0.7}};
    f = wave_field(g, wf);
    // g'(i, j, k) = f(j, n−1−i, k): the field rotated by +90° about z.
    rot.resize(f.size());
    for (int k = 0; k < m; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) rot[std::size_t(i + n * (j + n * k))] = f[std::size_t(j + n * ((n - 1 - i) + n * k))];
  }
};
const std::vector<TaskSpec> kRotTasks{
    TaskSpec::volume(0, TransferFunction::preset("diverging", 2), ValueWindow::absolute(-1, 1)),
    TaskSpec::isosurface(0, 0.5f),
};
}  // namespace

TEST(Renderer, RotatingFieldAndCameraGivesTheSameImage) {
  const RotScene s;
  const Vec3 p{30, -22, 18};
  const camera::Camera cam(p, {0, 0, 0}, {0, 0, 1}, 45, 48, 48);
  const camera::Camera cam_r({-p.y, p.x, p.z}, {0, 0, 0}, {0, 0, 1}, 45, 48, 48);
  const auto a = render_whole(cam, FieldView::whole(s.g, s.f.data()), kRotTasks);
  const auto b = render_whole(cam_r, FieldView::whole(s.g, s.rot.data()), kRotTasks);
  for (std::size_t t = 0; t < kRotTasks.size(); ++t)
    EXPECT_LE(max_diff(finish_image(a[t], cam, s.g), finish_image(b[t], cam_r, s.g)), 1) << "task " << t;
}

TEST(Renderer, RotatingTheFieldUnderAnAxialCameraRotatesTheImage) {
  const RotScene s;
  const camera::Camera cam({0, 0, 60}, {0, 0, 0}, {0, 1, 0}, 40, 48, 48);
  const auto a = render_whole(cam, FieldView::whole(s.g, s.f.data()), kRotTasks);
  const auto b = render_whole(cam, FieldView::whole(s.g, s.rot.data()), kRotTasks);
  for (std::size_t t = 0; t < kRotTasks.size(); ++t) {
    const Image ia = finish_image(a[t], cam, s.g), ib = finish_image(b[t], cam, s.g);
    int worst = 0, nonblack = 0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x)
        for (int c = 0; c < 3; ++c) {
          // Counter-clockwise by 90° on screen: new(x, y) = old(W − 1 − y, x).
          worst = std::max(worst, std::abs(int(ib.at(x, y)[c]) - int(ia.at(47 - y, x)[c])));
          nonblack += ib.at(x, y)[c] > 20;
        }
    EXPECT_LE(worst, 1) << "task " << t;
    EXPECT_GT(nonblack, 100) << "task " << t;
  }
}

TEST(Renderer, EmptyFieldGivesBackgroundOnlyAndTheOutlineWhenEnabled) {
  const GridGeometry g{{20, 16, 12}, {-9.5, -7.5, -5.5}, {1, 1, 1}};
  std::vector<float> v(20 * 16 * 12, 0.0f);
  const std::vector<TaskSpec> tasks{
      TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1)),
      TaskSpec::isosurface(0, 0.5f),
  };
  const camera::Camera cam({30, -25, 20}, {0, 0, 0}, {0, 0, 1}, 40, 64, 48);
  const auto out = render_whole(cam, FieldView::whole(g, v.data()), tasks);
  const Rgb bg{0.2f, 0.3f, 0.4f};
  const std::uint8_t bg8[3] = {51, 77, 102};
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    const Image off = finish_image(out[t], cam, g, bg, {false});
    for (int y = 0; y < off.height; ++y)
      for (int x = 0; x < off.width; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(off.at(x, y)[c], bg8[c]) << x << "," << y;
    // With the outline: changed pixels lie within 2 px of a projected box edge, and there are some.
    const Image on = finish_image(out[t], cam, g, bg);
    std::vector<std::array<double, 4>> edges;
    const Vec3 lo = g.domain_lo(), hi = g.domain_hi();
    for (int e = 0; e < 12; ++e) {
      const int a = e / 4, b = (a + 1) % 3, d = (a + 2) % 3;
      Vec3 p = lo, q = lo;
      p[b] = q[b] = (e & 1) ? hi[b] : lo[b];
      p[d] = q[d] = (e & 2) ? hi[d] : lo[d];
      q[a] = hi[a];
      double ax, ay, bx, by;
      ASSERT_TRUE(cam.project(p, ax, ay) && cam.project(q, bx, by));
      edges.push_back({ax, ay, bx, by});
    }
    int changed = 0;
    for (int y = 0; y < on.height; ++y)
      for (int x = 0; x < on.width; ++x) {
        if (on.at(x, y)[0] == bg8[0] && on.at(x, y)[1] == bg8[1] && on.at(x, y)[2] == bg8[2]) continue;
        ++changed;
        double dmin = 1e9;
        for (const auto& s : edges) {
          const double dx = s[2] - s[0], dy = s[3] - s[1];
          double u = ((x + 0.5 - s[0]) * dx + (y + 0.5 - s[1]) * dy) / (dx * dx + dy * dy);
          u = std::clamp(u, 0.0, 1.0);
          dmin = std::min(dmin, std::hypot(x + 0.5 - s[0] - u * dx, y + 0.5 - s[1] - u * dy));
        }
        EXPECT_LE(dmin, 2.0) << x << "," << y;
      }
    EXPECT_GT(changed, 100);
  }
}

TEST(Renderer, OutlineBehindAnOpaqueVolumeIsHidden) {
  const GridGeometry g{{20, 16, 12}, {-9.5, -7.5, -5.5}, {1, 1, 1}};
  std::vector<float> v(20 * 16 * 12, 1.0f);
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::constant({1, 0, 0}, 5), ValueWindow::absolute(0, 2))};
  const camera::Camera cam({40, -12, 8}, {0, 0, 0}, {0, 0, 1}, 40, 64, 48);
  const auto out = render_whole(cam, FieldView::whole(g, v.data()), tasks);
  const Image on = finish_image(out[0], cam, g, {0, 0, 0}, {true, {0, 1, 0}, 1.5f});
  // The corner farthest from the camera (−x, +y, −z) joins three back edges and projects inside the
  // volume's footprint: it must show the (red) volume, not the (green) outline.
  double bx, by;
  ASSERT_TRUE(cam.project({g.domain_lo().x, g.domain_hi().y, g.domain_lo().z}, bx, by));
  const std::uint8_t* px = on.at(int(bx), int(by));
  EXPECT_GT(px[0], 200);
  EXPECT_LT(px[1], 10);
  // A front (silhouette-free) edge stays visible: the corner nearest the camera (+x, −y, +z).
  double fx, fy;
  ASSERT_TRUE(cam.project({g.domain_hi().x, g.domain_lo().y, g.domain_hi().z}, fx, fy));
  EXPECT_GT(on.at(int(fx), int(fy))[1], 150);
}

// The renderer's hit shading (six interpolations as one 8-lane gather, |n·l|^32 by squarings) against
// the pre-issue-10 scalar formula, and both against the analytic answer on a linear field.
TEST(Renderer, IsosurfaceHitShadingMatchesTheScalarFormula) {
  // Linear field v = a·x (world coordinates, anisotropic spacing): central differences are exact, so
  // the normal is a/|a| everywhere, at the faces too (one-sided differences).
  const GridGeometry g{{19, 23, 17}, {-3, 2, -5}, {1.0, 1.5, 0.75}};
  const Vec3 grad{0.3, -0.8, 0.45};
  std::vector<float> lin(std::size_t(g.dims[0]) * g.dims[1] * g.dims[2]);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        lin[std::size_t(i + g.dims[0] * (j + g.dims[1] * k))] =
            float(grad[0] * i * g.spacing[0] + grad[1] * j * g.spacing[1] + grad[2] * k * g.spacing[2]);
  const WaveFront wf[] = {{{1, 9, -1}, 6, 2, 1.0}, {{-1, 15, 1}, 4, 1.5, -0.7}};
  const std::vector<float> wave = wave_field(g, wf);
  const FieldView fl = FieldView::whole(g, lin.data()), fw = FieldView::whole(g, wave.data());
  const Rgb colour{0.9f, 0.5f, 0.2f};
  std::uint32_t seed = 12345;
  auto uniform = [&] {
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  double worst = 0;
  int faces = 0;
  for (int n = 0; n < 2000; ++n) {
    double p[3];
    for (int a = 0; a < 3; ++a) {
      p[a] = uniform() * (g.dims[a] - 1);
      if (n % 7 == a) p[a] = 0, ++faces;                  // on a lower face
      if (n % 11 == a) p[a] = g.dims[a] - 1.0, ++faces;  // on an upper face
    }
    const Vec3 dir = normalize(Vec3{uniform() - 0.5, uniform() - 0.5, uniform() - 0.5});
    float fast[4], scalar[4];
    for (const FieldView* f : {&fl, &fw}) {
      shade_isosurface_hit(*f, p, dir, colour, true, fast);
      shade_isosurface_hit(*f, p, dir, colour, false, scalar);
      for (int c = 0; c < 4; ++c) worst = std::max(worst, double(std::abs(fast[c] - scalar[c])));
    }
    // The analytic colour on the linear field (float interpolation: a few 1e-6 of slack).
    shade_isosurface_hit(fl, p, dir, colour, true, fast);
    const double ndl = std::abs(dot(normalize(grad), dir));
    const double spec = 0.25 * std::pow(ndl, 32.0);
    const float rgb[3] = {colour.r, colour.g, colour.b};
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(fast[c], std::min(1.0, rgb[c] * (0.15 + 0.85 * ndl) + spec), 1e-4) << n;
    ASSERT_EQ(fast[3], 1.0f);
  }
  EXPECT_GT(faces, 100);
  // The same interpolated values; only |n·l|^32 rounds differently (a few ulps of a double).
  EXPECT_LE(worst, 1e-6);
  std::printf("hit shading: renderer vs scalar formula, worst channel difference %.3g\n", worst);
}

// A source's near field far above a fixed window (the paper run at h = 100 m: 1.3 1/s beside a
// window of 5e-5 1/s) must leave the field's zeros black. The 16-bit corner copy once spread its
// levels over the whole value range, so zero read back as 0.3x the window and the box glowed where
// the field was exactly zero; prepare_fields() now clamps each copy to what its tasks tell apart.
TEST(Renderer, FarAboveTheWindowZerosStayBlack) {
  const GridGeometry g{{24, 24, 24}, {-11.5, -11.5, -11.5}, {1, 1, 1}};
  std::vector<float> v(24 * 24 * 24, 0.0f);
  auto at = [&](int i, int j, int k) -> float& { return v[std::size_t(i + 24 * (j + 24 * k))]; };
  at(11, 11, 11) = 1.0f;  // both signs, so zero is not the range's end
  at(12, 11, 11) = -1.0f;
  const double window_top = 5e-5;
  const std::vector<TaskSpec> tasks{
      TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::relative_to(0, 1), window_top)};
  const camera::Camera cam({40, -30, 25}, {0, 0, 0}, {0, 0, 1}, 40, 96, 72);
  const FieldView view = FieldView::whole(g, v.data());
  auto lit_far_from_the_spike = [&](const std::vector<PreparedField>& fields) {
    std::vector<PartialImage> out(1);
    render_brick(cam, fields, tasks, out);
    const Image im = finish_image(out[0], cam, g, {0, 0, 0}, {false});
    // The spike projects near the image centre; count lit pixels outside a central disc.
    int lit = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const double dx = x - im.width / 2.0, dy = y - im.height / 2.0;
        if (dx * dx + dy * dy < 15.0 * 15.0) continue;
        const auto* p = im.at(x, y);
        if (p[0] + p[1] + p[2] > 6) ++lit;
      }
    return lit;
  };
  // The whole range in 16 bits (what every march read before): the box glows.
  EXPECT_GT(lit_far_from_the_spike({PreparedField(view)}), 1000);
  // As the in-situ session prepares it: nothing away from the spike.
  EXPECT_EQ(lit_far_from_the_spike(prepare_fields(std::span(&view, 1), tasks)), 0);
  const std::vector<QuantizationRange> keep = quantization_ranges(1, tasks);
  EXPECT_NEAR(keep[0].hi, window_top * 65, 1e-9);
  EXPECT_NEAR(keep[0].lo, -window_top * 65, 1e-9);
}

// The tiles' hand-out (tile_schedule.hpp): a row of tiles for few threads, smaller hand-outs when
// many threads share a small frame, never none.
TEST(TileSchedule, ARowOfTilesWhileEveryThreadGetsSixteen) {
  EXPECT_EQ(tile_chunk(58, 58 * 56, 2), 58);   // 920x896 in 16-pixel tiles, 2 threads
  EXPECT_EQ(tile_chunk(20, 20 * 20, 2), 12);   // 320x320: 400 tiles, 16 hand-outs per thread
  EXPECT_EQ(tile_chunk(58, 58 * 56, 64), 3);
  EXPECT_EQ(tile_chunk(4, 8, 64), 1);
  EXPECT_EQ(tile_chunk(1, 1, 0), 1);
}

// Each adaptive tile marches its own lattice, borders included (tiles are independent), so the tile
// edge sets how many rays a frame marches where nothing needs refining: a 128x128 frame from inside a
// transparent field marches 4 tiles x 17 x 17 lattice points with the default 64-pixel tiles, and
// 64 x 5 x 5 with 16-pixel tiles (56 % more than the stride's 32 x 32), which the anchor paid for.
TEST(Renderer, AdaptiveTilesMarchOnlyTheirLatticeWhereNothingChanges) {
  const GridGeometry grid{{24, 24, 24}, {0, 0, 0}, {1, 1, 1}};
  const std::vector<float> zero(std::size_t(24 * 24 * 24), 0.0f);
  const FieldView view = FieldView::whole(grid, zero.data());
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1.0))};
  const camera::Camera cam({12, 12, 12}, {30, 14, 11}, {0, 0, 1}, 60, 128, 128);  // inside: every ray meets the field
  const std::vector<PreparedField> fields{PreparedField(view)};
  RenderOptions opt;
  opt.adaptive = true;
  std::vector<PartialImage> out(1);
  RenderStats st = render_brick(cam, fields, tasks, out, opt);
  EXPECT_EQ(opt.adaptive_tile, 64);
  EXPECT_EQ(st.rays, 4u * 17 * 17);
  EXPECT_EQ(st.interpolated_pixels, 128u * 128 - st.rays);
  opt.adaptive_tile = 16;
  st = render_brick(cam, fields, tasks, out, opt);
  EXPECT_EQ(st.rays, 64u * 5 * 5);
  opt.adaptive_tile = 0;
  EXPECT_THROW(render_brick(cam, fields, tasks, out, opt), Error);
}

// Tiles are independent, so how the threads share them cannot change an image: a dense adaptive
// frame on one thread and on two (the OpenMP hand-out of tile_chunk()) has the same bits.
TEST(Renderer, TheImageDoesNotDependOnTheThreads) {
  const GridGeometry grid{{32, 48, 24}, {0, 0, 0}, {1, 1, 1}};
  const DenseWaveScene waves = dense_wave_scene(grid);
  const FieldView view = FieldView::whole(grid, waves.p.data());
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1.0))};
  const camera::Camera cam({70, -40, 50}, {16, 24, 12}, {0, 0, 1}, 30, 230, 224);  // 4 x 4 adaptive tiles
  RenderOptions opt;
  opt.adaptive = true;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::vector<PartialImage> one = render_whole(cam, view, tasks, opt);
  omp_set_num_threads(2);
  const std::vector<PartialImage> two = render_whole(cam, view, tasks, opt);
  omp_set_num_threads(threads);
  ASSERT_EQ(one[0].rgba.size(), two[0].rgba.size());
  EXPECT_EQ(one[0].rgba, two[0].rgba);
  EXPECT_EQ(one[0].depth, two[0].depth);
  double sum = 0;
  for (float v : one[0].rgba) sum += v;
  EXPECT_GT(sum, 100.0) << "the frame shows the field";
}
