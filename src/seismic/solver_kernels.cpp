#include <omp.h>

#include <algorithm>
#include <cmath>

#include "seismic/denormals.hpp"
#include "seismic/solver_impl.hpp"

namespace panoptes::seismic {

// ==================================================================== kernels

// One row (k, j) of the velocity update, followed by its CPML corrections (x, then y, then z: the
// same order per cell as separate passes) while the row is in cache. The corrections of v read
// only σ, so doing them row by row is exact.
template <class M>
void Solver::Impl::velocity_row(int k, int j, const M& mat0) {
  const std::size_t b = idx(0, j, k);
  const M m = mat0.row(b);
  const long Y = sy, Z = sz;
  float* __restrict ux = vx.data() + b;
  float* __restrict uy = vy.data() + b;
  float* __restrict uz = vz.data() + b;
  const float* __restrict xx = sxx.data() + b;
  const float* __restrict yy = syy.data() + b;
  const float* __restrict zz = szz.data() + b;
  const float* __restrict xy = sxy.data() + b;
  const float* __restrict xz = sxz.data() + b;
  const float* __restrict yz = syz.data() + b;
#pragma omp simd
  for (int i = 0; i < nx; ++i) {
    ux[i] += m(BX, i) * (C1 * (xx[i + 1] - xx[i]) + C2 * (xx[i + 2] - xx[i - 1]) + C1 * (xy[i] - xy[i - Y]) +
                         C2 * (xy[i + Y] - xy[i - 2 * Y]) + C1 * (xz[i] - xz[i - Z]) + C2 * (xz[i + Z] - xz[i - 2 * Z]));
    uy[i] += m(BY, i) * (C1 * (xy[i] - xy[i - 1]) + C2 * (xy[i + 1] - xy[i - 2]) + C1 * (yy[i + Y] - yy[i]) +
                         C2 * (yy[i + 2 * Y] - yy[i - Y]) + C1 * (yz[i] - yz[i - Z]) + C2 * (yz[i + Z] - yz[i - 2 * Z]));
    uz[i] += m(BZ, i) * (C1 * (xz[i] - xz[i - 1]) + C2 * (xz[i + 1] - xz[i - 2]) + C1 * (yz[i] - yz[i - Y]) +
                         C2 * (yz[i + Y] - yz[i - 2 * Y]) + C1 * (zz[i + Z] - zz[i]) + C2 * (zz[i + 2 * Z] - zz[i - Z]));
  }
  // CPML: ψ ← b·ψ + a·∂f and f += coefficient·ψ after the plain update (κ = 1), layers only.
  const int cx = pmlx.count();
  // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
  for (const auto& run : pmlx.runs) {
    const int i0 = run[0], i1 = run[1], s0 = run[2];
    const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
    float* __restrict q0 = psix[0].data() + p;
    float* __restrict q1 = psix[1].data() + p;
    float* __restrict q2 = psix[2].data() + p;
    const float* __restrict bh = pmlx.b_half.data();
    const float* __restrict ah = pmlx.a_half.data();
    const float* __restrict bf = pmlx.b_full.data();
    const float* __restrict af = pmlx.a_full.data();
#pragma omp simd
    for (int i = i0; i < i1; ++i) {
      const int q = i - i0;
      q0[q] = bh[i] * q0[q] + ah[i] * (C1 * (xx[i + 1] - xx[i]) + C2 * (xx[i + 2] - xx[i - 1]));
      ux[i] += m(BX, i) * q0[q];
      q1[q] = bf[i] * q1[q] + af[i] * (C1 * (xy[i] - xy[i - 1]) + C2 * (xy[i + 1] - xy[i - 2]));
      uy[i] += m(BY, i) * q1[q];
      q2[q] = bf[i] * q2[q] + af[i] * (C1 * (xz[i] - xz[i - 1]) + C2 * (xz[i + 1] - xz[i - 2]));
      uz[i] += m(BZ, i) * q2[q];
    }
  }
  if (const int s = pmly.count() > 0 ? pmly.slot[j] : -1; s >= 0) {
    const float bf = pmly.b_full[j], af = pmly.a_full[j], bh = pmly.b_half[j], ah = pmly.a_half[j];
    float* __restrict p0 = psiy[0].data() + (std::size_t(k) * pmly.count() + s) * nx;
    float* __restrict p1 = psiy[1].data() + (std::size_t(k) * pmly.count() + s) * nx;
    float* __restrict p2 = psiy[2].data() + (std::size_t(k) * pmly.count() + s) * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      p0[i] = bf * p0[i] + af * (C1 * (xy[i] - xy[i - Y]) + C2 * (xy[i + Y] - xy[i - 2 * Y]));
      ux[i] += m(BX, i) * p0[i];
      p1[i] = bh * p1[i] + ah * (C1 * (yy[i + Y] - yy[i]) + C2 * (yy[i + 2 * Y] - yy[i - Y]));
      uy[i] += m(BY, i) * p1[i];
      p2[i] = bf * p2[i] + af * (C1 * (yz[i] - yz[i - Y]) + C2 * (yz[i + Y] - yz[i - 2 * Y]));
      uz[i] += m(BZ, i) * p2[i];
    }
  }
  if (const int s = pmlz.count() > 0 ? pmlz.slot[k] : -1; s >= 0) {
    const float bf = pmlz.b_full[k], af = pmlz.a_full[k], bh = pmlz.b_half[k], ah = pmlz.a_half[k];
    float* __restrict p0 = psiz[0].data() + (std::size_t(s) * ny + j) * nx;
    float* __restrict p1 = psiz[1].data() + (std::size_t(s) * ny + j) * nx;
    float* __restrict p2 = psiz[2].data() + (std::size_t(s) * ny + j) * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      p0[i] = bf * p0[i] + af * (C1 * (xz[i] - xz[i - Z]) + C2 * (xz[i + Z] - xz[i - 2 * Z]));
      ux[i] += m(BX, i) * p0[i];
      p1[i] = bf * p1[i] + af * (C1 * (yz[i] - yz[i - Z]) + C2 * (yz[i + Z] - yz[i - 2 * Z]));
      uy[i] += m(BY, i) * p1[i];
      p2[i] = bh * p2[i] + ah * (C1 * (zz[i + Z] - zz[i]) + C2 * (zz[i + 2 * Z] - zz[i - Z]));
      uz[i] += m(BZ, i) * p2[i];
    }
  }
}

// Velocity row (k, j) with its CPML corrections and body forces.
void Solver::Impl::velocity_row_at(int k, int j, double t) {
  const std::size_t r = std::size_t(k) * ny + j;
  if (const int u = row_mat[r]; u >= 0) velocity_row(k, j, UniformMat{mat_tuples.data() + std::size_t(u) * K});
  else if (mat_table) velocity_row(k, j, table_mat());
  else velocity_row(k, j, dense_mat());
  for (int e = force_first[r]; e < force_first[r + 1]; ++e) {
    const Injection& q = force_rows[e];
    q.field[q.n] += float(q.weight * sources[q.source].stf.value(t) * mat(q.mat, q.n));
  }
}

// Rows [j0, j1) of velocity plane k (worksharing when called inside a parallel region).
void Solver::Impl::velocity_rows(int k, int j0, int j1, double t) {
#pragma omp for schedule(static)
  for (int j = j0; j < j1; ++j) velocity_row_at(k, j, t);
}

// Strain-rate differences (times h) at node / edge positions of plane k. Z selects the z stencil:
// 0 interior, 1 the free-surface plane (ezz from σzz = 0; 2nd-order ∂z for the edges at z = h/2),
// 2 the plane below it (2nd-order ∂z vz: vz above the surface is not a model value).
// Expects la = λ, tm = 2μ of the cell.
#define PANOPTES_STRAIN(Zm)                                                                                       \
  const float exx = C1 * (ux[i] - ux[i - 1]) + C2 * (ux[i + 1] - ux[i - 2]);                                       \
  const float eyy = C1 * (uy[i] - uy[i - Y]) + C2 * (uy[i + Y] - uy[i - 2 * Y]);                                   \
  float ezz;                                                                                                       \
  if constexpr (Zm == 0) ezz = C1 * (uz[i] - uz[i - Z]) + C2 * (uz[i + Z] - uz[i - 2 * Z]);                         \
  else if constexpr (Zm == 1) ezz = -la / (la + tm) * (exx + eyy);                                                 \
  else ezz = uz[i] - uz[i - Z];                                                                                    \
  const float exy = C1 * (ux[i + Y] - ux[i]) + C2 * (ux[i + 2 * Y] - ux[i - Y]) + C1 * (uy[i + 1] - uy[i]) +        \
                    C2 * (uy[i + 2] - uy[i - 1]);                                                                  \
  float exz, eyz;                                                                                                  \
  if constexpr (Zm == 1) {                                                                                         \
    exz = (ux[i + Z] - ux[i]) + C1 * (uz[i + 1] - uz[i]) + C2 * (uz[i + 2] - uz[i - 1]);                           \
    eyz = (uy[i + Z] - uy[i]) + C1 * (uz[i + Y] - uz[i]) + C2 * (uz[i + 2 * Y] - uz[i - Y]);                       \
  } else {                                                                                                         \
    exz = C1 * (ux[i + Z] - ux[i]) + C2 * (ux[i + 2 * Z] - ux[i - Z]) + C1 * (uz[i + 1] - uz[i]) +                  \
          C2 * (uz[i + 2] - uz[i - 1]);                                                                            \
    eyz = C1 * (uy[i + Z] - uy[i]) + C2 * (uy[i + 2 * Z] - uy[i - Z]) + C1 * (uz[i + Y] - uz[i]) +                  \
          C2 * (uz[i + 2 * Y] - uz[i - Y]);                                                                        \
  }                                                                                                                \
  const float th = exx + eyy + ezz;

// One row of the stress update (plus memory variables when attenuating), then its CPML
// corrections x, y, z; on the free-surface plane σzz is set to 0 last. Corrections of σ read only v.
// CPML correction of one stress row for the derivatives along y or z (stride S between rows of that
// axis): ψ0 of the axis's own velocity component n feeds the normal stresses (λ + 2μ on the axis's
// own, λ on the two others); ψ1 and ψ2 of the other components a1, a2 feed the two shear stresses in
// the axis's plane. Restrict-qualified so the loop vectorizes; the same expressions as the interior
// update's, so results do not depend on which code path a row takes.
template <int Mu1, int Mu2, class M>
[[gnu::always_inline]] inline void pml_stress_row(const M& m, int nx, long S, float bf, float af, float bh, float ah, float* __restrict q0,
                           float* __restrict q1, float* __restrict q2, float* __restrict normal, float* __restrict other1,
                           float* __restrict other2, float* __restrict shear1, float* __restrict shear2,
                           const float* __restrict n, const float* __restrict a1, const float* __restrict a2) {
#pragma omp simd
  for (int i = 0; i < nx; ++i) {
    q0[i] = bf * q0[i] + af * (C1 * (n[i] - n[i - S]) + C2 * (n[i + S] - n[i - 2 * S]));
    normal[i] += (m(LAM, i) + m(TWOMU, i)) * q0[i];
    other1[i] += m(LAM, i) * q0[i];
    other2[i] += m(LAM, i) * q0[i];
    q1[i] = bh * q1[i] + ah * (C1 * (a1[i + S] - a1[i]) + C2 * (a1[i + 2 * S] - a1[i - S]));
    shear1[i] += m(Mu1, i) * q1[i];
    q2[i] = bh * q2[i] + ah * (C1 * (a2[i + S] - a2[i]) + C2 * (a2[i + 2 * S] - a2[i - S]));
    shear2[i] += m(Mu2, i) * q2[i];
  }
}

template <int Zm, class M>
void Solver::Impl::stress_row(int k, int j, const M& mat0) {
  const std::size_t b = idx(0, j, k);
  const M m = mat0.row(b);
  const long Y = sy, Z = sz;
  {
  // Restrict-qualified only here: the CPML part below also writes σ through visco_pml (own restrict scopes).
  const float* __restrict ux = vx.data() + b;
  const float* __restrict uy = vy.data() + b;
  const float* __restrict uz = vz.data() + b;
  float* __restrict xx = sxx.data() + b;
  float* __restrict yy = syy.data() + b;
  float* __restrict zz = szz.data() + b;
  float* __restrict xy = sxy.data() + b;
  float* __restrict xz = sxz.data() + b;
  float* __restrict yz = syz.data() + b;
  if (L == 0) {
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      const float la = m(LAM, i), tm = m(TWOMU, i);
      PANOPTES_STRAIN(Zm)
      xx[i] += la * th + tm * exx;
      yy[i] += la * th + tm * eyy;
      zz[i] += la * th + tm * ezz;
      xy[i] += m(MUXY, i) * exy;
      xz[i] += m(MUXZ, i) * exz;
      yz[i] += m(MUYZ, i) * eyz;
    }
  } else {
    float* rows = rowbuf[std::size_t(omp_get_thread_num())].data();
    float* __restrict rxx_ = rows;
    float* __restrict ryy_ = rows + nx;
    float* __restrict rzz_ = rows + 2 * nx;
    float* __restrict rxy_ = rows + 3 * nx;
    float* __restrict rxz_ = rows + 4 * nx;
    float* __restrict ryz_ = rows + 5 * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      const float la = m(LAM, i), tm = m(TWOMU, i);
      PANOPTES_STRAIN(Zm)
      xx[i] += la * th + tm * exx;
      yy[i] += la * th + tm * eyy;
      zz[i] += la * th + tm * ezz;
      xy[i] += m(MUXY, i) * exy;
      xz[i] += m(MUXZ, i) * exz;
      yz[i] += m(MUYZ, i) * eyz;
      rxx_[i] = exx;
      ryy_[i] = eyy;
      rzz_[i] = ezz;
      rxy_[i] = exy;
      rxz_[i] = exz;
      ryz_[i] = eyz;
    }
    for (int l = 0; l < L; ++l) {
      const float A = relax_a[l], B = relax_b[l];
      float* __restrict mx = rxx[l].data() + b;
      float* __restrict my = ryy[l].data() + b;
      float* __restrict mz = rzz[l].data() + b;
      float* __restrict mxy_ = rxy[l].data() + b;
      float* __restrict mxz_ = rxz[l].data() + b;
      float* __restrict myz_ = ryz[l].data() + b;
      const int fl = CL(l), fm = CM(l), fxy = CMXY(l), fxz = CMXZ(l), fyz = CMYZ(l);
#pragma omp simd
      for (int i = 0; i < nx; ++i) {
        const float th = rxx_[i] + ryy_[i] + rzz_[i];
        const float cl_ = m(fl, i), cm_ = m(fm, i);
        float o, n;
        o = mx[i]; n = A * o + B * (cl_ * th + cm_ * rxx_[i]); mx[i] = n; xx[i] -= 0.5f * (o + n);
        o = my[i]; n = A * o + B * (cl_ * th + cm_ * ryy_[i]); my[i] = n; yy[i] -= 0.5f * (o + n);
        o = mz[i]; n = A * o + B * (cl_ * th + cm_ * rzz_[i]); mz[i] = n; zz[i] -= 0.5f * (o + n);
        o = mxy_[i]; n = A * o + B * (m(fxy, i) * rxy_[i]); mxy_[i] = n; xy[i] -= 0.5f * (o + n);
        o = mxz_[i]; n = A * o + B * (m(fxz, i) * rxz_[i]); mxz_[i] = n; xz[i] -= 0.5f * (o + n);
        o = myz_[i]; n = A * o + B * (m(fyz, i) * ryz_[i]); myz_[i] = n; yz[i] -= 0.5f * (o + n);
      }
    }
  }
  }
  // CPML corrections.
  const float* ux = vx.data() + b;
  const float* uy = vy.data() + b;
  const float* uz = vz.data() + b;
  float* xx = sxx.data() + b;
  float* yy = syy.data() + b;
  float* zz = szz.data() + b;
  float* xy = sxy.data() + b;
  float* xz = sxz.data() + b;
  float* yz = syz.data() + b;
  const int cx = pmlx.count();
  {  // restrict-qualified so that it vectorizes; memory variables below
    float* __restrict X = xx;
    float* __restrict YY = yy;
    float* __restrict ZZ = zz;
    float* __restrict XY = xy;
    float* __restrict XZ = xz;
    const float* __restrict U = ux;
    const float* __restrict V = uy;
    const float* __restrict W = uz;
    const float* __restrict bh = pmlx.b_half.data();
    const float* __restrict ah = pmlx.a_half.data();
    const float* __restrict bf = pmlx.b_full.data();
    const float* __restrict af = pmlx.a_full.data();
    // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
    for (const auto& run : pmlx.runs) {
      const int i0 = run[0], i1 = run[1], s0 = run[2];
      const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
      float* __restrict q0 = psix[3].data() + p;
      float* __restrict q1 = psix[4].data() + p;
      float* __restrict q2 = psix[5].data() + p;
#pragma omp simd
      for (int i = i0; i < i1; ++i) {
        const int q = i - i0;
        q0[q] = bf[i] * q0[q] + af[i] * (C1 * (U[i] - U[i - 1]) + C2 * (U[i + 1] - U[i - 2]));
        X[i] += (m(LAM, i) + m(TWOMU, i)) * q0[q];
        YY[i] += m(LAM, i) * q0[q];
        ZZ[i] += m(LAM, i) * q0[q];
        q1[q] = bh[i] * q1[q] + ah[i] * (C1 * (V[i + 1] - V[i]) + C2 * (V[i + 2] - V[i - 1]));
        XY[i] += m(MUXY, i) * q1[q];
        q2[q] = bh[i] * q2[q] + ah[i] * (C1 * (W[i + 1] - W[i]) + C2 * (W[i + 2] - W[i - 1]));
        XZ[i] += m(MUXZ, i) * q2[q];
      }
    }
  }
  if (L > 0)
    // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
    for (const auto& run : pmlx.runs) {
      const int i0 = run[0], i1 = run[1], s0 = run[2];
      const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
      visco_pml(m, b, i0, i1, psix[3].data() + p, 0, psix[4].data() + p, sxy, rxy, CMXY(0), psix[5].data() + p, sxz, rxz,
                CMXZ(0));
    }
  if (const int s = pmly.count() > 0 ? pmly.slot[j] : -1; s >= 0) {
    const float bf = pmly.b_full[j], af = pmly.a_full[j], bh = pmly.b_half[j], ah = pmly.a_half[j];
    const std::size_t p = (std::size_t(k) * pmly.count() + s) * nx;
    float* p0 = psiy[3].data() + p;
    float* p1 = psiy[4].data() + p;
    float* p2 = psiy[5].data() + p;
    pml_stress_row<MUXY, MUYZ>(m, nx, Y, bf, af, bh, ah, p0, p1, p2, yy, xx, zz, xy, yz, uy, ux, uz);
    if (L > 0) visco_pml(m, b, 0, nx, p0, 1, p1, sxy, rxy, CMXY(0), p2, syz, ryz, CMYZ(0));
  }
  if (const int s = pmlz.count() > 0 ? pmlz.slot[k] : -1; s >= 0) {
    const float bf = pmlz.b_full[k], af = pmlz.a_full[k], bh = pmlz.b_half[k], ah = pmlz.a_half[k];
    const std::size_t p = (std::size_t(s) * ny + j) * nx;
    float* p0 = psiz[3].data() + p;
    float* p1 = psiz[4].data() + p;
    float* p2 = psiz[5].data() + p;
    pml_stress_row<MUXZ, MUYZ>(m, nx, Z, bf, af, bh, ah, p0, p1, p2, zz, xx, yy, xz, yz, uz, ux, uy);
    if (L > 0) visco_pml(m, b, 0, nx, p0, 2, p1, sxz, rxz, CMXZ(0), p2, syz, ryz, CMYZ(0));
  }
  if constexpr (Zm == 1)
    for (int i = 0; i < nx; ++i) zz[i] = 0.0f;
}

// Stress row (k, j) with its memory variables, CPML corrections and moment sources.
void Solver::Impl::stress_row_at(int k, int j, double t) {
  const int g = k + kb;
  const int zm = !free_surface ? 0 : g == 0 ? 1 : g == 1 ? 2 : 0;
  const std::size_t r = std::size_t(k) * ny + j;
  if (const int u = row_mat[r]; u >= 0) {
    const UniformMat um{mat_tuples.data() + std::size_t(u) * K};
    if (zm == 0) stress_row<0>(k, j, um);
    else if (zm == 1) stress_row<1>(k, j, um);
    else stress_row<2>(k, j, um);
  } else if (mat_table) {
    if (zm == 0) stress_row<0>(k, j, table_mat());
    else if (zm == 1) stress_row<1>(k, j, table_mat());
    else stress_row<2>(k, j, table_mat());
  } else {
    if (zm == 0) stress_row<0>(k, j, dense_mat());
    else if (zm == 1) stress_row<1>(k, j, dense_mat());
    else stress_row<2>(k, j, dense_mat());
  }
  for (int e = stress_first[r]; e < stress_first[r + 1]; ++e) {
    const Injection& q = stress_rows[e];
    q.field[q.n] += float(q.weight * sources[q.source].stf.rate(t));
  }
}

// Rows [j0, j1) of stress plane k (worksharing when called inside a parallel region).
void Solver::Impl::stress_rows_(int k, int j0, int j1, double t) {
#pragma omp for schedule(static)
  for (int j = j0; j < j1; ++j) stress_row_at(k, j, t);
}

// The fused, cache-blocked sweep over velocity planes [kv0, kv1) and stress planes [ks0, ks1)
// (every velocity plane a stress plane needs must be new, either in the range or already done).
// Along z, stress plane m follows velocity plane m+2. Along y the rows are cut into blocks of
// `yblock` rows, swept one after the other through all planes so that the z neighbourhood of a
// block (≈ 5 planes of each field) stays in L2; the stress rows of a block lag its velocity rows
// by 2 (stress row j needs velocity rows j−2 … j+2 and is read, old, by the same ones). Each
// OpenMP thread sweeps its own contiguous range of rows; the 4 stress rows around the seams
// between threads follow after a barrier.
void Solver::Impl::sweep(int kv0, int kv1, int ks0, int ks1, double tv, double ts) {
  const int nth = std::max(1, std::min(omp_get_num_threads(), ny / 16));
  const int t = omp_get_thread_num();
  if (t < nth) {
    const int J0 = int(long(ny) * t / nth), J1 = int(long(ny) * (t + 1) / nth);
    const int S0 = J0 == 0 ? 0 : J0 + 2, S1 = J1 == ny ? ny : J1 - 2;
    for (int jb = J0; jb < J1; jb += yblock) {
      const int v0 = jb, v1 = std::min(jb + yblock, J1);
      const int s0 = jb == J0 ? S0 : jb - 2, s1 = v1 == J1 ? S1 : v1 - 2;
      for (int k = kv0; k < kv1; ++k) {
        for (int j = v0; j < v1; ++j) velocity_row_at(k, j, tv);
        if (k - 2 >= ks0 && k - 2 < ks1)
          for (int j = s0; j < s1; ++j) stress_row_at(k - 2, j, ts);
      }
      for (int m = std::max(ks0, kv1 - 2); m < ks1; ++m)
        for (int j = s0; j < s1; ++j) stress_row_at(m, j, ts);
    }
  }
#pragma omp barrier
  if (t + 1 < nth) {
    const int J1 = int(long(ny) * (t + 1) / nth);
    for (int m = ks0; m < ks1; ++m)
      for (int j = J1 - 2; j < J1 + 2; ++j) stress_row_at(m, j, ts);
  }
#pragma omp barrier
}

// Stress imaging (Levander 1988): σzz is antisymmetric about the surface plane z = 0, as are σxz
// and σyz about it (their planes sit at z = ±h/2, ±3h/2).
void Solver::Impl::free_surface_images() {
  if (!free_surface || kb != 0) return;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      szz[idx(i, j, -1)] = -szz[idx(i, j, 1)];
      szz[idx(i, j, -2)] = -szz[idx(i, j, 2)];
      sxz[idx(i, j, -1)] = -sxz[idx(i, j, 0)];
      sxz[idx(i, j, -2)] = -sxz[idx(i, j, 1)];
      syz[idx(i, j, -1)] = -syz[idx(i, j, 0)];
      syz[idx(i, j, -2)] = -syz[idx(i, j, 1)];
    }
}

// ==================================================================== communication

void Solver::Impl::start_exchange(std::initializer_list<Vec*> fields) {
#ifdef PANOPTES_HAVE_MPI
  if (comm == MPI_COMM_NULL || size == 1) return;
  reqs.clear();
  const int up = rank - 1, down = rank + 1 < size ? rank + 1 : -1;
  const int count = int(2 * sz);
  int f = 0;
  for (Vec* v : fields) {
    float* d = v->data();
    if (up >= 0) {
      reqs.emplace_back();
      MPI_Irecv(d + idx(-G, -G, -2), count, MPI_FLOAT, up, 2 * f + 1, comm, &reqs.back());
      reqs.emplace_back();
      MPI_Isend(d + idx(-G, -G, 0), count, MPI_FLOAT, up, 2 * f, comm, &reqs.back());
    }
    if (down >= 0) {
      reqs.emplace_back();
      MPI_Irecv(d + idx(-G, -G, nzl), count, MPI_FLOAT, down, 2 * f, comm, &reqs.back());
      reqs.emplace_back();
      MPI_Isend(d + idx(-G, -G, nzl - 2), count, MPI_FLOAT, down, 2 * f + 1, comm, &reqs.back());
    }
    ++f;
  }
#else
  (void)fields;
#endif
}

void Solver::Impl::finish_exchange() {
#ifdef PANOPTES_HAVE_MPI
  if (!reqs.empty()) MPI_Waitall(int(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  reqs.clear();
#endif
}

// ==================================================================== stepping

// Fused sweep: stress plane m needs the new velocities of planes m−2 … m+2 and is needed (old)
// by the velocity planes m−2 … m+2, so it is updated right after velocity plane m+2. Each field
// plane is then read from memory about once per step instead of twice (velocity and stress
// passes), and the CPML corrections are applied while their row is in cache. Per cell the
// arithmetic (and its order) is that of separate passes, so results do not depend on the order
// of planes or on the decomposition.
void Solver::Impl::step() {
  // Subnormal values flushed to zero on every thread of the step (denormals.hpp: the paper's early
  // steps up to 3x faster), the callers' modes restored after.
  const FlushSubnormals flush;
  const double tv = nsteps * dt;          // σ^n: body forces act at t_n
  const double ts = (nsteps + 0.5) * dt;  // v^{n+½}: moment rates act at t_{n+½}
  if (size == 1) {
#pragma omp parallel
    {
      const FlushSubnormals team;
      sweep(0, nzl, 0, nzl, tv, ts);
    }
  } else {
    // Rank-boundary velocity planes first; their halos travel while the interior is swept (the
    // interior stress planes 2 … nzl−3 need no velocity halo). The stress halos (6 fields × 2 planes)
    // are exchanged after the boundary stress planes: the next step's boundary velocity planes need
    // them at once.
    std::vector<int> edge;
    for (int k : {0, 1, nzl - 2, nzl - 1})
      if (k >= 0 && k < nzl && std::find(edge.begin(), edge.end(), k) == edge.end()) edge.push_back(k);
#pragma omp parallel
    {
      const FlushSubnormals team;
      for (int k : edge) velocity_plane(k, tv);
    }
    start_exchange({&vx, &vy, &vz});
    if (nzl > 4) {
#pragma omp parallel
      {
        const FlushSubnormals team;
        sweep(2, nzl - 2, 2, nzl - 2, tv, ts);
      }
    }
    finish_exchange();
#pragma omp parallel
    {
      const FlushSubnormals team;
      for (int k : edge) stress_plane(k, ts);
    }
    start_exchange({&sxx, &syy, &szz, &sxy, &sxz, &syz});
    finish_exchange();
  }
  free_surface_images();
  if (nsteps % cfg.record_every == 0) record();
  ++nsteps;
}

}  // namespace panoptes::seismic
