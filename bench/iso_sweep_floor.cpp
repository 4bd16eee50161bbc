// Issue 10, round 7: how far below "8 isosurfaces cost 2x one" a first-hit ray caster can go on the
// dense scene, whatever it does per sample. Not a *_bench program: a measurement of sample COUNTS,
// not of time, so it does not depend on the machine's load and scripts/bench does not run it.
//
//   iso_sweep_floor [--stride N] [--step D]
//
// The scene, isovalues and cameras of BM_ManyImages/mix:2: render::dense_wave_scene on 256x512x160,
// p's isosurfaces at 0.2 ... 0.9 x its 99.9th percentile of |p| against the 0.2 one alone, Yin-Yang
// cameras 12 and 77 at 920x896 (every N-th pixel per axis, default 4), samples every D voxels
// (default 0.5, the library's default) from where the ray enters the domain. Per ray it finds every
// surface's first crossing (a sign change of value - isovalue between consecutive samples, as the
// renderer tests it) and counts the samples a march must evaluate to find them:
//   - macro-cells of M^3 cells (M = 8, the renderer's, and 4, 2, 1): a sample is needed if the
//     macro-cell it lies in (min/max with the renderer's one-point margin) contains the isovalue of a
//     surface not hit yet; the 8-surface march needs the union over its pending surfaces;
//   - the same at M = 8 plus value-based skipping: after an evaluated sample with value v the next
//     n samples are skipped while n * L < min |v - isovalue| over the pending surfaces, where L
//     bounds the change of the trilinear field per sample step (largest |difference| of adjacent
//     points along each axis in the macro-cell and its 26 neighbours, times the step's components).
// A march's time is at least proportional to the samples it evaluates (each is a trilinear
// interpolation from a field far larger than the caches), so K/one of the counts is the floor of
// the benchmark's K_over_one for that scheme, before the 8 images' extra hits are shaded.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "render/field_view.hpp"
#include "render/macro_cells.hpp"
#include "render/synthetic_fields.hpp"
#include "render/transfer_function.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

constexpr int kSurfaces = 8;
constexpr int kWidth = 920, kHeight = 896;
const GridGeometry kGrid{{256, 512, 160}, {0, 0, 0}, {1, 1, 1}};  // BM_ManyImages' grid (spacing 1)

struct Field {
  const float* v;
  int nx, ny, nz;
  float at(int i, int j, int k) const { return v[(std::size_t(k) * ny + j) * nx + i]; }
  // Trilinear at an index-space position, cell clamped into the data (as the renderer's interp).
  float operator()(double x, double y, double z) const {
    x = std::clamp(x, 0.0, double(nx - 1)), y = std::clamp(y, 0.0, double(ny - 1)), z = std::clamp(z, 0.0, double(nz - 1));
    const int i = std::min(int(x), nx - 2), j = std::min(int(y), ny - 2), k = std::min(int(z), nz - 2);
    const float fx = float(x - i), fy = float(y - j), fz = float(z - k);
    auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
    const float c00 = lerp(at(i, j, k), at(i + 1, j, k), fx), c10 = lerp(at(i, j + 1, k), at(i + 1, j + 1, k), fx);
    const float c01 = lerp(at(i, j, k + 1), at(i + 1, j, k + 1), fx), c11 = lerp(at(i, j + 1, k + 1), at(i + 1, j + 1, k + 1), fx);
    return lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz);
  }
};

// Per macro-cell of size M: the largest |difference| of adjacent points along each axis over the
// cell's points with the one-point margin, then the largest over the cell and its 26 neighbours.
std::vector<float> slope_bounds(const Field& f, const MacroCells& mc) {
  const int M = mc.size();
  const Index3 c = mc.counts();
  std::vector<float> own(3 * std::size_t(mc.total()), 0.0f), out(own.size(), 0.0f);
#pragma omp parallel for schedule(dynamic, 1)
  for (int mz = 0; mz < c[2]; ++mz)
    for (int my = 0; my < c[1]; ++my)
      for (int mx = 0; mx < c[0]; ++mx) {
        const int m[3] = {mx, my, mz}, n[3] = {f.nx, f.ny, f.nz};
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) lo[a] = std::max(0, m[a] * M - 1), hi[a] = std::min(n[a] - 1, (m[a] + 1) * M + 1);
        float g[3] = {0, 0, 0};
        for (int k = lo[2]; k <= hi[2]; ++k)
          for (int j = lo[1]; j <= hi[1]; ++j)
            for (int i = lo[0]; i <= hi[0]; ++i) {
              const float v = f.at(i, j, k);
              if (i < hi[0]) g[0] = std::max(g[0], std::abs(f.at(i + 1, j, k) - v));
              if (j < hi[1]) g[1] = std::max(g[1], std::abs(f.at(i, j + 1, k) - v));
              if (k < hi[2]) g[2] = std::max(g[2], std::abs(f.at(i, j, k + 1) - v));
            }
        for (int a = 0; a < 3; ++a) own[3 * std::size_t(mc.linear(mx, my, mz)) + std::size_t(a)] = g[a];
      }
  for (int mz = 0; mz < c[2]; ++mz)
    for (int my = 0; my < c[1]; ++my)
      for (int mx = 0; mx < c[0]; ++mx)
        for (int z = std::max(0, mz - 1); z <= std::min(c[2] - 1, mz + 1); ++z)
          for (int y = std::max(0, my - 1); y <= std::min(c[1] - 1, my + 1); ++y)
            for (int x = std::max(0, mx - 1); x <= std::min(c[0] - 1, mx + 1); ++x)
              for (int a = 0; a < 3; ++a) {
                float& o = out[3 * std::size_t(mc.linear(mx, my, mz)) + std::size_t(a)];
                o = std::max(o, own[3 * std::size_t(mc.linear(x, y, z)) + std::size_t(a)]);
              }
  return out;
}

struct Counts {
  double one = 0, many = 0, separate = 0;
};

int usage(const char* argv0, int code) {
  std::fprintf(code ? stderr : stdout,
               "usage: %s [--stride N] [--step D]\n"
               "  Counts the samples a first-hit ray caster needs for the 8-isosurface sweep of\n"
               "  BM_ManyImages/mix:2 and for its 0.2 surface alone, per skipping scheme (see the\n"
               "  comment at the top of bench/iso_sweep_floor.cpp). --stride: every N-th pixel per\n"
               "  axis (default 4); --step: sample distance in voxels (default 0.5).\n",
               argv0);
  return code;
}

}  // namespace

int main(int argc, char** argv) try {
  int stride = 4;
  double step = 0.5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage(argv[0], 0);
    if ((a == "--stride" || a == "--step") && i + 1 < argc) {
      char* end = nullptr;
      const double v = std::strtod(argv[++i], &end);
      if (!end || *end || !(v > 0) || (a == "--stride" && (v != std::floor(v) || v > 64)) || (a == "--step" && v > 16))
        throw Error(a + " " + argv[i] +
                    "; expected a whole number 1..64 (--stride) or 0 < D <= 16 (--step)");
      (a == "--stride" ? void(stride = int(v)) : void(step = v));
      continue;
    }
    std::fprintf(stderr, "iso_sweep_floor: unknown argument '%s'\n", a.c_str());
    return usage(argv[0], 2);
  }

  std::fprintf(stderr, "building the dense scene (256x512x160) ...\n");
  const DenseWaveScene scene = dense_wave_scene(kGrid);
  const FieldView view = FieldView::whole(kGrid, scene.p.data());
  const Field f{scene.p.data(), kGrid.dims[0], kGrid.dims[1], kGrid.dims[2]};
  const double ref = abs_percentile(view, 0.999);
  double iso[kSurfaces];
  for (int j = 0; j < kSurfaces; ++j) iso[j] = 0.1 * ref * (2 + j);
  const int sizes[] = {8, 4, 2, 1};
  std::vector<MacroCells> cells;
  for (int M : sizes) cells.emplace_back(view, M);
  const std::vector<float> slopes = slope_bounds(f, cells[0]);

  const camera::Domain domain{kGrid.domain_lo(), kGrid.domain_hi() - kGrid.domain_lo()};
  const camera::Rig rig = camera::make_rig("yinyang", domain);
  constexpr int kSchemes = 6;  // macro-cells 8, 4, 2, 1; macro-cells 8 + value-based skipping; value-based only
  Counts total[kSchemes];
  double rays = 0, hits = 0;
  for (int cam_id : {12, 77}) {
    const camera::Camera cam = rig.camera(cam_id, kWidth, kHeight);
    const int cols = (kWidth + stride - 1) / stride, rows = (kHeight + stride - 1) / stride;
#pragma omp parallel
    {
      Counts local[kSchemes];
      double lrays = 0, lhits = 0;
      std::vector<float> v;
      std::vector<int> cell[4];
#pragma omp for schedule(dynamic, 16)
      for (int r = 0; r < cols * rows; ++r) {
        const camera::Ray ray = cam.ray((r % cols) * stride + 0.5, (r / cols) * stride + 0.5);
        double t0 = 0, t1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
          const double hi = kGrid.dims[a] - 1;
          if (ray.direction[a] == 0) {
            if (ray.origin[a] < 0 || ray.origin[a] > hi) t0 = INFINITY;
            continue;
          }
          double u0 = (0 - ray.origin[a]) / ray.direction[a], u1 = (hi - ray.origin[a]) / ray.direction[a];
          if (u0 > u1) std::swap(u0, u1);
          t0 = std::max(t0, u0), t1 = std::min(t1, u1);
        }
        if (!(t0 < t1)) continue;
        const int n = int(std::floor((t1 - t0) / step)) + 1;
        v.resize(std::size_t(n));
        for (auto& c : cell) c.resize(std::size_t(n));
        std::vector<double> px(std::size_t(n)), py(std::size_t(n)), pz(std::size_t(n));
        for (int k = 0; k < n; ++k) {
          const double t = t0 + k * step;
          const double p[3] = {ray.origin[0] + t * ray.direction[0], ray.origin[1] + t * ray.direction[1],
                               ray.origin[2] + t * ray.direction[2]};
          v[std::size_t(k)] = f(p[0], p[1], p[2]);
          for (int s = 0; s < 4; ++s) {
            const MacroCells& mc = cells[std::size_t(s)];
            int m[3];
            for (int a = 0; a < 3; ++a) m[a] = std::clamp(int(std::floor(p[a] / mc.size())), 0, mc.counts()[a] - 1);
            cell[s][std::size_t(k)] = mc.linear(m[0], m[1], m[2]);
          }
        }
        int hit[kSurfaces];  // index of the sample that detects the first crossing, n if none
        for (int j = 0; j < kSurfaces; ++j) {
          hit[j] = n;
          for (int k = 1; k < n; ++k)
            if ((v[std::size_t(k)] - iso[j] < 0) != (v[std::size_t(k - 1)] - iso[j] < 0)) {
              hit[j] = k;
              lhits += 1;
              break;
            }
        }
        lrays += 1;
        // Needed samples of surfaces first..last under macro-cells of scheme s.
        auto needed = [&](int s, int first, int last) {
          const MacroCells& mc = cells[std::size_t(s)];
          double c = 0;
          for (int k = 0; k < n; ++k) {
            const int id = cell[s][std::size_t(k)];
            for (int j = first; j <= last; ++j)
              if (k <= hit[j] && mc.min(id) <= iso[j] && iso[j] <= mc.max(id)) {
                c += 1;
                break;
              }
          }
          return c;
        };
        for (int s = 0; s < 4; ++s) {
          local[s].one += needed(s, 0, 0);
          local[s].many += needed(s, 0, kSurfaces - 1);
          for (int j = 0; j < kSurfaces; ++j) local[s].separate += needed(s, j, j);
        }
        // Value-based skipping on top of the M = 8 macro-cells.
        auto skipped = [&](int first, int last, bool cells_too) {
          const MacroCells& mc = cells[0];
          const double cap = std::floor((mc.size() - 1) / (step * std::max({std::abs(ray.direction[0]),
                                                                           std::abs(ray.direction[1]),
                                                                           std::abs(ray.direction[2])})));
          double c = 0;
          for (int k = 0; k < n;) {
            const int id = cell[0][std::size_t(k)];
            bool pending = false, live = false;
            double gap = INFINITY;
            for (int j = first; j <= last; ++j)
              if (k <= hit[j]) {
                pending = true;
                gap = std::min(gap, std::abs(double(v[std::size_t(k)]) - iso[j]));
                live = live || !cells_too || (mc.min(id) <= iso[j] && iso[j] <= mc.max(id));
              }
            if (!pending) break;
            if (!live) {
              ++k;
              continue;
            }
            c += 1;
            const float* g = &slopes[3 * std::size_t(id)];
            const double L = step * (g[0] * std::abs(ray.direction[0]) + g[1] * std::abs(ray.direction[1]) +
                                     g[2] * std::abs(ray.direction[2]));
            const double skip = L > 0 ? std::min(cap, std::floor(gap / L)) : cap;
            k += 1 + int(skip);
          }
          return c;
        };
        for (int s = 4; s < 6; ++s) {
          local[s].one += skipped(0, 0, s == 4);
          local[s].many += skipped(0, kSurfaces - 1, s == 4);
          for (int j = 0; j < kSurfaces; ++j) local[s].separate += skipped(j, j, s == 4);
        }
      }
#pragma omp critical
      {
        for (int s = 0; s < kSchemes; ++s) {
          total[s].one += local[s].one;
          total[s].many += local[s].many;
          total[s].separate += local[s].separate;
        }
        rays += lrays;
        hits += lhits;
      }
    }
  }
  const char* names[kSchemes] = {"macro-cells 8^3 (the renderer's)", "macro-cells 4^3", "macro-cells 2^3",
                                 "macro-cells 1^3 (every cell)", "macro-cells 8^3 + value-based skipping",
                                 "value-based skipping alone (bounds of the 8^3 macro-cells)"};
  std::printf("rays %.0f (cameras 12, 77; every %d-th pixel), step %.2f voxel, surfaces hit per ray %.2f of 8\n",
              rays, stride, step, hits / rays);
  std::printf("| scheme | one: samples/ray | 8 surfaces: samples/ray | K/one | 8 separate: samples/ray | K/separate |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (int s = 0; s < kSchemes; ++s)
    std::printf("| %s | %.1f | %.1f | %.2f | %.1f | %.3f |\n", names[s], total[s].one / rays, total[s].many / rays,
                total[s].many / total[s].one, total[s].separate / rays, total[s].many / total[s].separate);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "iso_sweep_floor: %s\n", e.what());
  return 1;
}
