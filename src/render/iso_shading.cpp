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
