// Grid descriptions, their validation and the resampling adapter: exact on fields the interpolation
// reproduces, and rendered images of an analytic shell field on every grid kind against the same
// field sampled directly on the uniform grid (PSNR ≥ 40 dB), Yin-Yang against a plain spherical
// grid, and no seam where the Yin-Yang rule switches patch.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "core/image.hpp"
#include "grid/grid_description.hpp"
#include "grid/resampler.hpp"
#include "grid/sample.hpp"
#include "render/renderer.hpp"

namespace panoptes::grid {
namespace {

constexpr double kPi = std::numbers::pi;

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[std::size_t(i)] = a + (b - a) * i / (n - 1);
  return v;
}
// Coordinates crowded towards both ends (as boundary layers are resolved in CFD codes).
std::vector<double> stretched(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = -1 + 2.0 * i / (n - 1);
    v[std::size_t(i)] = a + (b - a) * 0.5 * (1 + std::tanh(1.2 * s) / std::tanh(1.2));
  }
  return v;
}
// A full sphere: longitudes [0, 2π) and cell-centred colatitudes (no point on the poles).
GridDescription full_sphere(int nr, int nt, int np, double ri = 0.35, double ro = 1.0) {
  std::vector<double> t(static_cast<std::size_t>(nt)), p(static_cast<std::size_t>(np));
  for (int j = 0; j < nt; ++j) t[std::size_t(j)] = (j + 0.5) * kPi / nt;
  for (int k = 0; k < np; ++k) p[std::size_t(k)] = k * 2 * kPi / np;
  return GridDescription::spherical(linspace(ri, ro, nr), t, p);
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The grid resampled onto `target` (whole), from a field given as a function of position.
std::vector<float> resampled(const GridDescription& g, const render::GridGeometry& target,
                             const std::function<double(const Vec3&)>& f, float outside = 0) {
  const Resampler rs(g, target, {{0, 0, 0}, target.dims}, outside);
  std::vector<std::vector<float>> data;
  std::vector<SourceBlock> blocks;
  for (int p = 0; p < g.patches(); ++p) data.push_back(sample(g, p, f));
  for (int p = 0; p < g.patches(); ++p) blocks.push_back(SourceBlock::whole(g, p, data[std::size_t(p)].data()));
  std::vector<float> out(std::size_t(rs.size()));
  rs.resample(blocks, out);
  return out;
}

// Images of a field on a uniform grid from cameras around and inside the shell: a volume
// rendering (p-wave preset on |v|) and a slice through the centre.
std::vector<Image> render_views(const render::GridGeometry& g, const std::vector<float>& v) {
  using namespace render;
  const FieldView view = FieldView::whole(g, v.data());
  const std::vector<TaskSpec> tasks{
      TaskSpec::volume(0, TransferFunction::preset("p-wave", 4.0f), ValueWindow::absolute(0, 1.2)),
      TaskSpec::slice(0, 2, 0.1, TransferFunction::preset("diverging"), ValueWindow::absolute(-1.2, 1.2))};
  const std::vector<FieldView> views{view};
  const std::vector<PreparedField> fields = prepare_fields(views, tasks);
  std::vector<Image> images;
  const Vec3 eyes[] = {{0, -3.2, 0.8}, {2.2, 1.7, 1.5}, {0.3, 0.2, 3.1}, {0.62, 0.1, 0.05}};
  for (const Vec3& eye : eyes) {
    const camera::Camera cam(eye, {0, 0, 0}, {0, 0, 1}, eye.x == 0.62 ? 80 : 40, 96, 96);
    std::vector<PartialImage> parts(tasks.size());
    render_brick(cam, fields, tasks, parts);
    for (const PartialImage& p : parts) images.push_back(finish_image(p, cam, g, {0.1f, 0.1f, 0.15f}, {false}));
  }
  return images;
}

double min_psnr(const std::vector<Image>& a, const std::vector<Image>& b) {
  double m = 1e9;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::min(m, psnr(a[i], b[i]));
  return m;
}

TEST(GridDescription, ValidationNamesTheProblem) {
  EXPECT_NE(error_of([] { GridDescription::rectilinear({0, 1, 1, 2}, {0, 1}, {0, 1}).validate(); })
                .find("x coordinates are not strictly increasing: x[1] = 1, x[2] = 1"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::rectilinear({0, 1}, {0, NAN}, {0, 1}).validate(); }).find("y[1] is not finite"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::rectilinear({0}, {0, 1}, {0, 1}).validate(); }).find("1 x coordinates"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::spherical({-0.1, 1}, {0, 1}, {0, 1}).validate(); }).find("radius >= 0"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::spherical({0.5, 1}, {0, 3.5}, {0, 1}).validate(); }).find("[0, pi]"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::spherical({0.5, 1}, {0, 1}, {0, 7}).validate(); }).find("at most 2 pi"),
            std::string::npos);
  // A Yin-Yang patch too narrow in θ leaves a gap; one reaching the poles is not a low-latitude patch.
  EXPECT_NE(error_of([] { GridDescription::yinyang({0.5, 1}, linspace(0.9, 2.3, 20), linspace(-2.4, 2.4, 40)).validate(); })
                .find("leave a gap"),
            std::string::npos);
  EXPECT_NE(error_of([] { GridDescription::yinyang({0.5, 1}, linspace(0, 2.5, 20), linspace(-2.4, 2.4, 40)).validate(); })
                .find("low-latitude"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_grid_kind("curvilinear"); }).find("expected uniform, rectilinear, spherical or yinyang"),
            std::string::npos);
  EXPECT_NO_THROW(GridDescription::yinyang_standard(linspace(0.35, 1, 8), 20, 56).validate());
  EXPECT_EQ(parse_grid_kind("yinyang"), GridKind::yinyang);
}

TEST(GridDescription, BoundsOfShellsAndSectors) {
  const GridDescription full = full_sphere(4, 8, 16);
  EXPECT_TRUE(full.phi_periodic());
  const Vec3 lo = full.bounds_lo(), hi = full.bounds_hi();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], -1, 1e-3);
    EXPECT_NEAR(hi[a], 1, 1e-3);
  }
  // The octant x, y, z ≥ 0 of a shell of radii [0.5, 1].
  const GridDescription octant = GridDescription::spherical({0.5, 1}, linspace(0, kPi / 2, 5), linspace(0, kPi / 2, 5));
  EXPECT_FALSE(octant.phi_periodic());
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(octant.bounds_lo()[a], 0, 1e-3);
    EXPECT_NEAR(octant.bounds_hi()[a], 1, 1e-3);
  }
  const render::GridGeometry cover = uniform_cover(full, 41);
  EXPECT_EQ(cover.dims, (render::Index3{41, 41, 41}));
  EXPECT_NEAR(cover.spacing.x, 0.05, 1e-3);
}

TEST(Resampler, ReproducesWhatTrilinearInterpolationReproduces) {
  // On a stretched box, a field linear in each coordinate is reproduced exactly.
  const GridDescription box = GridDescription::rectilinear(stretched(-1, 2, 17), stretched(0, 1, 9), linspace(-1, 1, 5));
  const render::GridGeometry target = uniform_cover(box, 40);
  auto f = [](const Vec3& p) { return 1 + 2 * p.x - p.y + 0.5 * p.z + p.x * p.y * p.z; };
  const std::vector<float> v = resampled(box, target, f);
  const std::vector<float> want = sample(target, [&](const Vec3& p) {
    // The cover reaches slightly beyond the box: those points take the face's value.
    Vec3 q = p;
    for (int a = 0; a < 3; ++a) q[a] = std::clamp(q[a], box.bounds_lo()[a], box.bounds_hi()[a]);
    return f(q);
  });
  double err = 0;
  for (std::size_t i = 0; i < v.size(); ++i) err = std::max(err, double(std::fabs(v[i] - want[i])));
  EXPECT_LT(err, 2e-4);
  // On a shell, a field depending on r only (linearly) is reproduced exactly; the core and the
  // outside take the fill value.
  const GridDescription shell = full_sphere(9, 12, 24, 0.4, 1.0);
  const render::GridGeometry t2 = uniform_cover(shell, 33);
  const Resampler rs(shell, t2, {{0, 0, 0}, t2.dims}, -7.0f);
  const std::vector<float> src = sample(shell, 0, [](const Vec3& p) { return 3 * norm(p); });
  std::vector<float> out(std::size_t(rs.size()));
  const SourceBlock blocks[] = {SourceBlock::whole(shell, 0, src.data())};
  rs.resample(blocks, out);
  const std::vector<float> r = sample(t2, [](const Vec3& p) { return norm(p); });
  std::int64_t outside = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (r[i] < 0.4 || r[i] > 1.0) {
      EXPECT_EQ(out[i], -7.0f) << "r = " << r[i];
      ++outside;
    } else {
      EXPECT_NEAR(out[i], 3 * r[i], 2e-4);
    }
  }
  EXPECT_EQ(outside, rs.outside_points());
}

TEST(Resampler, RefusesBlocksThatDoNotCoverThePlan) {
  const GridDescription shell = full_sphere(5, 8, 16);
  const render::GridGeometry t = uniform_cover(shell, 17);
  const Resampler rs(shell, t, {{0, 0, 0}, t.dims});
  std::vector<float> half(std::size_t(5 * 8 * 8)), out(std::size_t(rs.size()));
  const SourceBlock blocks[] = {SourceBlock::of(0, {{0, 0, 0}, {5, 8, 8}}, half.data())};
  EXPECT_NE(error_of([&] { rs.resample(blocks, out); }).find("no source block of patch 0 covers points (0, 0, 0)-(5, 8, 16)"),
            std::string::npos);
  std::vector<float> short_out(3);
  EXPECT_NE(error_of([&] { rs.resample(blocks, short_out); }).find("output of 3 values"), std::string::npos);
  EXPECT_THROW(Resampler(shell, t, {{0, 0, 0}, {18, 17, 17}}), Error);
}

// The analytic shell field on each grid kind renders like the same field sampled on the uniform grid.
class RenderedLikeTheFineGrid : public ::testing::TestWithParam<GridKind> {};

TEST_P(RenderedLikeTheFineGrid, Psnr40) {
  for (double time : {0.0, 1.3}) {
    const ShellField field{0.35, 1.0, time};
    GridDescription g;
    switch (GetParam()) {
      case GridKind::uniform: g = GridDescription::make_uniform(uniform_cover(full_sphere(2, 16, 32), 49)); break;
      case GridKind::rectilinear:
        g = GridDescription::rectilinear(stretched(-1, 1, 56), stretched(-1, 1, 56), stretched(-1, 1, 56));
        break;
      case GridKind::spherical: g = full_sphere(24, 64, 128); break;
      case GridKind::yinyang: g = GridDescription::yinyang_standard(linspace(0.35, 1, 24), 34, 98); break;
    }
    const render::GridGeometry target = uniform_cover(GridDescription::spherical({0.35, 1}, {0.1, 3}, {0, 6}), 81);
    const std::vector<float> reference = sample(target, field);
    const std::vector<float> adapted = resampled(g, target, field);
    const double db = min_psnr(render_views(target, reference), render_views(target, adapted));
    RecordProperty("min_psnr_db", std::to_string(db));
    std::printf("%s t=%.1f: min PSNR over 8 images %.1f dB\n", std::string(to_string(GetParam())).c_str(), time, db);
    EXPECT_GE(db, 40.0);
  }
}
INSTANTIATE_TEST_SUITE_P(Kinds, RenderedLikeTheFineGrid,
                         ::testing::Values(GridKind::uniform, GridKind::rectilinear, GridKind::spherical, GridKind::yinyang),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(YinYang, EqualsThePlainSphericalGridWhereBothAreDefined) {
  const ShellField field{0.35, 1.0, 0.7};
  // yinyang_standard(…, 34, 98) spaces colatitudes by π/58 and longitudes by 2π/124, from
  // π/4 − 2·π/58 and −3π/4 − 2·2π/124: the plain spherical grid below (cell-centred colatitudes,
  // 124 longitudes from −π + π/124) holds every Yin point, Yin's index (j, k) at (j + 12, k + 13).
  const GridDescription yy = GridDescription::yinyang_standard(linspace(0.35, 1, 24), 34, 98);
  const double dt = kPi / 58, dp = 2 * kPi / 124;
  std::vector<double> t, p;
  for (int j = 0; j < 58; ++j) t.push_back((j + 0.5) * dt);
  for (int k = 0; k < 124; ++k) p.push_back(-kPi + (k + 0.5) * dp);
  for (int j = 0; j < 34; ++j) ASSERT_NEAR(yy.coords[1][std::size_t(j)], t[std::size_t(j) + 12], 1e-12);
  for (int k = 0; k < 98; ++k) ASSERT_NEAR(yy.coords[2][std::size_t(k)], p[std::size_t(k) + 13], 1e-12);
  const GridDescription sp = GridDescription::spherical(linspace(0.35, 1, 24), t, p);
  const render::GridGeometry target = uniform_cover(yy, 65);
  const Resampler rs(yy, target, {{0, 0, 0}, target.dims});
  const std::vector<float> a = resampled(yy, target, field, -9), b = resampled(sp, target, field, -9);
  double yin = 0, yang = 0;
  std::int64_t yin_points = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i] == -9, b[i] == -9) << "one grid covers point " << i << " and the other does not";
    if (a[i] == -9) continue;
    const double d = std::fabs(a[i] - b[i]);
    if (rs.patch_at(std::int64_t(i)) == 0) {
      yin = std::max(yin, d);
      ++yin_points;
    } else {
      yang = std::max(yang, d);
    }
  }
  std::printf("yinyang vs spherical: %lld points read Yin, max |difference| there %.2g; on Yang's %.4f "
              "(interpolation error of two grids; field range about [-2, 2])\n",
              (long long)yin_points, yin, yang);
  EXPECT_GT(yin_points, 50000);
  EXPECT_LT(yin, 1e-4);  // the same stencils (up to the coordinates' last bits)
  EXPECT_LT(yang, 0.1);
  const double db =
      min_psnr(render_views(target, resampled(yy, target, field)), render_views(target, resampled(sp, target, field)));
  std::printf("yinyang vs spherical rendered: min PSNR %.1f dB\n", db);
  EXPECT_GE(db, 40.0);
}

TEST(YinYang, NoSeamWherePatchesSwitch) {
  // Along every x row of the uniform grid, the step between neighbours differs from the field's own
  // step by the interpolation error; a seam would make it larger where the neighbours read
  // different patches than where they read the same one.
  const ShellField field{0.35, 1.0, 0.4};
  const GridDescription yy = GridDescription::yinyang_standard(linspace(0.35, 1, 24), 34, 98);
  const render::GridGeometry target = uniform_cover(yy, 97);
  const Resampler rs(yy, target, {{0, 0, 0}, target.dims});
  const std::vector<float> v = resampled(yy, target, field);
  const std::vector<float> exact = sample(target, field);
  double across = 0, within = 0;
  std::int64_t switches = 0, yang = 0;
  const int nx = target.dims[0];
  for (std::int64_t q = 0; q + 1 < rs.size(); ++q) {
    if ((q + 1) % nx == 0) continue;
    const int pa = rs.patch_at(q), pb = rs.patch_at(q + 1);
    yang += pa == 1;
    if (pa < 0 || pb < 0) continue;
    const double e = std::fabs(double(v[std::size_t(q) + 1] - v[std::size_t(q)]) - (exact[std::size_t(q) + 1] - exact[std::size_t(q)]));
    if (pa != pb) {
      across = std::max(across, e);
      ++switches;
    } else {
      within = std::max(within, e);
    }
  }
  std::printf("yinyang seam: %lld switching pairs, step error across %.5f, within a patch %.5f\n", (long long)switches,
              across, within);
  EXPECT_GT(switches, 1000);
  EXPECT_GT(yang, 100000);
  EXPECT_LE(across, within);
}

}  // namespace
}  // namespace panoptes::grid
