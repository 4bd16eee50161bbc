#include "render/iso_shading.hpp"

#include <algorithm>
#include <cmath>

#include "render/sample_blocks.hpp"

namespace panoptes::render {
namespace march {
namespace {

// Headlight shading of an isosurface hit from its gradient g (field units per world unit): diffuse
// 0.15 + 0.85·|n·l|, specular 0.25·|n·l|^32, two-sided; a zero gradient counts as facing the camera.
// `squarings`: |n·l|^32 by five squarings (the renderer) instead of std::pow (the pre-issue-10
// formula, kept for the reference renderer); they differ by a few ulps of a double.
inline void shade_from_gradient(const double g[3], const Vec3& dir, const float colour[3], bool squarings, float* a) {
  const Vec3 n = normalize(Vec3{g[0], g[1], g[2]});
  double ndl = std::abs(dot(n, dir));  // headlight: light comes from the camera; two-sided
  if (norm(n) == 0) ndl = 1;
  double p32 = ndl;
  if (squarings) {
    for (int i = 0; i < 5; ++i) p32 *= p32;
  } else {
    p32 = std::pow(ndl, 32.0);
  }
  const float diffuse = float(0.15 + 0.85 * ndl);
  const float spec = float(0.25 * p32);
  for (int k = 0; k < 3; ++k) a[k] = std::min(1.0f, colour[k] * diffuse + spec);
  a[3] = 1.0f;
}

// The positions of the central differences at p: ±0.5 voxel per axis, one-sided at the domain's
// faces. q[2·ax] = p − 0.5·e_ax, q[2·ax + 1] = p + 0.5·e_ax; h[ax] = their distance in world units.
inline void gradient_points(const double p[3], const Index3& dims, const Vec3& spacing, double (*q)[3], double h[3]) {
  for (int ax = 0; ax < 3; ++ax) {
    double* q0 = q[2 * ax];
    double* q1 = q[2 * ax + 1];
    for (int b = 0; b < 3; ++b) q0[b] = q1[b] = p[b];
    q1[ax] = std::min(q1[ax] + 0.5, double(dims[ax] - 1));
    q0[ax] = std::max(q0[ax] - 0.5, 0.0);
    h[ax] = (q1[ax] - q0[ax]) * spacing[ax];
  }
}

}  // namespace

// The pre-issue-10 hit shading: six scalar interpolations, std::pow. The reference renderer's
// isosurfaces use it, so "within 45 dB of the reference" means "of what the renderer computed before".
void shade_hit_scalar(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
                      const float colour[3], float* a) {
  double q[6][3], h[3], g[3];
  gradient_points(p, dims, spacing, q, h);
  for (int ax = 0; ax < 3; ++ax) {
    const double* q0 = q[2 * ax];
    const double* q1 = q[2 * ax + 1];
    g[ax] = h[ax] > 0 ? (interp_clamped(f, q1[0], q1[1], q1[2]) - interp_clamped(f, q0[0], q0[1], q0[2])) / h[ax] : 0.0;
  }
  shade_from_gradient(g, dir, colour, false, a);
}

// The renderer's gradient: the six interpolations of the central differences (float positions, clamps
// and lerps of interp_clamped(), so the same values) as lanes of one 8-lane gather evaluation.
void field_gradient(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], double g[3]) {
  double q[6][3], h[3];
  gradient_points(p, dims, spacing, q, h);
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    alignas(32) float x[8], y[8], z[8], v[8];
    for (int l = 0; l < 6; ++l) x[l] = float(q[l][0]), y[l] = float(q[l][1]), z[l] = float(q[l][2]);
    x[6] = x[7] = x[0], y[6] = y[7] = y[0], z[6] = z[7] = z[0];  // unused lanes: a valid position
    // interp_clamped(): positions clamped into the data (std::clamp = max then min for numbers),
    // then the cell index clamped to [ilo, ihi].
    auto pos = [&](const float* c, int ax) {
      return _mm256_min_ps(_mm256_max_ps(_mm256_load_ps(c), _mm256_set1_ps(f.plo[ax])), _mm256_set1_ps(f.phi[ax]));
    };
    const __m256 px = pos(x, 0), py = pos(y, 1), pz = pos(z, 2);
    _mm256_store_ps(v, trilinear8(f, px, py, pz));
    for (int ax = 0; ax < 3; ++ax) g[ax] = h[ax] > 0 ? (double(v[2 * ax + 1]) - double(v[2 * ax])) / h[ax] : 0.0;
    return;
  }
#endif
  for (int ax = 0; ax < 3; ++ax) {
    const double* q0 = q[2 * ax];
    const double* q1 = q[2 * ax + 1];
    g[ax] = h[ax] > 0 ? (interp_clamped(f, q1[0], q1[1], q1[2]) - interp_clamped(f, q0[0], q0[1], q0[2])) / h[ax] : 0.0;
  }
}

// The renderer's hit shading: field_gradient() and |n·l|^32 by squarings. With eight isosurfaces a
// ray makes ~3 hits, each of which paid six scalar interpolations and a libm pow.
void shade_hit(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
               const float colour[3], float* a, double* gradient) {
  double g[3];
  field_gradient(f, dims, spacing, p, g);
  shade_from_gradient(g, dir, colour, true, a);
  if (gradient) std::copy_n(g, 3, gradient);
}

namespace {
// Anti-aliasing's shading filter (shade_hit_footprint()); issue 41's scene decided the constants
// (iso_edges_test.cpp, IsoEdges.SpecklesAgainstTheSupersampledSurface: fewest speckles with the PSNR
// against the supersampled reference no lower than without the filter).
// Only near a rim (|n·d| below kRimBelow, where the footprint stretches round the surface) or in the
// highlight (above kHighlightFrom, where 0.25·|n·l|^32 bends) is the surface looked at: between them
// the diffuse term is linear in n, so a box filter leaves the centre's shading unless the normal
// bends sharply within the pixel (a crease: one speckle of issue 41's scene, camera 115, stays). It
// saves most of the filter's cost (BM_Isosurfaces from outside: +12 … +22 % of an anti-aliased
// isosurface frame when every hit is looked at, +4 … +10 % so; docs/rendering.md).
constexpr double kRimBelow = 0.3, kHighlightFrom = 0.92;
// Filtered where the footprint corners' mean departs from the centre by more than this (three times
// a box filter's departure for a quadratic change: ~2.7 levels).
constexpr float kBends = 8.0f / 255;
// Sub-rays that pass beyond the rim see what lies behind the surface, which the hit does not know:
// the background at an outer silhouette (dark), another sheet in a valley where two meet (light).
// They count with this weight with the rim's own shading, the rest of their weight going to those
// that meet the surface (1: the valleys keep dark speckles; 0: outer rims turn light).
constexpr double kBeyondRim = 0.6;
// The renderer's normals are central differences over a voxel; the field's bend between samples ½
// voxel apart is sharper than theirs. Dividing it by 1.5 matched the reference best (measured with
// every hit looked at: 1 left 3 speckles outside instead of 4 but lost 0.3 dB; 2 left 6).
constexpr double kCurvatureScale = 1.5;
// The tangents' samples reach as far as half a voxel on every axis allows, at most twice `reach`.
constexpr double kRadiusCap = 2.0;

inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The field at eight index-space positions (interp_clamped()'s values) as one gather evaluation.
void field_values8(const FieldAcc& f, const double (*q)[3], float v[8]) {
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    alignas(32) float x[8], y[8], z[8], out[8];
    for (int l = 0; l < 8; ++l) x[l] = float(q[l][0]), y[l] = float(q[l][1]), z[l] = float(q[l][2]);
    auto pos = [&](const float* c, int ax) {
      return _mm256_min_ps(_mm256_max_ps(_mm256_load_ps(c), _mm256_set1_ps(f.plo[ax])), _mm256_set1_ps(f.phi[ax]));
    };
    _mm256_store_ps(out, trilinear8(f, pos(x, 0), pos(y, 1), pos(z, 2)));
    std::copy_n(out, 8, v);
    return;
  }
#endif
  for (int l = 0; l < 8; ++l) v[l] = interp_clamped(f, q[l][0], q[l][1], q[l][2]);
}

// The surface's frame at a hit: unit normal n, t1 = d on the tangent plane (the direction the
// footprint stretches in, 1 / |n·d|; any tangent head-on), t2 = n × t1 (across the ray: d lies in
// span(n, t1)).
struct HitFrame {
  double n[3], t1[3], t2[3], nd;
  HitFrame(const double g[3], double gn, const Vec3& dir) {
    for (int c = 0; c < 3; ++c) n[c] = g[c] / gn;
    const double d[3] = {dir[0], dir[1], dir[2]};
    nd = dot3(n, d);
    for (int c = 0; c < 3; ++c) t1[c] = d[c] - nd * n[c];
    double l1 = std::sqrt(dot3(t1, t1));
    if (l1 < 1e-6) {
      const int ax = std::abs(n[0]) <= std::abs(n[1]) && std::abs(n[0]) <= std::abs(n[2]) ? 0 : std::abs(n[1]) <= std::abs(n[2]) ? 1 : 2;
      for (int c = 0; c < 3; ++c) t1[c] = double(c == ax) - n[ax] * n[c];
      l1 = std::sqrt(dot3(t1, t1));
    }
    for (double& c : t1) c /= l1;
    t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2], t2[2] = n[0] * t1[1] - n[1] * t1[0];
  }
};

// The surface round a hit, as far as a brick may read: a hit lies up to half a voxel beyond the
// brick's last sample and its own gradient reads half a voxel farther, so nothing may be read
// farther than half a voxel from it on any axis (gradients taken ½ voxel away broke compositing by
// 3/255). One gather gives the surface's second fundamental form: the field at p and at ±r along t1,
// t2 and their diagonal, g·t = 0, so f(p ± r·t) − f(p) = ½ r²·tᵀHt to third order; the normal anywhere
// on the patch is then n + x·∂n/∂t1 + y·∂n/∂t2, ∂n/∂t = P·H·t / |∇f|. A sub-ray at image offset (α
// along t1's image, β along t2) meets the surface at y = β and x with α = −(n·d·x + ½ k·x² + k2·x·y)
// (n·d changes by k per unit of x, k2 per unit of y), or passes beyond the rim where that has no root:
// a grazing ray's footprint reaches round the surface's rim, which no read near p could show.
struct Patch {
  const HitFrame& H;
  const Vec3& dir;
  const float* colour;
  double h11 = 0, h12 = 0, h22 = 0, k = 0, k2 = 0, xmax = 0;
  Patch(const FieldAcc& f, const Vec3& spacing, const double p[3], const Vec3& d, const HitFrame& frame, double gn,
        double reach, const float* col)
      : H(frame), dir(d), colour(col) {
    const double hmin = std::min({spacing[0], spacing[1], spacing[2]});
    double u[3];
    for (int c = 0; c < 3; ++c) u[c] = 0.70710678118654752 * (H.t1[c] + H.t2[c]);
    const auto radius = [&](const double* t) {  // within half a voxel on every axis
      double r = kRadiusCap * reach;
      for (int c = 0; c < 3; ++c)
        if (std::abs(t[c]) > 1e-12) r = std::min(r, reach * spacing[c] / (std::abs(t[c]) * hmin));
      return r;
    };
    const double r1 = radius(H.t1), r2 = radius(H.t2), ru = radius(u);
    double q[8][3];
    for (int c = 0; c < 3; ++c) {
      const double a1 = r1 * H.t1[c] / spacing[c], a2 = r2 * H.t2[c] / spacing[c], au = ru * u[c] / spacing[c];
      q[0][c] = q[7][c] = p[c];
      q[1][c] = p[c] + a1, q[2][c] = p[c] - a1, q[3][c] = p[c] + a2, q[4][c] = p[c] - a2, q[5][c] = p[c] + au,
      q[6][c] = p[c] - au;
    }
    float v[8];
    field_values8(f, q, v);
    const double f0 = v[0], gs = gn * kCurvatureScale;
    h11 = (double(v[1]) + double(v[2]) - 2 * f0) / (r1 * r1 * gs);
    h22 = (double(v[3]) + double(v[4]) - 2 * f0) / (r2 * r2 * gs);
    h12 = (double(v[5]) + double(v[6]) - 2 * f0) / (ru * ru * gs) - 0.5 * (h11 + h22);
    const double s1 = H.t1[0] * dir[0] + H.t1[1] * dir[1] + H.t1[2] * dir[2];
    k = h11 * s1, k2 = h12 * s1;
    const double kmax = std::max({std::abs(h11), std::abs(h12), std::abs(h22)});
    xmax = kmax > 0 ? 1.0 / kmax : 1e30;  // the linear model is believed for a radian's turn
  }
  // The surface point (x, y) of the sub-ray at (α, β); false beyond the rim (then the rim's point).
  bool meet(double alpha, double beta, double& x, double& y) const {
    y = std::clamp(beta, -xmax, xmax);
    const double nd1 = H.nd + k2 * y, disc = nd1 * nd1 - 2 * k * alpha;
    const bool hit = disc >= 0;
    if (hit) {
      const double den = nd1 + std::copysign(std::sqrt(disc), nd1);
      x = den != 0 ? -2 * alpha / den : 0.0;
    } else {
      x = k != 0 ? -nd1 / k : 0.0;
    }
    x = std::clamp(x, -xmax, xmax);
    return hit;
  }
  void shade(double x, double y, float* rgb) const {
    double m[3];
    for (int c = 0; c < 3; ++c) m[c] = H.n[c] + x * (h11 * H.t1[c] + h12 * H.t2[c]) + y * (h12 * H.t1[c] + h22 * H.t2[c]);
    shade_from_gradient(m, dir, colour, true, rgb);
  }
  // Whether the shading can change non-linearly across a footprint `span` wide (a box filter of a
  // linear change is the centre's value, so only a bend matters: a highlight narrower than the pixel,
  // a rim, a crease): the four corners' mean against the centre, or a corner beyond the rim.
  bool bends(double span) const {
    const double h = 0.5 * span;
    // |x·∂n/∂t1 + y·∂n/∂t2|² = a11·x² + 2·a12·x·y + a22·y² (∂n/∂t ⟂ n): the patch normal's length.
    const double a11 = h11 * h11 + h12 * h12, a12 = h11 * h12 + h12 * h22, a22 = h12 * h12 + h22 * h22;
    const double c = std::max({colour[0], colour[1], colour[2]});  // the channel that changes most
    const auto shade1 = [c](double ndl) {
      double p32 = ndl;
      for (int i = 0; i < 5; ++i) p32 *= p32;
      return std::min(1.0, c * (0.15 + 0.85 * ndl) + 0.25 * p32);
    };
    double mean = 0;
    for (int i = 0; i < 4; ++i) {
      double x, y;
      if (!meet(i & 1 ? h : -h, i & 2 ? h : -h, x, y)) return true;
      const double md = H.nd + k * x + k2 * y, mm = 1 + a11 * x * x + 2 * a12 * x * y + a22 * y * y;
      mean += 0.25 * shade1(std::min(1.0, std::abs(md) / std::sqrt(mm)));
    }
    return std::abs(mean - shade1(std::abs(H.nd))) > kBends;
  }
  // The box filter over the footprint: 4 × 4 sub-rays, the reference's pattern.
  void filter(double span, float* a) const {
    float sum[3] = {0, 0, 0};
    double wsum = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double x, y;
        const double w = meet(span * ((i + 0.5) / 4 - 0.5), span * ((j + 0.5) / 4 - 0.5), x, y) ? 1.0 : kBeyondRim;
        float rgb[4];
        shade(x, y, rgb);
        for (int c = 0; c < 3; ++c) sum[c] += float(w) * rgb[c];
        wsum += w;
      }
    for (int c = 0; c < 3; ++c) a[c] = sum[c] / float(wsum);
  }
};

}  // namespace

bool shade_hit_footprint(const FieldAcc& f, const Vec3& spacing, const double p[3], const Vec3& dir, const double g[3],
                         double width, double reach, const float colour[3], float* a) {
  const double gn = std::sqrt(dot3(g, g));
  if (!(gn > 0 && width > 0)) return false;
  const double ndabs = std::abs(g[0] * dir[0] + g[1] * dir[1] + g[2] * dir[2]) / gn;
  if (ndabs >= kRimBelow && ndabs < kHighlightFrom) return false;
  const HitFrame H(g, gn, dir);
  const Patch patch(f, spacing, p, dir, H, gn, reach, colour);
  if (!patch.bends(width)) return false;
  patch.filter(width, a);
  return true;
}

}  // namespace march

void shade_isosurface_hit(const FieldView& v, const double p[3], const Vec3& dir, Rgb colour, bool renderer,
                          float rgba[4]) {
  v.validate();
  const march::FieldAcc f = march::make_acc(v);
  const float c[3] = {colour.r, colour.g, colour.b};
  if (renderer)
    march::shade_hit(f, v.grid.dims, v.grid.spacing, p, dir, c, rgba);
  else
    march::shade_hit_scalar(f, v.grid.dims, v.grid.spacing, p, dir, c, rgba);
}

}  // namespace panoptes::render
