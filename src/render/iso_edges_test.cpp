// Isosurface anti-aliasing (iso_edges.hpp): silhouettes against an analytic coverage, bricks still
// composite to the single-brick image, surfaces away from silhouettes are unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/image.hpp"
#include "core/png.hpp"
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
  // Steps up to 1 voxel: a hit lies up to a step outside its brick and what is read round it reaches
  // a voxel farther (required_points(); with one ghost layer less above, 5/255 off at step 0.5).
  for (const double step : {0.5, 1.0})
    for (const camera::Camera& cam : cams) {
      opt.sample_distance = step;
      const std::vector<Brick> one = {Brick::slab(grid, 0, 1, 0)};
      const std::vector<Image> ref = render_bricked(cam, views, tasks, one, opt);
      RenderOptions off;
      off.sample_distance = step;
      const std::vector<Image> plain = render_bricked(cam, views, tasks, one, off);
      EXPECT_GT(max_diff(ref[0], plain[0]), 8);  // anti-aliasing changed the silhouettes
      for (int axis = 0; axis < 3; ++axis)
        for (int n : {2, 3}) {
          std::vector<Brick> bricks;
          for (int i = 0; i < n; ++i) bricks.push_back(Brick::slab(grid, axis, n, i));
          const std::vector<Image> img = render_bricked(cam, views, tasks, bricks, opt);
          for (std::size_t t = 0; t < tasks.size(); ++t)
            EXPECT_LE(max_diff(img[t], ref[t]), 1) << "step " << step << ", axis " << axis << ", " << n << " bricks, task " << t;
        }
    }
}

TEST(IsoEdges, PixelPitchIsTheAngleBetweenNeighbouringRows) {
  const camera::Camera persp({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 90, 200, 100);
  EXPECT_NEAR(march::pixel_pitch(persp), 2.0 / 100, 1e-4);  // 2·tan(45°) / 100 rows at the centre
  const camera::Camera eq({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 90, 360, 180, camera::Projection::equirectangular);
  EXPECT_NEAR(march::pixel_pitch(eq), M_PI / 180, 1e-9);
}
namespace {

// Issue 41's scene: three Ricker fronts whose 0.3-isosurfaces are smooth shells meeting in creases.
struct ShellScene {
  GridGeometry grid{{48, 48, 48}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> f;
  ShellScene() {
    const WaveFront fronts[] = {{{20, 22, 24}, 13, 3, 1.0}, {{30, 26, 20}, 11, 2.5, 0.9}, {{24, 18, 30}, 8, 2, 0.8}};
    f = wave_field(grid, fronts);
  }
};

struct Frame {
  Image img;
  std::vector<float> cover;  // per pixel: the alpha (1x1) or the fraction of sub-pixels hit (supersampled)
};

Frame render_iso(const camera::Camera& cam, const ShellScene& sc, const RenderOptions& opt) {
  std::vector<PreparedField> fields;
  fields.emplace_back(FieldView::whole(sc.grid, sc.f.data()));
  const std::vector<TaskSpec> tasks = {TaskSpec::isosurface(0, 0.3f, {0.9f, 0.8f, 0.6f})};
  std::vector<PartialImage> out(1);
  render_brick(cam, fields, tasks, out, opt);
  Frame fr{finish_image(out[0], cam, sc.grid, {0, 0, 0}, OutlineStyle{false}), {}};
  fr.cover.assign(std::size_t(cam.width()) * std::size_t(cam.height()), 0.0f);
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x)
      if (out[0].rect.contains(x, y)) fr.cover[std::size_t(y) * std::size_t(cam.width()) + std::size_t(x)] = out[0].rgba_at(x, y)[3];
  return fr;
}

// The box-filtered S×S supersampled frame.
Frame downsample(const Frame& big, int S) {
  Frame r{Image(big.img.width / S, big.img.height / S), {}};
  r.cover.assign(std::size_t(r.img.width) * std::size_t(r.img.height), 0.0f);
  for (int y = 0; y < r.img.height; ++y)
    for (int x = 0; x < r.img.width; ++x) {
      int sum[4] = {0, 0, 0, 0}, hit = 0;
      for (int j = 0; j < S; ++j)
        for (int i = 0; i < S; ++i) {
          const std::uint8_t* p = big.img.at(x * S + i, y * S + j);
          for (int c = 0; c < 4; ++c) sum[c] += p[c];
          hit += big.cover[std::size_t(y * S + j) * std::size_t(big.img.width) + std::size_t(x * S + i)] > 0.5f;
        }
      for (int c = 0; c < 4; ++c) r.img.at(x, y)[c] = std::uint8_t((sum[c] + S * S / 2) / (S * S));
      r.cover[std::size_t(y) * std::size_t(r.img.width) + std::size_t(x)] = float(hit) / float(S * S);
    }
  return r;
}

// Speckles: surface pixels (some sub-pixel of the reference hits the surface) whose colour lies more
// than 30 levels outside the range the reference takes over the pixel and its 8 neighbours in some
// channel. An edge pixel whose coverage is somewhat off stays within that range; a ray that sees
// through the surface to the black background or to a sheet behind it does not.
int speckles(const Frame& img, const Frame& ref, const char* tag = nullptr) {
  int n = 0;
  for (int y = 0; y < img.img.height; ++y)
    for (int x = 0; x < img.img.width; ++x) {
      if (!(ref.cover[std::size_t(y) * std::size_t(img.img.width) + std::size_t(x)] > 0)) continue;
      bool off = false;
      for (int c = 0; c < 3 && !off; ++c) {
        int lo = 255, hi = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int v = ref.img.at(std::clamp(x + dx, 0, img.img.width - 1), std::clamp(y + dy, 0, img.img.height - 1))[c];
            lo = std::min(lo, v), hi = std::max(hi, v);
          }
        const int v = img.img.at(x, y)[c];
        off = v < lo - 30 || v > hi + 30;
        // PANOPTES_ISO_SPECKLES=1 lists the speckles and the pixels within 10 levels of being one.
        if (tag && (v < lo - 20 || v > hi + 20) && std::getenv("PANOPTES_ISO_SPECKLES"))
          std::printf("%s %s (%d, %d) channel %d: %d, reference %d..%d\n", off ? "speckle" : "near", tag, x, y, c, v, lo, hi);
      }
      n += off;
    }
  return n;
}

}  // namespace

// A grazing sliver's entry and exit may lie in two bricks: the exit adds nothing only because the
// entry came before it on the ray. Each brick returns its colour with and without a sliver open at
// its front (PartialImage::slivers) and compositing picks, so slabs along every axis composite to the
// single-brick image within 1/255 on issue 41's shells, from outside and inside, and the choice is
// really made (some brick's two colours differ at some pixel).
TEST(IsoEdges, SliverStateCrossesBricks) {
  const ShellScene sc;
  const std::vector<FieldView> views = {FieldView::whole(sc.grid, sc.f.data())};
  const std::vector<TaskSpec> tasks = {TaskSpec::isosurface(0, 0.3f, {0.9f, 0.8f, 0.6f})};
  const camera::Rig rig =
      camera::make_rig("yinyang", camera::Domain{sc.grid.domain_lo(), sc.grid.domain_hi() - sc.grid.domain_lo()});
  RenderOptions opt;
  opt.iso_antialias = true;
  opt.equirect_adaptive = false;
  const camera::Camera cams[] = {rig.camera(35, 96, 96), rig.camera(80, 96, 96),
                                 camera::Camera({30, 30, 38}, {40, 24, 24}, {0, 0, 1}, 60, 128, 64,
                                                camera::Projection::equirectangular)};
  int chosen = 0;
  for (const camera::Camera& cam : cams) {
    const std::vector<Brick> one = {Brick::slab(sc.grid, 0, 1, 0)};
    const std::vector<Image> ref = render_bricked(cam, views, tasks, one, opt);
    for (int axis = 0; axis < 3; ++axis)
      for (int n : {2, 3}) {
        std::vector<Brick> bricks;
        for (int i = 0; i < n; ++i) bricks.push_back(Brick::slab(sc.grid, axis, n, i));
        EXPECT_LE(max_diff(render_bricked(cam, views, tasks, bricks, opt)[0], ref[0]), 1) << "axis " << axis << ", " << n;
        for (const Brick& b : bricks) {
          std::vector<PreparedField> fields;
          fields.emplace_back(views[0].subview(b));
          std::vector<PartialImage> out(1);
          render_brick(cam, fields, tasks, out, opt);
          ASSERT_TRUE(out[0].slivers);
          for (std::size_t p = 0; p < out[0].depth.size(); ++p)
            chosen += out[0].rgba[4 * p + 3] != out[0].rgba_open[4 * p + 3];
        }
      }
  }
  EXPECT_GT(chosen, 0);
  std::printf("pixels whose colour depends on the sliver state in front: %d\n", chosen);
}

// Issue 41: with anti-aliasing, a smooth isosurface got dark and light speckles and, from inside,
// cracks where two sheets meet: rays that crossed a surface where the field's own curvature bent the
// three-sample parabola back were taken for one end of a grazing sliver (an exit got no coverage and
// showed what lay behind it). Against the box-filtered 4×4 supersampled frame with anti-aliasing off
// (sample distance 0.125 voxel). Outside (every 5th camera of the 130-camera rig) and inside (360°
// frames from three points in the domain). The bend of the surface itself decides, and an exit adds
// nothing only when its entry came before it on the ray, in this brick or one in front (the sliver
// state, PartialImage::slivers). What that left (11 outside, 2 inside) were not surfaces the march
// steps over but one shading sample against the reference's 16 — grazing rims, creases and highlights
// narrower than a pixel. The shading filtered over the pixel footprint (shade_hit_footprint(), and
// shade_near_miss_footprint() for near misses at a rim) takes them all: sub-rays on a patch of the
// renderer's own gradient field, each moved onto the surface by a Newton step along itself, read
// within a voxel of the hit (one more ghost layer above a brick than before: required_points()).
// Anti-aliasing off keeps its 9 and 2.
TEST(IsoEdges, SpecklesAgainstTheSupersampledSurface) {
  const ShellScene sc;
  const camera::Rig rig =
      camera::make_rig("yinyang", camera::Domain{sc.grid.domain_lo(), sc.grid.domain_hi() - sc.grid.domain_lo()});
  constexpr int S = 4;
  RenderOptions on, off, ref;
  on.iso_antialias = true;
  on.equirect_adaptive = off.equirect_adaptive = ref.equirect_adaptive = false;  // every pixel marched
  ref.sample_distance = 0.125;
  struct View {
    camera::Camera cam, big;
  };
  std::vector<View> outside, inside;
  for (int c = 0; c < 130; c += 5) outside.push_back({rig.camera(c, 96, 96), rig.camera(c, 96 * S, 96 * S)});
  for (const Vec3 eye : {Vec3{30, 30, 38}, Vec3{8, 40, 24}, Vec3{6, 6, 6}}) {
    const auto eq = camera::Projection::equirectangular;
    inside.push_back({camera::Camera(eye, {40, 24, 24}, {0, 0, 1}, 60, 256, 128, eq),
                      camera::Camera(eye, {40, 24, 24}, {0, 0, 1}, 60, 256 * S, 128 * S, eq)});
  }
  for (const auto* views : {&outside, &inside}) {
    const char* where = views == &outside ? "outside" : "inside";
    int n_on = 0, n_off = 0;
    double se_on = 0, se_off = 0, count = 0;
    for (std::size_t vi = 0; vi < views->size(); ++vi) {
      const View& v = (*views)[vi];
      const Frame a = render_iso(v.cam, sc, on), b = render_iso(v.cam, sc, off);
      const Frame r = downsample(render_iso(v.big, sc, ref), S);
      const std::string tag_on = std::string(where) + " view " + std::to_string(vi) + " on",
                        tag_off = std::string(where) + " view " + std::to_string(vi) + " off";
      if (const char* dir = std::getenv("PANOPTES_ISO_FRAMES")) {  // the frames docs/rendering.md's crops are cut from
        const std::string stem = std::string(dir) + "/" + where + std::to_string(vi);
        write_png(stem + "_on.png", a.img);
        write_png(stem + "_off.png", b.img);
        write_png(stem + "_ref.png", r.img);
      }
      n_on += speckles(a, r, tag_on.c_str());
      n_off += speckles(b, r, tag_off.c_str());
      for (std::size_t i = 0; i < a.img.pixels.size(); ++i) {
        if (i % 4 == 3) continue;
        const double d1 = double(a.img.pixels[i]) - r.img.pixels[i], d2 = double(b.img.pixels[i]) - r.img.pixels[i];
        se_on += d1 * d1, se_off += d2 * d2, count += 1;
      }
    }
    const double db_on = 10 * std::log10(255.0 * 255.0 * count / se_on), db_off = 10 * std::log10(255.0 * 255.0 * count / se_off);
    std::printf("%s (%zu views): speckles with anti-aliasing %d, without %d; PSNR against the supersampled frames %.3f dB "
                "with, %.3f dB without\n",
                where, views->size(), n_on, n_off, db_on, db_off);
    RecordProperty(std::string(where) + "_speckles_on_off", std::to_string(n_on) + " " + std::to_string(n_off));
    // Measured (without anti-aliasing 9 outside, 2 inside; 43.6 and 47.0 dB): before issue 41 121 and
    // 89 speckles, 39.5 and 40.4 dB; with exits checked for their entry within the ghost layers
    // (issue 43) 51 and 12, 42.5 and 45.7 dB; with the sliver state carried across bricks 11 and 2,
    // 46.15 and 49.20 dB; with the shading filtered over the footprint from field values within half
    // a voxel 5 and 1, 46.23 and 49.26 dB; from the gradient field within a voxel, sub-rays moved onto
    // the surface, near misses at rims filtered: 0 and 0, 46.95 and 50.07 dB (PANOPTES_ISO_SPECKLES=1
    // lists them and the pixels within 10 levels of being one: camera 105's (44, 35) lies exactly 30
    // above the reference's range, a near sheet in front covering a fifth of the pixel whose |f − iso|
    // has no minimum at the 0.5-voxel step). Issue 41 asks for none.
    EXPECT_EQ(n_on, 0) << where;
    EXPECT_GE(db_on, views == &outside ? 46.9 : 50.0) << where;
  }
}
