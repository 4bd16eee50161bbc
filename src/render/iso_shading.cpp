#include "render/iso_shading.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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

#ifdef PANOPTES_RENDER_AVX2
namespace {
// Coordinate `ax` of the eight points q as float lanes, converted and assembled in registers. Written as
// eight floats and read back as one 32-byte load, the load could not be forwarded from the eight
// stores and waited for all of them to reach the cache, three times per gather evaluation (Round 19).
// The conversion rounds as float(q[l][ax]) does, so the lanes hold the same bits.
inline __m256 axis_lanes(const double (*q)[3], int ax) {
  const __m128 lo = _mm256_cvtpd_ps(_mm256_setr_pd(q[0][ax], q[1][ax], q[2][ax], q[3][ax]));
  const __m128 hi = _mm256_cvtpd_ps(_mm256_setr_pd(q[4][ax], q[5][ax], q[6][ax], q[7][ax]));
  return _mm256_set_m128(hi, lo);
}
}  // namespace
#endif

// The renderer's gradient: the six interpolations of the central differences (float positions, clamps
// and lerps of interp_clamped(), so the same values) as lanes of one 8-lane gather evaluation.
void field_gradient(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], double g[3],
                    float* samples) {
  double q[8][3], h[3];
  gradient_points(p, dims, spacing, q, h);
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    alignas(32) float v[8];
    // Lane 6: the field at p itself (the footprint filter's cheap look, cheap_bends()); lane 7 unused.
    for (int c = 0; c < 3; ++c) q[6][c] = q[7][c] = p[c];
    // interp_clamped(): positions clamped into the data (std::clamp = max then min for numbers),
    // then the cell index clamped to [ilo, ihi].
    auto pos = [&](int ax) {
      return _mm256_min_ps(_mm256_max_ps(axis_lanes(q, ax), _mm256_set1_ps(f.plo[ax])), _mm256_set1_ps(f.phi[ax]));
    };
    const __m256 px = pos(0), py = pos(1), pz = pos(2);
    _mm256_store_ps(v, trilinear8(f, px, py, pz));
    if (samples) std::copy_n(v, 8, samples);
    for (int ax = 0; ax < 3; ++ax) g[ax] = h[ax] > 0 ? (double(v[2 * ax + 1]) - double(v[2 * ax])) / h[ax] : 0.0;
    return;
  }
#endif
  for (int ax = 0; ax < 3; ++ax) {
    const double* q0 = q[2 * ax];
    const double* q1 = q[2 * ax + 1];
    const float v0 = interp_clamped(f, q0[0], q0[1], q0[2]), v1 = interp_clamped(f, q1[0], q1[1], q1[2]);
    g[ax] = h[ax] > 0 ? (v1 - v0) / h[ax] : 0.0;
    if (samples) samples[2 * ax] = v0, samples[2 * ax + 1] = v1;
  }
  if (samples) samples[6] = samples[7] = interp_clamped(f, p[0], p[1], p[2]);
}

// The renderer's hit shading: field_gradient() and |n·l|^32 by squarings. With eight isosurfaces a
// ray makes ~3 hits, each of which paid six scalar interpolations and a libm pow.
void shade_hit(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
               const float colour[3], float* a, double* gradient, float* samples) {
  double g[3];
  field_gradient(f, dims, spacing, p, g, samples);
  shade_from_gradient(g, dir, colour, true, a);
  if (gradient) std::copy_n(g, 3, gradient);
}

namespace {
// Anti-aliasing's shading filter (shade_hit_footprint(), shade_near_miss_footprint()); issue 41's scene
// decided the constants (iso_edges_test.cpp, IsoEdges.SpecklesAgainstTheSupersampledSurface: no
// speckles, the PSNR against the supersampled reference highest).
// Filtered where the footprint corners' mean departs from the centre by more than this (three times
// a box filter's departure for a quadratic change: ~2.7 levels).
constexpr float kBends = 8.0f / 255;
// Sub-rays that pass beyond the rim see what lies behind the surface, which the hit does not know:
// the background at an outer silhouette (dark), another sheet in a valley where two meet (light).
// They count with this weight with the rim's own shading, the rest of their weight going to those
// that meet the surface (1: the valleys keep dark speckles; 0: outer rims turn light).
constexpr double kBeyondRim = 0.6;
// The gradients beside the hit lie as far along t1 and t2 as `reach` on every axis allows, at most
// this times `reach` (a tangent along a diagonal of the grid).
constexpr double kRadiusCap = 2.0;
// A near miss is filtered only near a rim (|n·d| below this at its point of closest approach) and
// where the patch puts the centre ray within half a footprint of the rim.
constexpr double kNearMissRim = 0.3;

inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double dot3(const double* a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The test of Patch::bends() and cheap_bends(): whether the shading can change non-linearly across a
// footprint 2h wide. The model's gradient g + x·D1 + y·D2 at the footprint's four corners (image
// offsets (±h, ±h): y = β, x where α = −(n·d·x + ½ k·x² + k2·x·y), both within ±xmax) and the four
// gradients `beside` the hit, each set's mean shading against the centre's (n·d); a corner beyond the
// rim bends too. `c`: the colour's largest channel (it changes most). The four corners are the four
// lanes of one vector: a hit pays its divisions and square roots once, not four times (Round 20).
struct CornerTest {
  double nd, k, k2, xmax;
  const double *g, *D1, *D2;
  const double (*beside)[3];
};

inline double shade_channel(double c, double ndl) {  // one channel of shade_from_gradient()
  double p32 = ndl;
  for (int i = 0; i < 5; ++i) p32 *= p32;
  return std::min(1.0, c * (0.15 + 0.85 * ndl) + 0.25 * p32);
}

bool corners_bend(const CornerTest& T, const Vec3& dir, double c, double h) {
  const double centre = shade_channel(c, std::abs(T.nd));
#ifdef PANOPTES_RENDER_AVX2
  // In float: the test compares shadings with an 8/255 bar, far above float's rounding, and the
  // model's corners and the four gradients beside the hit then fit one 8-lane vector.
  const __m128 zero = _mm_setzero_ps(), sign = _mm_set1_ps(-0.0f);
  const float hf = float(h), xm = float(T.xmax);
  const __m128 alpha = _mm_setr_ps(-hf, hf, -hf, hf);
  const __m128 xmax = _mm_set1_ps(xm), nxmax = _mm_set1_ps(-xm);
  const __m128 y = _mm_min_ps(_mm_max_ps(_mm_setr_ps(-hf, -hf, hf, hf), nxmax), xmax);
  const __m128 nd1 = _mm_add_ps(_mm_set1_ps(float(T.nd)), _mm_mul_ps(_mm_set1_ps(float(T.k2)), y));
  const __m128 disc = _mm_sub_ps(_mm_mul_ps(nd1, nd1), _mm_mul_ps(_mm_set1_ps(float(2 * T.k)), alpha));
  if (_mm_movemask_ps(_mm_cmp_ps(disc, zero, _CMP_NGE_UQ))) return true;  // a corner beyond the rim
  const __m128 den = _mm_add_ps(nd1, _mm_or_ps(_mm_sqrt_ps(disc), _mm_and_ps(nd1, sign)));
  __m128 x = _mm_blendv_ps(zero, _mm_div_ps(_mm_mul_ps(_mm_set1_ps(-2.0f), alpha), den), _mm_cmp_ps(den, zero, _CMP_NEQ_OQ));
  x = _mm_min_ps(_mm_max_ps(x, nxmax), xmax);
  // Lanes 0-3: the model at the four corners; 4-7: the four gradients beside the hit.
  const auto lanes = [&](int a) {
    const __m128 m = _mm_add_ps(_mm_set1_ps(float(T.g[a])), _mm_add_ps(_mm_mul_ps(x, _mm_set1_ps(float(T.D1[a]))),
                                                                       _mm_mul_ps(y, _mm_set1_ps(float(T.D2[a])))));
    const __m128 b = _mm_setr_ps(float(T.beside[0][a]), float(T.beside[1][a]), float(T.beside[2][a]), float(T.beside[3][a]));
    return _mm256_set_m128(b, m);
  };
  const __m256 m0 = lanes(0), m1 = lanes(1), m2 = lanes(2);
  const __m256 one = _mm256_set1_ps(1.0f), zero8 = _mm256_setzero_ps();
  const __m256 mm = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m0, m0), _mm256_mul_ps(m1, m1)), _mm256_mul_ps(m2, m2));
  const __m256 md = _mm256_andnot_ps(_mm256_set1_ps(-0.0f),
                                     _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m0, _mm256_set1_ps(float(dir[0]))),
                                                                 _mm256_mul_ps(m1, _mm256_set1_ps(float(dir[1])))),
                                                   _mm256_mul_ps(m2, _mm256_set1_ps(float(dir[2])))));
  const __m256 cs = _mm256_blendv_ps(one, _mm256_min_ps(one, _mm256_div_ps(md, _mm256_sqrt_ps(mm))), _mm256_cmp_ps(mm, zero8, _CMP_GT_OQ));
  __m256 p32 = cs;
  for (int i = 0; i < 5; ++i) p32 = _mm256_mul_ps(p32, p32);
  const __m256 sh = _mm256_min_ps(one, _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(float(c)), _mm256_add_ps(_mm256_set1_ps(0.15f), _mm256_mul_ps(_mm256_set1_ps(0.85f), cs))),
                                                     _mm256_mul_ps(_mm256_set1_ps(0.25f), p32)));
  alignas(32) float l[8];
  _mm256_store_ps(l, sh);
  const double mean = 0.25 * (double(l[0]) + l[1] + l[2] + l[3]), near = 0.25 * (double(l[4]) + l[5] + l[6] + l[7]);
#else
  const auto abs_cos = [&](const double* m) {
    const double mm = dot3(m, m);
    return mm > 0 ? std::min(1.0, std::abs(dot3(m, dir)) / std::sqrt(mm)) : 1.0;
  };
  double mean = 0, near = 0;
  for (int i = 0; i < 4; ++i) {
    const double alpha = i & 1 ? h : -h, y = std::clamp(i & 2 ? h : -h, -T.xmax, T.xmax);
    const double nd1 = T.nd + T.k2 * y, disc = nd1 * nd1 - 2 * T.k * alpha;
    if (!(disc >= 0)) return true;
    const double den = nd1 + std::copysign(std::sqrt(disc), nd1);
    const double x = std::clamp(den != 0 ? -2 * alpha / den : 0.0, -T.xmax, T.xmax);
    double m[3];
    for (int a = 0; a < 3; ++a) m[a] = T.g[a] + x * T.D1[a] + y * T.D2[a];
    mean += 0.25 * shade_channel(c, abs_cos(m));
    near += 0.25 * shade_channel(c, abs_cos(T.beside[i]));
  }
#endif
  return std::abs(mean - centre) > kBends || std::abs(near - centre) > kBends;
}

// The field at eight index-space positions (interp_clamped()'s values) as one gather evaluation.
void field_values8(const FieldAcc& f, const double (*q)[3], float v[8]) {
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    alignas(32) float out[8];
    auto pos = [&](int ax) {
      return _mm256_min_ps(_mm256_max_ps(axis_lanes(q, ax), _mm256_set1_ps(f.plo[ax])), _mm256_set1_ps(f.phi[ax]));
    };
    _mm256_store_ps(out, trilinear8(f, pos(0), pos(1), pos(2)));
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

// The surface round a hit from the renderer's own gradient field (what the reference's sub-rays shade
// with), read within a voxel of the hit on every axis (the ghost layers cover that: required_points()).
// field_gradient() at p ± r1·t1 and p ± r2·t2 on the tangent plane, r within `reach` (half a voxel)
// of p on every axis: their differences are how the gradient changes along t1 and t2 (D1, D2 per
// world unit), so the gradient anywhere on the patch is g + x·D1 + y·D2 (extrapolated beyond r: a
// grazing ray's footprint stretches by 1 / |n·d| along t1 and reaches round the rim) and the normal
// changes by ∂n/∂t = P·D / |∇f|. A sub-ray at image offset (α along t1's image, β along t2) meets the
// surface at y = β and x with α = −(n·d·x + ½ k·x² + k2·x·y) (n·d changes by k per unit of x, k2 per
// unit of y), or passes beyond the rim where that has no root. Where the model's meeting point lies
// within `reach` of p, one Newton step on the field along the sub-ray itself moves it onto the
// surface and the sub-ray is shaded with the gradient there: across a crease, where the smooth model
// puts the sub-rays on the wrong sheet, they see the sheet the reference's sub-rays see.
struct Patch {
  const FieldAcc& f;
  const Index3& dims;
  const Vec3& spacing;
  const double* p;
  const HitFrame& H;
  const Vec3& dir;
  const float* colour;
  double iso, gn, reach_index, inv_spacing[3];
  double g0[3], D1[3], D2[3], G[4][3];
  double k = 0, k2 = 0, xmax = 0;
  Patch(const FieldAcc& f_, const Index3& dims_, const Vec3& spacing_, const double p_[3], const Vec3& d,
        const HitFrame& frame, const double g[3], double gnorm, double reach, const float* col, double iso_)
      : f(f_), dims(dims_), spacing(spacing_), p(p_), H(frame), dir(d), colour(col), iso(iso_), gn(gnorm) {
    const double hmin = std::min({spacing[0], spacing[1], spacing[2]});
    reach_index = reach / hmin;
    for (int c = 0; c < 3; ++c) inv_spacing[c] = 1.0 / spacing[c];
    const auto radius = [&](const double* t) {  // within `reach` on every axis
      double r = kRadiusCap * reach;
      for (int c = 0; c < 3; ++c)
        if (std::abs(t[c]) > 1e-12) r = std::min(r, reach * spacing[c] / (std::abs(t[c]) * hmin));
      return r;
    };
    const double r1 = radius(H.t1), r2 = radius(H.t2);
    double c[4][3];  // p + r1·t1, p − r1·t1, p + r2·t2, p − r2·t2 (index space)
    for (int a = 0; a < 3; ++a) {
      const double a1 = r1 * H.t1[a] / spacing[a], a2 = r2 * H.t2[a] / spacing[a];
      c[0][a] = p[a] + a1, c[1][a] = p[a] - a1, c[2][a] = p[a] + a2, c[3][a] = p[a] - a2;
    }
    // The four gradients' 24 interpolations as three gather evaluations.
    double q[24][3], h[4][3];
    for (int i = 0; i < 4; ++i) gradient_points(c[i], dims, spacing, q + 6 * i, h[i]);
    float v[24];
    for (int b = 0; b < 3; ++b) field_values8(f, q + 8 * b, v + 8 * b);
    for (int i = 0; i < 4; ++i)
      for (int a = 0; a < 3; ++a)
        G[i][a] = h[i][a] > 0 ? (double(v[6 * i + 2 * a + 1]) - double(v[6 * i + 2 * a])) / h[i][a] : 0.0;
    for (int a = 0; a < 3; ++a) {
      g0[a] = g[a];
      D1[a] = (G[0][a] - G[1][a]) / (2 * r1);
      D2[a] = (G[2][a] - G[3][a]) / (2 * r2);
    }
    // n·d along the patch: ∂(n·d)/∂t = (D·d − (n·D)(n·d)) / |∇f|.
    k = (dot3(D1, dir) - dot3(H.n, D1) * H.nd) / gn;
    k2 = (dot3(D2, dir) - dot3(H.n, D2) * H.nd) / gn;
    // The linear model is believed for a radian's turn of the normal.
    double kmax = 0;
    for (const double* D : {D1, D2}) {
      const double nD = dot3(H.n, D);
      double t[3];
      for (int a = 0; a < 3; ++a) t[a] = D[a] - nD * H.n[a];
      kmax = std::max(kmax, std::sqrt(dot3(t, t)) / gn);
    }
    xmax = kmax > 0 ? 1.0 / kmax : 1e30;
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
  // The patch's gradient at (x, y).
  void model_gradient(double x, double y, double m[3]) const {
    for (int c = 0; c < 3; ++c) m[c] = g0[c] + x * D1[c] + y * D2[c];
  }
  // Whether the shading can change non-linearly across a footprint `span` wide (a box filter of a
  // linear change is the centre's value, so only a bend matters: a highlight narrower than the pixel,
  // a rim, a crease): the model's four footprint corners against the centre, or a corner beyond the
  // rim, or the four gradients read beside the hit against it (a crease bends them unlike the model).
  bool bends(double span) const {
    const CornerTest T{H.nd, k, k2, xmax, g0, D1, D2, G};
    return corners_bend(T, dir, std::max({colour[0], colour[1], colour[2]}), 0.5 * span);
  }
  // The box filter over the footprint: 4 × 4 sub-rays, the reference's pattern, the centre ray at
  // image offset (alpha0, 0). `hits_only`: the mean of the sub-rays that meet the surface (a near
  // miss, whose coverage is counted apart); false when none does. A sub-ray that meets the patch at
  // (x, y) is moved onto the surface by one Newton step on the field along p + α·e1 + β·t2 + λ·d
  // (e1 = s1·n − n·d·t1, the image of t1; s1 = t1·d) from the patch's meeting point and shaded with
  // the gradient where it lands; the patch's gradient stands in where a point would lie beyond
  // `reach` of p on some axis or the sub-ray runs along the surface. The sub-rays' interpolations
  // are packed eight to a gather evaluation (3 per sub-ray for the step, 6 for the gradient: 19
  // evaluations for the corners and the rest instead of 32 half-empty ones, Round 20).
  bool filter(double span, float* a, double alpha0 = 0, bool hits_only = false) const {
    // The pattern's four corner sub-rays first: where all four meet the surface and their shadings
    // agree within kBends, the footprint's shading is their mean (37 % of the filtered pixels in
    // BM_DenseInside: -2 % of its frame, its speckles and PSNR unchanged; Round 20), else the other
    // twelve too.
    static constexpr int kCorners[4] = {0, 3, 12, 15}, kRest[12] = {1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14};
    float rgb[16][3];
    double wc[16];
    sub_rays(span, alpha0, hits_only, kCorners, 4, rgb, wc);
    // (A corner skipped as a near miss's non-hit has no colour: the weights are looked at first.)
    bool agree = wc[0] == 1.0 && wc[3] == 1.0 && wc[12] == 1.0 && wc[15] == 1.0;
    for (int c = 0; c < 3 && agree; ++c) {
      float lo = rgb[0][c], hi = rgb[0][c];
      for (const int k : kCorners) lo = std::min(lo, rgb[k][c]), hi = std::max(hi, rgb[k][c]);
      agree = hi - lo <= kBends;
    }
    if (agree) {
      for (int c = 0; c < 3; ++c) a[c] = 0.25f * (rgb[0][c] + rgb[3][c] + rgb[12][c] + rgb[15][c]);
      return true;
    }
    sub_rays(span, alpha0, hits_only, kRest, 12, rgb, wc);
    float sum[3] = {0, 0, 0};
    double wsum = 0;
    for (int k = 0; k < 16; ++k) {
      if (!(wc[k] > 0)) continue;
      for (int c = 0; c < 3; ++c) sum[c] += float(wc[k]) * rgb[k][c];
      wsum += wc[k];
    }
    if (!(wsum > 0)) return false;
    for (int c = 0; c < 3; ++c) a[c] = sum[c] / float(wsum);
    return true;
  }
  // Shades the sub-rays `cells` (4·i + j of the 4 × 4 pattern): rgb[cell], wc[cell] (0: not counted).
  void sub_rays(double span, double alpha0, bool hits_only, const int* cells, int count, float (*rgb)[3], double* wc) const {
    const double s1 = dot3(H.t1, dir);
    double m[16][3], w[16], lam[16], o[16][3], q[16][3];
    int idx[16], cell[16], n = 0, steps = 0;  // idx: the sub-ray (of n) of each Newton step
    double al[16], be[16], xs[16], ys[16];
    bool hits[16];
    for (int l = 0; l < count; ++l) {
      const int i = cells[l] / 4, j = cells[l] % 4;
      al[l] = alpha0 + span * ((i + 0.5) / 4 - 0.5), be[l] = span * ((j + 0.5) / 4 - 0.5);
    }
    for (int b = 0; b < count; b += 4) meet4(al + b, be + b, xs + b, ys + b, hits + b);
    for (int l = 0; l < count; ++l) {
      if (!hits[l] && hits_only) {
        wc[cells[l]] = 0;
        continue;
      }
      cell[n] = cells[l];
      w[n] = hits[l] ? 1.0 : kBeyondRim;
      model_gradient(xs[l], ys[l], m[n]);
      if (hits[l]) {
        for (int c = 0; c < 3; ++c) o[steps][c] = al[l] * (s1 * H.n[c] - H.nd * H.t1[c]) + be[l] * H.t2[c];
        lam[steps] = xs[l] * s1;
        if (place(o[steps], lam[steps], q[steps])) idx[steps++] = n;
      }
      ++n;
    }
    // The Newton step needs the field and its slope along the sub-ray at each meeting point: the
    // field there and at ±½ voxel along the ray (one-sided where that leaves the domain), three
    // interpolations, 48 for 16 sub-rays in six gather evaluations. (The gradient's six, dotted with
    // the direction, took 14 and gave 460 instead of 448 speckles in BM_DenseInside; Round 20.)
    int landed = 0;
    {
      const double e = 0.5 * std::min({spacing[0], spacing[1], spacing[2]});
      double pts[16 * 3][3], span_e[16];
      float v[16 * 3];
      for (int k = 0; k < steps; ++k) {
        bool lo_in = true, hi_in = true;
        for (int c = 0; c < 3; ++c) {
          const double dc = e * dir[c] * inv_spacing[c], top = double(dims[c] - 1);
          lo_in = lo_in && q[k][c] - dc >= 0 && q[k][c] - dc <= top;
          hi_in = hi_in && q[k][c] + dc >= 0 && q[k][c] + dc <= top;
        }
        span_e[k] = (lo_in ? e : 0.0) + (hi_in ? e : 0.0);
        for (int c = 0; c < 3; ++c) {
          const double dc = e * dir[c] * inv_spacing[c];
          pts[3 * k][c] = q[k][c];
          pts[3 * k + 1][c] = lo_in ? q[k][c] - dc : q[k][c];
          pts[3 * k + 2][c] = hi_in ? q[k][c] + dc : q[k][c];
        }
      }
      values(pts, 3 * steps, v);
      for (int k = 0; k < steps; ++k) {
        if (!(span_e[k] > 0)) continue;
        const double gd = (double(v[3 * k + 2]) - double(v[3 * k + 1])) / span_e[k];
        if (!(std::abs(gd) > 1e-3 * gn)) continue;
        if (place(o[k], lam[k] - (double(v[3 * k]) - iso) / gd, q[landed])) idx[landed++] = idx[k];
      }
    }
    // The gradient where each step lands.
    {
      double pts[16 * 6][3], h[16][3];
      float v[16 * 6];
      for (int k = 0; k < landed; ++k) gradient_points(q[k], dims, spacing, pts + 6 * k, h[k]);
      values(pts, 6 * landed, v);
      for (int k = 0; k < landed; ++k) std::ranges::copy(central_difference(v + 6 * k, h[k]), m[idx[k]]);
    }
    double ndl[16];
    abs_cos16(m, n, ndl);
    for (int k = 0; k < n; ++k) {
      double p32 = ndl[k];
      for (int i = 0; i < 5; ++i) p32 *= p32;
      const float diffuse = float(0.15 + 0.85 * ndl[k]), spec = float(0.25 * p32);
      for (int c = 0; c < 3; ++c) rgb[cell[k]][c] = std::min(1.0f, colour[c] * diffuse + spec);
      wc[cell[k]] = w[k];
    }
  }
  // meet() for four sub-rays at once (the lanes of one vector where the renderer has AVX2).
  void meet4(const double* alpha, const double* beta, double* x, double* y, bool* hit) const {
#ifdef PANOPTES_RENDER_AVX2
    const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
    const __m256d hi = _mm256_set1_pd(xmax), lo = _mm256_set1_pd(-xmax);
    const __m256d a = _mm256_loadu_pd(alpha), vk = _mm256_set1_pd(k);
    const __m256d yy = _mm256_min_pd(_mm256_max_pd(_mm256_loadu_pd(beta), lo), hi);
    const __m256d nd1 = _mm256_add_pd(_mm256_set1_pd(H.nd), _mm256_mul_pd(_mm256_set1_pd(k2), yy));
    const __m256d disc = _mm256_sub_pd(_mm256_mul_pd(nd1, nd1), _mm256_mul_pd(_mm256_add_pd(vk, vk), a));
    const __m256d in = _mm256_cmp_pd(disc, zero, _CMP_GE_OQ);
    const __m256d den = _mm256_add_pd(nd1, _mm256_or_pd(_mm256_sqrt_pd(_mm256_max_pd(disc, zero)), _mm256_and_pd(nd1, sign)));
    const __m256d xin = _mm256_blendv_pd(zero, _mm256_div_pd(_mm256_mul_pd(_mm256_set1_pd(-2.0), a), den),
                                         _mm256_cmp_pd(den, zero, _CMP_NEQ_OQ));
    // Beyond the rim: the rim's point, x = −n·d / k (0 where k = 0).
    const __m256d xout = k != 0 ? _mm256_div_pd(_mm256_xor_pd(nd1, sign), vk) : zero;
    _mm256_storeu_pd(x, _mm256_min_pd(_mm256_max_pd(_mm256_blendv_pd(xout, xin, in), lo), hi));
    _mm256_storeu_pd(y, yy);
    const int mask = _mm256_movemask_pd(in);
    for (int l = 0; l < 4; ++l) hit[l] = mask >> l & 1;
#else
    for (int l = 0; l < 4; ++l) hit[l] = meet(alpha[l], beta[l], x[l], y[l]);
#endif
  }
  // |m·d| / |m| (at most 1; 1 where m = 0: facing the camera, as shade_from_gradient()) of n gradients.
  void abs_cos16(const double (*m)[3], int n, double* out) const {
#ifdef PANOPTES_RENDER_AVX2
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), sign = _mm256_set1_pd(-0.0);
    const __m256d dx = _mm256_set1_pd(dir[0]), dy = _mm256_set1_pd(dir[1]), dz = _mm256_set1_pd(dir[2]);
    for (int b = 0; b < n; b += 4) {
      const int r = std::min(4, n - b);
      const auto lane = [&](int a) {
        return _mm256_setr_pd(m[b][a], m[b + std::min(1, r - 1)][a], m[b + std::min(2, r - 1)][a], m[b + std::min(3, r - 1)][a]);
      };
      const __m256d m0 = lane(0), m1 = lane(1), m2 = lane(2);
      const __m256d mm = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m0, m0), _mm256_mul_pd(m1, m1)), _mm256_mul_pd(m2, m2));
      const __m256d md = _mm256_andnot_pd(sign, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m0, dx), _mm256_mul_pd(m1, dy)),
                                                              _mm256_mul_pd(m2, dz)));
      const __m256d cs = _mm256_blendv_pd(one, _mm256_min_pd(one, _mm256_div_pd(md, _mm256_sqrt_pd(mm))),
                                          _mm256_cmp_pd(mm, zero, _CMP_GT_OQ));
      alignas(32) double l[4];
      _mm256_store_pd(l, cs);
      std::copy_n(l, r, out + b);
    }
#else
    for (int i = 0; i < n; ++i) {
      const double mm = dot3(m[i], m[i]);
      out[i] = mm > 0 ? std::min(1.0, std::abs(dot3(m[i], dir)) / std::sqrt(mm)) : 1.0;
    }
#endif
  }
  // The index-space point p + o + λ·d; false where it lies beyond `reach` of p on some axis.
  bool place(const double o[3], double l, double q[3]) const {
    double far = 0;
    for (int c = 0; c < 3; ++c) {
      const double off = (o[c] + l * dir[c]) * inv_spacing[c];
      far = std::max(far, std::abs(off));
      q[c] = p[c] + off;
    }
    return !(far > reach_index);
  }
  // The gradient from the six values at gradient_points() (h: their distances).
  static std::array<double, 3> central_difference(const float* v, const double h[3]) {
    std::array<double, 3> g;
    for (int a = 0; a < 3; ++a) g[a] = h[a] > 0 ? (double(v[2 * a + 1]) - double(v[2 * a])) / h[a] : 0.0;
    return g;
  }
  // The field at `count` index-space points, eight per gather evaluation (the last one padded).
  void values(const double (*pts)[3], int count, float* v) const {
    for (int b = 0; b < count; b += 8) {
      if (count - b >= 8) {
        field_values8(f, pts + b, v + b);
        continue;
      }
      double tail[8][3];
      float tv[8];
      for (int l = 0; l < 8; ++l) std::copy_n(pts[std::min(b + l, count - 1)], 3, tail[l]);
      field_values8(f, tail, tv);
      std::copy_n(tv, count - b, v + b);
    }
  }
};

// A cheap look before the patch's three gathers, for hits not near a rim (|n·d| ≥ kCheapLo), from
// values already read: the field's Hessian (diagonal from the values at p ± ½ voxel and at p that
// shade_hit()'s gather read, off-diagonal from the trilinear mixed derivatives of p's cell, cache-hot),
// the tangential change of the gradient it implies times kCheapMargin, put through the patch's own
// test (the model's four footprint corners, four gradients beside the hit). Where even that does not
// bend, the patch is not built and the pixel is not filtered. Issue 41's scene (IsoEdges.Speckles…),
// looked at for 0.3 ≤ |n·d| < 0.92 with margin 3: 58 % of those hits (42 % of all) skipped the patch,
// 1.3 % of the skipped (209 of ~16,400) the patch would have filtered (a crease the four gradients
// see and the Hessian at p does not). Speckles 0 and 0 with PSNR 46.92 / 50.07 dB (46.95 / 50.07
// without the look); over the highlight too, as here, 46.917 / 50.072; also near rims (kCheapLo 0)
// 46.907 / 50.066 and no faster (rims bend). Margin 2 (to 0.92): 46.91 / 50.07; 1.5 (to 0.8) fails.
constexpr double kCheapLo = 0.3, kCheapMargin = 3.0;

bool cheap_bends(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir, const HitFrame& H,
                 const double g[3], double gn, double reach, const float* colour, double span, const float* samples) {
  const double hmin = std::min({spacing[0], spacing[1], spacing[2]});
  const auto radius = [&](const double* t) {
    double r = kRadiusCap * reach;
    for (int c = 0; c < 3; ++c)
      if (std::abs(t[c]) > 1e-12) r = std::min(r, reach * spacing[c] / (std::abs(t[c]) * hmin));
    return r;
  };
  double r[2] = {radius(H.t1), radius(H.t2)};
  // The Hessian from what the hit's gradient read (cache-hot): the values at p ± ½ voxel per axis
  // and at p (diagonal), the trilinear mixed derivatives of p's cell (off-diagonal).
  double q[6][3], hh[3];
  gradient_points(p, dims, spacing, q, hh);
  for (int ax = 0; ax < 3; ++ax)
    if (!(std::abs(hh[ax] - spacing[ax]) <= 1e-9 * spacing[ax])) return true;  // at a face: the patch decides
  const float* v = samples;
  double Hs[3][3];
  for (int ax = 0; ax < 3; ++ax)
    Hs[ax][ax] = (double(v[2 * ax]) + double(v[2 * ax + 1]) - 2 * double(v[6])) / (0.25 * spacing[ax] * spacing[ax]);
  {
    double x[3];
    int ci[3];
    for (int a = 0; a < 3; ++a) {
      const float pc = std::clamp(float(p[a]), f.plo[a], f.phi[a]);
      ci[a] = std::min(std::max(int(pc), f.ilo[a]), f.ihi[a]);
      x[a] = double(pc) - ci[a];
    }
    const float* d = f.data + (f.off0 + ci[0] * f.sx + ci[1] * f.sy + ci[2] * f.sz);
    const std::int64_t st[3] = {f.sx, f.sy, f.sz};
    auto c = [&](int i, int j, int k) { return double(d[i * st[0] + j * st[1] + k * st[2]]); };
    // ∂²/∂a∂b: the mixed difference of the face pairs, interpolated along the third axis.
    const double fxy = (1 - x[2]) * (c(1, 1, 0) - c(1, 0, 0) - c(0, 1, 0) + c(0, 0, 0)) + x[2] * (c(1, 1, 1) - c(1, 0, 1) - c(0, 1, 1) + c(0, 0, 1));
    const double fxz = (1 - x[1]) * (c(1, 0, 1) - c(1, 0, 0) - c(0, 0, 1) + c(0, 0, 0)) + x[1] * (c(1, 1, 1) - c(1, 1, 0) - c(0, 1, 1) + c(0, 1, 0));
    const double fyz = (1 - x[0]) * (c(0, 1, 1) - c(0, 1, 0) - c(0, 0, 1) + c(0, 0, 0)) + x[0] * (c(1, 1, 1) - c(1, 1, 0) - c(1, 0, 1) + c(1, 0, 0));
    Hs[0][1] = Hs[1][0] = fxy / (spacing[0] * spacing[1]);
    Hs[0][2] = Hs[2][0] = fxz / (spacing[0] * spacing[2]);
    Hs[1][2] = Hs[2][1] = fyz / (spacing[1] * spacing[2]);
  }
  double Ht1[3], Ht2[3];
  for (int a = 0; a < 3; ++a) Ht1[a] = dot3(Hs[a], H.t1), Ht2[a] = dot3(Hs[a], H.t2);
  const double a11 = dot3(H.t1, Ht1), a22 = dot3(H.t2, Ht2), a12 = dot3(H.t1, Ht2);
  const double m = kCheapMargin;
  // The patch's D1, D2 (tangential parts, times the margin) and its four gradients beside at ±r.
  double D1[3], D2[3], G[4][3];
  for (int c = 0; c < 3; ++c) {
    D1[c] = m * (a11 * H.t1[c] + a12 * H.t2[c]);
    D2[c] = m * (a12 * H.t1[c] + a22 * H.t2[c]);
  }
  const double r1 = r[0], r2 = r[1];
  for (int c = 0; c < 3; ++c) {
    G[0][c] = g[c] + r1 * D1[c], G[1][c] = g[c] - r1 * D1[c];
    G[2][c] = g[c] + r2 * D2[c], G[3][c] = g[c] - r2 * D2[c];
  }
  const double k = (dot3(D1, dir) - dot3(H.n, D1) * H.nd) / gn, k2 = (dot3(D2, dir) - dot3(H.n, D2) * H.nd) / gn;
  const CornerTest T{H.nd, k, k2, std::numeric_limits<double>::infinity(), g, D1, D2, G};
  return corners_bend(T, dir, std::max({colour[0], colour[1], colour[2]}), 0.5 * span);
}

}  // namespace

bool shade_hit_footprint(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
                         const double g[3], double width, double reach, double iso, const float colour[3], float* a,
                         const float* samples) {
  const double gn = std::sqrt(dot3(g, g));
  if (!(gn > 0 && width > 0)) return false;
  const HitFrame H(g, gn, dir);
  if (std::abs(H.nd) >= kCheapLo && samples && !cheap_bends(f, dims, spacing, p, dir, H, g, gn, reach, colour, width, samples))
    return false;
  const Patch patch(f, dims, spacing, p, dir, H, g, gn, reach, colour, iso);
  if (!patch.bends(width)) return false;
  return patch.filter(width, a);
}

bool shade_near_miss_footprint(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3],
                               const Vec3& dir, const double g[3], double width, double reach, double miss, double iso,
                               const float colour[3], float* a) {
  const double gn = std::sqrt(dot3(g, g));
  if (!(gn > 0 && width > 0) || std::abs(dot3(g, dir)) >= kNearMissRim * gn) return false;
  const HitFrame H(g, gn, dir);
  const Patch patch(f, dims, spacing, p, dir, H, g, gn, reach, colour, iso);
  if (patch.k == 0) return false;
  // The centre ray passes `miss` beyond the patch's rim (where n·d² − 2kα = 0).
  const double alpha0 = H.nd * H.nd / (2 * patch.k) + std::copysign(miss, patch.k);
  if (std::abs(alpha0) > 0.5 * width) return false;
  return patch.filter(width, a, alpha0, true);
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
