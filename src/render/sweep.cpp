#include "render/ray_box.hpp"
#include "render/sweep.hpp"

// Sections: the sweep's tasks compiled (SweepPlan), the isosurface ray (iso_ray), the volume ray
// (volume_ray), the pixel loop (render_sweep). The per-sample operations are render_brick()'s
// (ray_march.cpp): the same interpolation of sample k at the same position bits, the same hit
// refinement and shading, the same compositing kernels, so a sweep frame is the task's own image.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <cstring>
#ifdef __linux__
#include <sys/mman.h>
#endif
#include <string>

#include "camera/pixel_rays.hpp"
#include "core/error.hpp"
#include "render/compositing_kernels.hpp"
#include "render/iso_shading.hpp"
#include "render/march_plan.hpp"
#include "render/sample_blocks.hpp"

namespace panoptes::render {

namespace {

using march::kBlock;
using march::kRowShift;

inline std::uint8_t sweep_byte(float c) {  // as finish_image()'s rounding: k/255 comes back as k
  const float v = (c > 0.0f ? std::min(c, 1.0f) : 0.0f) * 255.0f;
  return std::uint8_t(int(double(v) + 0.5));
}

// The sweep compiled once per call: the field's access (from the march plan of its first task, so
// the same corner copy and clamps), the isovalues sorted, or per window its LUT rows and the value
// range where its opacity is not zero.
struct SweepPlan {
  march::MarchPlan base;  // of tasks[0]: field access, step, termination, grid
  bool iso = false;
  int K = 0;
  // Isosurfaces: order[j] = task of the j-th smallest isovalue, sorted[j] its isovalue.
  std::vector<int> order;
  std::vector<float> sorted;
  std::vector<std::array<float, 3>> colour;  // per task
  // Volume windows: rows, bin mapping, and the hull [vis_lo, vis_hi] of values (|v| for an
  // absolute-value map) that reach a bin of non-zero opacity (empty: vis_lo > vis_hi).
  // Each window's LUT rows, shared between windows whose rows are the same (one transfer function
  // over windows of one width: a window sweep's usual case): 1,000 tables of 16 KB each missed the
  // caches on every sample, one table stays in L1.
  std::vector<std::vector<march::VolRow>> tables;
  std::vector<const march::VolRow*> rows;
  std::vector<int> table_of;
  std::vector<float> lo, sc, last, vis_lo, vis_hi;
  std::vector<char> absv;
  bool same_abs = false;    // every window maps v, or every window |v|
  std::vector<int> by_vis;  // windows in increasing vis_lo (same_abs), else in task order
};

SweepPlan compile_sweep(std::span<const PreparedField> fields, std::span<const TaskSpec> tasks,
                        const RenderOptions& opt) {
  SweepPlan P;
  P.base = march::compile_march_plan(fields, tasks.first(1), opt);
  P.K = int(tasks.size());
  P.iso = tasks[0].kind == TaskKind::isosurface;
  if (P.iso) {
    P.order.resize(tasks.size());
    std::iota(P.order.begin(), P.order.end(), 0);
    for (const TaskSpec& t : tasks)
      if (!std::isfinite(t.isovalue))
        throw Error("render_sweep: isovalue " + std::to_string(t.isovalue) + "; expected a finite value");
    std::stable_sort(P.order.begin(), P.order.end(),
                     [&](int a, int b) { return tasks[std::size_t(a)].isovalue < tasks[std::size_t(b)].isovalue; });
    for (int i : P.order) P.sorted.push_back(tasks[std::size_t(i)].isovalue);
    for (const TaskSpec& t : tasks) P.colour.push_back({t.surface_colour.r, t.surface_colour.g, t.surface_colour.b});
    return P;
  }
  for (const TaskSpec& t : tasks) {
    const TransferLut lut(t.tf, t.window.resolve(t.reference), opt.sample_distance);
    std::vector<march::VolRow> r = march::vol_rows(lut);
    std::size_t u = 0;
    const std::size_t first = P.tables.size() > 16 ? P.tables.size() - 16 : 0;  // the recent ones suffice
    for (u = first; u < P.tables.size(); ++u)
      if (P.tables[u].size() == r.size() &&
          std::memcmp(P.tables[u].data(), r.data(), r.size() * sizeof(march::VolRow)) == 0)
        break;
    if (u == P.tables.size()) P.tables.push_back(std::move(r));
    P.rows.push_back(nullptr);  // pointed into tables once they stop moving (below)
    P.table_of.push_back(int(u));
    P.lo.push_back(lut.lo()), P.sc.push_back(lut.scale()), P.last.push_back(float(lut.bins() - 1));
    P.absv.push_back(lut.absolute_value());
    // Bins b with non-zero opacity hold the values v with b ≤ (v − lo)·sc < b + 1 (clamped at both
    // ends): the hull of those bins, widened by a bin for rounding, in values.
    int b0 = lut.bins(), b1 = -1;
    for (int b = 0; b < lut.bins(); ++b)
      if (lut.entry(b).alpha > 0) b0 = std::min(b0, b), b1 = b;
    float vl = INFINITY, vh = -INFINITY;
    if (b1 >= 0) {
      vl = b0 <= 1 ? -INFINITY : lut.lo() + float(b0 - 1) / lut.scale();
      vh = b1 >= lut.bins() - 2 ? INFINITY : lut.lo() + float(b1 + 2) / lut.scale();
    }
    P.vis_lo.push_back(vl), P.vis_hi.push_back(vh);
  }
  for (std::size_t i = 0; i < P.rows.size(); ++i) P.rows[i] = P.tables[std::size_t(P.table_of[i])].data();
  P.same_abs = std::all_of(P.absv.begin(), P.absv.end(), [&](char a) { return a == P.absv[0]; });
  P.by_vis.resize(tasks.size());
  std::iota(P.by_vis.begin(), P.by_vis.end(), 0);
  if (P.same_abs)
    std::stable_sort(P.by_vis.begin(), P.by_vis.end(),
                     [&](int a, int b) { return P.vis_lo[std::size_t(a)] < P.vis_lo[std::size_t(b)]; });
  return P;
}

// The ray's geometry as render_brick() computes it for a one-brick domain.
struct Ray {
  double O[3], D[3];
  Vec3 dir;
  double t0, tg1;
};

// Per-thread scratch of the volume ray: accumulators and the live windows.
struct VolumeScratch {
  std::vector<std::array<float, 4>> acc;
  std::vector<int> live;
};

// The isosurface sweep's gradient field: ∇f as shade_hit() computes it (central differences of the
// trilinear field at ±0.5 voxel, one-sided at the domain's faces) is, per axis, exactly the trilinear
// interpolation of the staggered differences (f(i+1) − f(i))/h at the point shifted by half a voxel
// along that axis (the difference of two linear pieces half a voxel apart is linear between the
// midpoints; clamping the shifted coordinate to the staggered grid gives the one-sided faces). So
// three interpolations per sample instead of six. Built once per render_sweep() call, into buffers
// its calling thread keeps.
struct StaggeredGradients {
  std::vector<float> d[3];
  march::FieldAcc acc[3];

  // Recomputes the differences of `v` (the buffers' capacity is kept from call to call: a fresh
  // 12 bytes per point each call cost more in page faults than computing them).
  void build(const FieldView& v) {
    const Index3 lo = v.points.lo;
    const int n[3] = {v.points.hi[0] - lo[0], v.points.hi[1] - lo[1], v.points.hi[2] - lo[2]};
    for (int ax = 0; ax < 3; ++ax) {
      int m[3] = {n[0], n[1], n[2]};
      m[ax] = std::max(1, n[ax] - 1);
      d[ax].resize(std::size_t(m[0]) * std::size_t(m[1]) * std::size_t(m[2]));
      const float inv_h = float(1.0 / v.grid.spacing[ax]);
      float* out = d[ax].data();
      const int e[3] = {ax == 0, ax == 1, ax == 2};
#pragma omp parallel for schedule(static)
      for (int k = 0; k < m[2]; ++k)
        for (int j = 0; j < m[1]; ++j)
          for (int i = 0; i < m[0]; ++i) {
            const int gi = lo[0] + i, gj = lo[1] + j, gk = lo[2] + k;
            out[(std::size_t(k) * std::size_t(m[1]) + std::size_t(j)) * std::size_t(m[0]) + std::size_t(i)] =
                n[ax] > 1 ? (v.at(gi + e[0], gj + e[1], gk + e[2]) - v.at(gi, gj, gk)) * inv_h : 0.0f;
          }
      march::FieldAcc& a = acc[ax];
      a.data = d[ax].data();
      a.sx = 1, a.sy = m[0], a.sz = std::int64_t(m[0]) * m[1];
      a.off0 = -(lo[0] * a.sx + lo[1] * a.sy + lo[2] * a.sz);
      for (int q = 0; q < 3; ++q) {
        a.ilo[q] = lo[q];
        a.ihi[q] = std::max(lo[q], lo[q] + m[q] - 2);
        a.plo[q] = float(lo[q]);
        a.phi[q] = float(lo[q] + m[q] - 1);
      }
      a.gather32 = std::int64_t(m[0]) * m[1] * m[2] + a.sx + a.sy + a.sz < (std::int64_t(1) << 31);
    }
  }

  // g[axis][l] = ∇f at samples k_first … k_first + count − 1 (count ≤ 16) of the ray P.
  void at_samples(const march::RayPos& P, std::int64_t k_first, int count, float (*g)[16]) const {
#ifdef PANOPTES_RENDER_AVX2
    if (acc[0].gather32 && acc[1].gather32 && acc[2].gather32) {
      const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
      for (int c0 = 0; c0 < count; c0 += 8) {
        const __m256 fk = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(int(k_first + c0)), lane));
        const __m256 p[3] = {_mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx)),
                             _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by)),
                             _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz))};
        for (int ax = 0; ax < 3; ++ax) {
          const march::FieldAcc& a = acc[ax];
          __m256 q[3];
          for (int b = 0; b < 3; ++b) {
            const __m256 x = b == ax ? _mm256_sub_ps(p[b], _mm256_set1_ps(0.5f)) : p[b];
            q[b] = _mm256_min_ps(_mm256_max_ps(x, _mm256_set1_ps(a.plo[b])), _mm256_set1_ps(a.phi[b]));
          }
          _mm256_storeu_ps(g[ax] + c0, march::trilinear8(a, q[0], q[1], q[2]));
        }
      }
      return;
    }
#endif
    for (int l = 0; l < count; ++l) {
      const float fk = float(k_first + l);
      const float p[3] = {P.bx + fk * P.sx, P.by + fk * P.sy, P.bz + fk * P.sz};
      for (int ax = 0; ax < 3; ++ax) {
        float q[3] = {p[0], p[1], p[2]};
        q[ax] -= 0.5f;
        g[ax][l] = march::interp_clamped(acc[ax], q[0], q[1], q[2]);
      }
    }
  }
};

// The number of sorted isovalues ≤ v (std::upper_bound) through a bucket table over their range:
// one lookup and a step or two instead of a binary search per sample.
struct IsoIndex {
  const float* iso = nullptr;
  int K = 0;
  float lo = 0, scale = 0;
  std::vector<int> table;  // table[b] ≈ isovalues ≤ the lower edge of bucket b

  explicit IsoIndex(const std::vector<float>& sorted) : iso(sorted.data()), K(int(sorted.size())) {
    const int B = 4 * K;
    lo = sorted.front();
    const float span = sorted.back() - sorted.front();
    scale = span > 0 ? float(B) / span : 0.0f;
    table.resize(std::size_t(B) + 1);
    for (int b = 0; b <= B; ++b) {
      const float edge = scale > 0 ? lo + float(b) / scale : lo;
      table[std::size_t(b)] = int(std::upper_bound(iso, iso + K, edge) - iso);
    }
  }
  // ib[l] = operator()(v[l]) for l < 8, or −1 where v[l] is NaN or infinite.
  void block(const float* v, int* ib) const {
#ifdef PANOPTES_RENDER_AVX2
    const __m256 x = _mm256_loadu_ps(v);
    const __m256 finite = _mm256_cmp_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), x), _mm256_set1_ps(INFINITY), _CMP_LT_OQ);
    const __m256 u = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(x, _mm256_set1_ps(lo)), _mm256_set1_ps(scale)),
                                                 _mm256_setzero_ps()),
                                   _mm256_set1_ps(float(table.size() - 1)));
    const __m256i b = _mm256_and_si256(_mm256_cvttps_epi32(u), _mm256_castps_si256(finite));  // NaN lanes: bucket 0
    __m256i j = _mm256_i32gather_epi32(table.data(), b, 4);
    const __m256i Kv = _mm256_set1_epi32(K), one = _mm256_set1_epi32(1), zero = _mm256_setzero_si256();
    // One step up (the bucket's edge may lie below an isovalue ≤ v), then check both neighbours.
    auto iso_at = [&](__m256i idx) {
      return _mm256_i32gather_ps(iso, _mm256_min_epi32(_mm256_max_epi32(idx, zero), _mm256_sub_epi32(Kv, one)), 4);
    };
    const __m256 up = _mm256_and_ps(_mm256_cmp_ps(iso_at(j), x, _CMP_LE_OQ), _mm256_castsi256_ps(_mm256_cmpgt_epi32(Kv, j)));
    j = _mm256_sub_epi32(j, _mm256_castps_si256(up));  // true lanes are −1: j + 1
    const __m256 above_ok = _mm256_or_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(j, Kv)), _mm256_cmp_ps(iso_at(j), x, _CMP_GT_OQ));
    const __m256 below_ok = _mm256_or_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(j, zero)),
                                         _mm256_cmp_ps(iso_at(_mm256_sub_epi32(j, one)), x, _CMP_LE_OQ));
    const int ok = _mm256_movemask_ps(_mm256_and_ps(above_ok, below_ok));
    const int fin = _mm256_movemask_ps(finite);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(ib), j);
    for (int l = 0; l < 8; ++l)
      if (!(fin >> l & 1)) ib[l] = -1;
      else if (!(ok >> l & 1)) ib[l] = (*this)(v[l]);
#else
    for (int l = 0; l < 8; ++l) ib[l] = std::isfinite(v[l]) ? (*this)(v[l]) : -1;
#endif
  }
  int operator()(float v) const {  // v finite
    if (v < lo) return 0;
    const float u = (v - lo) * scale;
    int j = table[std::size_t(std::min(u, float(table.size() - 1)))];
    while (j < K && iso[j] <= v) ++j;
    while (j > 0 && iso[j - 1] > v) --j;
    return j;
  }
};

// Per-thread scratch of the isosurface ray: hit bits per sorted isovalue, and a block's hits.
struct IsoScratch {
  std::vector<std::uint64_t> hit;
  std::vector<int> hj;  // sorted index of each hit, segment by segment
  explicit IsoScratch(int K) : hit(std::size_t((K + 63) / 64)), hj(std::size_t(K) + 8) {}
};

// Marks the isovalues sorted[j0 … j1) not hit yet as hit and appends them to the block's hits
// (sc.hj from index nh; sized for every isovalue). Returns the new count.
inline int take_hits(IsoScratch& sc, int nh, int j0, int j1) {
  for (int w = j0 >> 6; w <= (j1 - 1) >> 6; ++w) {
    std::uint64_t m = ~sc.hit[std::size_t(w)];
    if (w == j0 >> 6) m &= ~std::uint64_t(0) << (j0 & 63);
    if (w == (j1 - 1) >> 6 && ((j1 - 1) & 63) != 63) m &= (std::uint64_t(1) << (((j1 - 1) & 63) + 1)) - 1;
    sc.hit[std::size_t(w)] |= m;
    for (; m; m &= m - 1, ++nh) sc.hj[std::size_t(nh)] = w * 64 + std::countr_zero(m);
  }
  return nh;
}
inline bool any_unhit(const std::vector<std::uint64_t>& hit, int j0, int j1) {
  for (int w = j0 >> 6; w <= (j1 - 1) >> 6; ++w) {
    std::uint64_t m = ~hit[std::size_t(w)];
    if (w == j0 >> 6) m &= ~std::uint64_t(0) << (j0 & 63);
    if (w == (j1 - 1) >> 6 && ((j1 - 1) & 63) != 63) m &= (std::uint64_t(1) << (((j1 - 1) & 63) + 1)) - 1;
    if (m) return true;
  }
  return false;
}

// The segment count from which a segment's hits take the field from its cubic (iso_ray()).
constexpr int kCubicHits = 3;

// v[q] = the field at positions k[q] (in samples along the ray P) for q < m ≤ 16, eight at a time.
inline void interp_at(const march::FieldAcc& f, const march::RayPos& P, const float* k, int m, float* v) {
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    for (int q0 = 0; q0 < m; q0 += 8) {
      // The positions read element by element (a gather): each element forwards from its own scalar
      // store, where one 32-byte load of the eight would wait for all of them to reach the cache
      // (Round 19). Lanes past m repeat position m − 1.
      const __m256i idx = _mm256_min_epi32(_mm256_setr_epi32(q0, q0 + 1, q0 + 2, q0 + 3, q0 + 4, q0 + 5, q0 + 6, q0 + 7),
                                           _mm256_set1_epi32(m - 1));
      const __m256 k8 = _mm256_i32gather_ps(k, idx, 4);
      auto pos = [&](float b, float st, int ax) {
        return _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(k8, _mm256_set1_ps(st), _mm256_set1_ps(b)), _mm256_set1_ps(f.plo[ax])),
                             _mm256_set1_ps(f.phi[ax]));
      };
      _mm256_storeu_ps(v + q0, march::trilinear8(f, pos(P.bx, P.sx, 0), pos(P.by, P.sy, 1), pos(P.bz, P.sz, 2)));
    }
    return;
  }
#endif
  for (int q = 0; q < m; ++q) v[q] = march::interp_clamped(f, P.bx + k[q] * P.sx, P.by + k[q] * P.sy, P.bz + k[q] * P.sz);
}

// Hits hj[0 … m) of one segment (samples k_a = k_seg and k_a + 1 of the ray P, values va and vc):
// each placed as render_brick() places a hit — the linear estimate, one regula-falsi step with the
// field there (from the segment's cubic, or interpolated where cubic is null) — shaded with the
// gradient of the segment's Catmull–Rom spline cr (per axis c0 + s·(c1 + s·(c2 + s·c3))) and written
// as SweepFrames' 2-byte code 1 + |n·l|·65534 (a zero gradient faces the camera) to slot px + 2·j.
void place_hits(const march::FieldAcc& f, const march::RayPos& P, float k_seg, float va, float vc, const float* cubic,
                const float (*cr)[4], const float* iso, const int* hj, int m, const float dir[3], std::uint8_t* px) {
  int h = 0;
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    const __m256 Va = _mm256_set1_ps(va), Vd = _mm256_set1_ps(va - vc), one = _mm256_set1_ps(1.0f),
                 zero = _mm256_setzero_ps(), sign = _mm256_set1_ps(-0.0f);
    for (; h < m; h += 8) {
      // Lanes past m read the isovalues of whatever hj holds there (the scratch is sized for K + 8
      // hits and holds isovalue indices only); their results are not written.
      const __m256 is = _mm256_i32gather_ps(iso, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(hj + h)), 4);
      const __m256 s1 = _mm256_div_ps(_mm256_sub_ps(Va, is), Vd);
      __m256 v;
      if (cubic) {
        const __m256 t = _mm256_mul_ps(s1, _mm256_set1_ps(3.0f));
        v = _mm256_fmadd_ps(_mm256_sub_ps(t, _mm256_set1_ps(2.0f)), _mm256_set1_ps(cubic[3]), _mm256_set1_ps(cubic[2]));
        v = _mm256_fmadd_ps(_mm256_sub_ps(t, one), v, _mm256_set1_ps(cubic[1]));
        v = _mm256_fmadd_ps(t, v, _mm256_set1_ps(cubic[0]));
      } else {
        const __m256 k8 = _mm256_add_ps(_mm256_set1_ps(k_seg), s1);
        auto pos = [&](float b, float st, int ax) {
          return _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(k8, _mm256_set1_ps(st), _mm256_set1_ps(b)), _mm256_set1_ps(f.plo[ax])),
                               _mm256_set1_ps(f.phi[ax]));
        };
        v = march::trilinear8(f, pos(P.bx, P.sx, 0), pos(P.by, P.sy, 1), pos(P.bz, P.sz, 2));
      }
      // The regula-falsi step: the sub-segment whose ends straddle the isovalue, its secant.
      const __m256 v1 = _mm256_sub_ps(v, is), fa0 = _mm256_sub_ps(Va, is), fb0 = _mm256_sub_ps(_mm256_set1_ps(vc), is);
      // (v1 < 0) != (fa0 < 0): the root lies in [0, s1] (else in [s1, 1]), as the scalar form tests.
      const __m256 diff = _mm256_xor_ps(_mm256_cmp_ps(v1, zero, _CMP_LT_OQ), _mm256_cmp_ps(fa0, zero, _CMP_LT_OQ));
      const __m256 sa = _mm256_andnot_ps(diff, s1), sb = _mm256_blendv_ps(one, s1, diff);
      const __m256 fa = _mm256_blendv_ps(v1, fa0, diff), fb = _mm256_blendv_ps(fb0, v1, diff);
      const __m256 den = _mm256_sub_ps(fa, fb);
      const __m256 s = _mm256_blendv_ps(s1, _mm256_fmadd_ps(_mm256_sub_ps(sb, sa), _mm256_div_ps(fa, den), sa),
                                        _mm256_cmp_ps(den, zero, _CMP_NEQ_OQ));
      auto spline = [&](int a) {
        __m256 g = _mm256_fmadd_ps(s, _mm256_set1_ps(cr[a][3]), _mm256_set1_ps(cr[a][2]));
        g = _mm256_fmadd_ps(s, g, _mm256_set1_ps(cr[a][1]));
        return _mm256_fmadd_ps(s, g, _mm256_set1_ps(cr[a][0]));
      };
      const __m256 gx = spline(0), gy = spline(1), gz = spline(2);
      const __m256 nn = _mm256_fmadd_ps(gx, gx, _mm256_fmadd_ps(gy, gy, _mm256_mul_ps(gz, gz)));
      const __m256 d = _mm256_fmadd_ps(gx, _mm256_set1_ps(dir[0]), _mm256_fmadd_ps(gy, _mm256_set1_ps(dir[1]), _mm256_mul_ps(gz, _mm256_set1_ps(dir[2]))));
      __m256 ndl = _mm256_min_ps(one, _mm256_div_ps(_mm256_andnot_ps(sign, d), _mm256_sqrt_ps(nn)));
      ndl = _mm256_blendv_ps(one, ndl, _mm256_cmp_ps(nn, zero, _CMP_GT_OQ));
      const __m256i code = _mm256_add_epi32(
          _mm256_cvttps_epi32(_mm256_fmadd_ps(ndl, _mm256_set1_ps(65534.0f), _mm256_set1_ps(0.5f))), _mm256_set1_epi32(1));
      alignas(32) std::uint32_t out[8];
      _mm256_store_si256(reinterpret_cast<__m256i*>(out), code);
      for (int q = 0; q < std::min(8, m - h); ++q) {
        const std::uint16_t c = std::uint16_t(out[q]);
        std::memcpy(px + 2 * std::size_t(hj[h + q]), &c, 2);
      }
    }
    return;
  }
#endif
  for (; h < m; ++h) {
    const float is = iso[hj[h]];
    const float s1 = (va - is) / (va - vc);
    float v;
    if (cubic) {
      const float t = 3.0f * s1;
      v = cubic[0] + t * (cubic[1] + (t - 1.0f) * (cubic[2] + (t - 2.0f) * cubic[3]));
    } else {
      const float k = k_seg + s1;
      v = march::interp_clamped(f, P.bx + k * P.sx, P.by + k * P.sy, P.bz + k * P.sz);
    }
    const float dpa = va - is, dpb = vc - is, v1 = v - is;
    float sa = 0, sb = 1, fa = dpa, fb = dpb;
    if ((v1 < 0) == (dpa < 0)) sa = s1, fa = v1;
    else sb = s1, fb = v1;
    const float s = fa != fb ? sa + (sb - sa) * (fa / (fa - fb)) : s1;
    float gv[3];
    for (int a = 0; a < 3; ++a) gv[a] = cr[a][0] + s * (cr[a][1] + s * (cr[a][2] + s * cr[a][3]));
    const float nn = gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2];
    const float ndl = nn > 0 ? std::min(1.0f, std::fabs(gv[0] * dir[0] + gv[1] * dir[1] + gv[2] * dir[2]) / std::sqrt(nn)) : 1.0f;
    const std::uint16_t c = std::uint16_t(int(ndl * 65534.0f + 0.5f) + 1);
    std::memcpy(px + 2 * std::size_t(hj[h]), &c, 2);
  }
}

// One isosurface-sweep ray: writes slot j's code (px + 2·j) for every sorted isovalue j it hits.
// Returns the samples interpolated.
//
// A hit is found and placed as render_brick() places one: the first segment (samples k − 1, k)
// whose values straddle the isovalue, the linear estimate in it, one regula-falsi step with the
// field there — interpolated where the segment crosses one or two isovalues, from the segment's
// cubic where it crosses more (a 1,000-value sweep crosses 12.5 per segment with hits on
// sweep_bench's scene). It is shaded with the gradient of the Catmull–Rom spline through the
// gradients at samples k − 2 … k + 1 (shade_hit() evaluates six interpolations per hit; such a
// sweep makes hundreds of hits per ray).
std::uint64_t iso_ray(const SweepPlan& SP, const StaggeredGradients& G, const IsoIndex& X, const Ray& r,
                      IsoScratch& sc, std::uint8_t* px) {
  const march::MarchPlan& S = SP.base;
  const march::FieldAcc& f = S.acc[0];
  const double dt = S.dt, t0 = r.t0;
  const std::int64_t kg_last = std::int64_t(std::ceil((r.tg1 - t0) / dt)) - 1;
  if (kg_last < 1) return 0;
  const march::RayPos P{float(r.O[0] + t0 * r.D[0]), float(r.O[1] + t0 * r.D[1]), float(r.O[2] + t0 * r.D[2]),
                        float(dt * r.D[0]),          float(dt * r.D[1]),          float(dt * r.D[2])};
  std::fill(sc.hit.begin(), sc.hit.end(), 0);
  int remaining = SP.K;
  const float* iso = SP.sorted.data();
  const float dir[3] = {float(r.dir[0]), float(r.dir[1]), float(r.dir[2])};
  alignas(32) float vb[kBlock + 1];
  alignas(32) int ib[kBlock + 1];  // isovalues ≤ vb[l] (−1: NaN or infinite)
  // Gradients at samples k0 − 2 … k0 + 8 (g[axis][i] ↔ sample k0 − 2 + i).
  alignas(32) float g[3][16];
  bool g_valid = false;  // g[·][0 … 2] hold samples k0 − 2 … k0 (carried from the previous block)
  std::uint64_t marched = 0;
  for (std::int64_t k0 = 0; k0 <= kg_last && remaining > 0; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kg_last - k0 + 1));
    march::interp_block(f, P, k0, n, false, vb + 1);
    marched += std::uint64_t(n);
    const int l0 = k0 == 0 ? 1 : 0;  // the first segment ends at sample 1
    if (k0 == 0) vb[0] = vb[1], ib[0] = -1;
    int bmin = SP.K, bmax = 0;
    X.block(vb + 1, ib + 1);
    for (int l = 1; l <= n; ++l)
      if (ib[l] >= 0) bmin = std::min(bmin, ib[l]), bmax = std::max(bmax, ib[l]);
    if (l0 == 0 && ib[0] >= 0) bmin = std::min(bmin, ib[0]), bmax = std::max(bmax, ib[0]);
    // The block's crossings all lie in [bmin, bmax): late on a ray most blocks cross only isovalues hit already.
    if (!(bmin < bmax && any_unhit(sc.hit, bmin, bmax))) {
      vb[0] = vb[n], ib[0] = ib[n];
      g_valid = false;
      continue;
    }
    int nh = 0;
    int seg_first[kBlock], seg_count[kBlock];  // the block's hits of segment l: seg_first[l] … + seg_count[l]
    for (int l = l0; l < n; ++l) {
      seg_first[l] = nh, seg_count[l] = 0;
      const int ia = ib[l], ic = ib[l + 1];
      if (ia < 0 || ic < 0 || ia == ic) continue;  // no sign change (a NaN sample crosses nothing)
      nh = take_hits(sc, nh, std::min(ia, ic), std::max(ia, ic));
      seg_count[l] = nh - seg_first[l];
    }
    if (nh == 0) {
      vb[0] = vb[n], ib[0] = ib[n];
      g_valid = false;
      continue;
    }
    remaining -= nh;
    // The regula-falsi step needs the field at each hit's linear estimate. A segment that crosses
    // kCubicHits isovalues or more takes it from the cubic through the field at the segment's ends and
    // at its thirds (two interpolations for the segment: the trilinear field along a line within one
    // cell is a cubic in the ray parameter, piecewise across the cells' faces); the others' hits
    // interpolate it at the estimate itself.
    alignas(32) float cubic[kBlock][4];  // per cubic segment: y0, Δy0, ½Δ²y0, ⅙Δ³y0 on the nodes t = 0 … 3 (t = 3s)
    {
      alignas(32) float sp[16];  // positions (in samples) of the cubic segments' thirds
      int cl[kBlock], nc = 0;
      for (int l = l0; l < n; ++l)
        if (seg_count[l] >= kCubicHits) {
          sp[2 * nc] = float(k0 + l - 1) + (1.0f / 3.0f), sp[2 * nc + 1] = float(k0 + l - 1) + (2.0f / 3.0f);
          cl[nc++] = l;
        }
      alignas(32) float st[16];
      interp_at(f, P, sp, 2 * nc, st);
      for (int c = 0; c < nc; ++c) {
        const int l = cl[c];
        const float y0 = vb[l], y1 = st[2 * c], y2 = st[2 * c + 1], y3 = vb[l + 1];
        cubic[l][0] = y0, cubic[l][1] = y1 - y0, cubic[l][2] = 0.5f * (y2 - 2 * y1 + y0),
        cubic[l][3] = (y3 - 3 * y2 + 3 * y1 - y0) * (1.0f / 6.0f);
      }
    }
    // Gradients of the block's samples (and two on either side) for the splines.
    if (g_valid) {
      G.at_samples(P, k0 + 1, 8, reinterpret_cast<float(*)[16]>(&g[0][3]));
    } else {
      G.at_samples(P, k0 - 2, 11, g);
    }
    // Catmull–Rom through samples kk − 2 … kk + 1 of each segment (i = l … l + 3): c0 + s·(c1 + s·(c2 + s·c3)).
    alignas(32) float cr[kBlock][3][4];
    for (int l = l0; l < n; ++l)
      for (int a = 0; a < 3; ++a) {
        const float p0 = g[a][l], p1 = g[a][l + 1], p2 = g[a][l + 2], p3 = g[a][l + 3];
        cr[l][a][0] = p1;
        cr[l][a][1] = 0.5f * (p2 - p0);
        cr[l][a][2] = p0 - 2.5f * p1 + 2.0f * p2 - 0.5f * p3;
        cr[l][a][3] = 0.5f * (p3 - p0) + 1.5f * (p1 - p2);
      }
    // Each segment's hits placed, shaded and written (eight at a time: a segment's values,
    // cubic and spline are the same for all its hits).
    for (int l = l0; l < n; ++l)
      if (seg_count[l] > 0)
        place_hits(f, P, float(k0 + l - 1), vb[l], vb[l + 1], seg_count[l] >= kCubicHits ? cubic[l] : nullptr, cr[l],
                   iso, &sc.hj[std::size_t(seg_first[l])], seg_count[l], dir, px);
    vb[0] = vb[n], ib[0] = ib[n];
    for (int a = 0; a < 3; ++a) g[a][0] = g[a][8], g[a][1] = g[a][9], g[a][2] = g[a][10];
    g_valid = true;
  }
  return marched;
}

// One volume-sweep ray: composites every window; writes every task's pixel. Returns the samples interpolated.
std::uint64_t volume_ray(const SweepPlan& SP, const Ray& r, VolumeScratch& sc, std::uint8_t* px) {
  const march::MarchPlan& S = SP.base;
  const march::FieldAcc& f = S.acc[0];
  const double dt = S.dt, t0 = r.t0;
  const std::int64_t kg_last = std::int64_t(std::ceil((r.tg1 - t0) / dt)) - 1;
  const int K = SP.K;
  for (auto& a : sc.acc) a = {0, 0, 0, 1};
  std::uint64_t marched = 0;
  if (kg_last >= 0) {
    // The last sample stands for a shorter segment (ray_march.cpp's k_partial).
    std::int64_t k_partial = -1;
    float partial = 1;
    const double fr = (r.tg1 - (t0 + double(kg_last) * dt)) / dt;
    if (fr < 1 - 1e-6) k_partial = kg_last, partial = float(std::max(0.0, fr));
    const float tr_stop = 1.0f - S.termination;
    const march::RayPos P{float(r.O[0] + t0 * r.D[0]), float(r.O[1] + t0 * r.D[1]), float(r.O[2] + t0 * r.D[2]),
                          float(dt * r.D[0]),          float(dt * r.D[1]),          float(dt * r.D[2])};
    sc.live = SP.by_vis;
    alignas(32) float v[kBlock];
    alignas(32) int bins[4][kBlock];
    for (std::int64_t k0 = 0; k0 <= kg_last && !sc.live.empty(); k0 += kBlock) {
      const int n = int(std::min<std::int64_t>(kBlock, kg_last - k0 + 1));
      march::volume_block(f, P, k0, n, false, v);
      marched += std::uint64_t(n);
      float bmin = v[0], bmax = v[0], amin = std::fabs(v[0]), amax = amin;
      for (int l = 1; l < n; ++l)
        bmin = std::min(bmin, v[l]), bmax = std::max(bmax, v[l]), amin = std::min(amin, std::fabs(v[l])),
        amax = std::max(amax, std::fabs(v[l]));
      const bool finite = std::isfinite(bmin) && std::isfinite(bmax);
      // Windows that see something in this block, four at a time (composite_group()). With one
      // value mapping (all |v| or all v) the live windows stay sorted by the low end of their visible
      // range, so those that cannot see the block's largest value are not looked at.
      std::size_t end = sc.live.size();
      if (SP.same_abs && finite) {
        const float top = SP.absv[0] ? amax : bmax;
        end = std::size_t(std::partition_point(sc.live.begin(), sc.live.end(),
                                               [&](int w) { return SP.vis_lo[std::size_t(w)] <= top; }) -
                          sc.live.begin());
      }
      int ids[4], at[4], g = 0;
      bool died = false;
      auto flush = [&]() {
        const march::VolRow* luts[4];
        float* as[4];
        int stops[4];
        for (int q = 0; q < g; ++q) luts[q] = SP.rows[std::size_t(ids[q])], as[q] = sc.acc[std::size_t(ids[q])].data();
        switch (g) {
          case 1: march::composite_group<1>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
          case 2: march::composite_group<2>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
          case 3: march::composite_group<3>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
          default: march::composite_group<4>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
        }
        for (int q = 0; q < g; ++q)
          if (stops[q] >= 0) sc.live[std::size_t(at[q])] = -1, died = true;  // opaque: leaves the ray
        g = 0;
      };
      for (std::size_t i = 0; i < end; ++i) {
        const int w = sc.live[i];
        const float lo = SP.absv[std::size_t(w)] ? amin : bmin, hi = SP.absv[std::size_t(w)] ? amax : bmax;
        if (finite && (hi < SP.vis_lo[std::size_t(w)] || lo > SP.vis_hi[std::size_t(w)]))
          continue;  // every sample of the block is transparent for it: exact no-ops
        march::lut_bin_block<kRowShift>(v, SP.lo[std::size_t(w)], SP.sc[std::size_t(w)], SP.last[std::size_t(w)],
                                        SP.absv[std::size_t(w)] != 0, bins[g]);
        ids[g] = w, at[g++] = int(i);
        if (g == 4) flush();
      }
      if (g) flush();
      if (died) sc.live.erase(std::remove(sc.live.begin(), sc.live.end(), -1), sc.live.end());  // keeps the order
    }
  }
  for (int t = 0; t < K; ++t) {
    const std::array<float, 4>& a = sc.acc[std::size_t(t)];
    std::uint8_t* o = px + 4 * std::size_t(t);
    o[0] = sweep_byte(a[0]), o[1] = sweep_byte(a[1]), o[2] = sweep_byte(a[2]), o[3] = sweep_byte(1.0f - a[3]);
  }
  return marched;
}

// Copies a pixel's `bytes` (a multiple of 64; both 64-byte aligned) with non-temporal stores.
inline void stream_pixel(const std::uint8_t* from, std::uint8_t* to, std::size_t bytes) {
#ifdef PANOPTES_RENDER_AVX2
  for (std::size_t i = 0; i < bytes; i += 32)
    _mm256_stream_si256(reinterpret_cast<__m256i*>(to + i), _mm256_load_si256(reinterpret_cast<const __m256i*>(from + i)));
#else
  std::memcpy(to, from, bytes);
#endif
}

}  // namespace

void SweepFrames::resize(int w, int h, int tasks, int bytes) {
  width = w, height = h, count = tasks, task_bytes = bytes;
  stride = (std::size_t(bytes) * std::size_t(tasks) + 63) / 64 * 64;
  const std::size_t need = std::size_t(w) * std::size_t(h) * stride + 64;
  if (storage_.size() != need) {
    const bool grew = need > storage_.capacity();
    storage_.resize(need);
#ifdef __linux__
    // Transparent huge pages for the frames (hundreds of MB, written once per camera): a 4 KB page
    // fault per 4 KB of frames cost as much as the march of their pixels.
    if (grew) {
      const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(storage_.data()) + 4095) & ~std::uintptr_t(4095);
      const std::uintptr_t e = (reinterpret_cast<std::uintptr_t>(storage_.data()) + need) & ~std::uintptr_t(4095);
      if (e > a) ::madvise(reinterpret_cast<void*>(a), e - a, MADV_HUGEPAGE);
    }
#endif
  }
  base_ = (64 - reinterpret_cast<std::uintptr_t>(storage_.data()) % 64) % 64;
}

void SweepFrames::to_partial(int t, PartialImage& out) const {
  if (t < 0 || t >= count)
    throw Error("sweep frames: task " + std::to_string(t) + " of " + std::to_string(count));
  out.resize(width, height, {0, 0, width, height});
  const std::size_t n = std::size_t(width) * std::size_t(height);
  const std::uint8_t* p = data() + std::size_t(task_bytes) * std::size_t(slot[std::size_t(t)]);
  constexpr float inv = 1.0f / 255.0f;
  if (task_bytes == 2) {
    const std::array<float, 3>& col = colour[std::size_t(t)];
    for (std::size_t i = 0; i < n; ++i, p += stride) {
      float* o = out.rgba.data() + 4 * i;
      std::uint16_t code;
      std::memcpy(&code, p, 2);
      if (!code) {
        o[0] = o[1] = o[2] = o[3] = 0, out.depth[i] = PartialImage::kNoDepth;
        continue;
      }
      // shade_hit()'s headlight: diffuse 0.15 + 0.85·|n·l|, specular 0.25·|n·l|^32.
      const float ndl = float(code - 1) * (1.0f / 65534.0f);
      float p32 = ndl;
      for (int k = 0; k < 5; ++k) p32 *= p32;
      const float diffuse = 0.15f + 0.85f * ndl, spec = 0.25f * p32;
      for (int k = 0; k < 3; ++k) o[k] = std::min(1.0f, col[std::size_t(k)] * diffuse + spec);
      o[3] = 1, out.depth[i] = 0;
    }
    return;
  }
  for (std::size_t i = 0; i < n; ++i, p += stride) {
    float* o = out.rgba.data() + 4 * i;
    o[0] = p[0] * inv, o[1] = p[1] * inv, o[2] = p[2] * inv, o[3] = p[3] * inv;
    out.depth[i] = p[3] ? 0.0f : PartialImage::kNoDepth;
  }
}

bool is_sweep(std::span<const TaskSpec> tasks) {
  if (tasks.size() < 2) return false;
  const TaskSpec& a = tasks[0];
  if (a.kind != TaskKind::isosurface && !(a.kind == TaskKind::volume && a.field2 < 0)) return false;
  for (const TaskSpec& t : tasks)
    if (t.kind != a.kind || t.field != a.field || (t.kind == TaskKind::volume && t.field2 >= 0)) return false;
  return true;
}

RenderStats render_sweep(const camera::Camera& cam, std::span<const PreparedField> fields,
                         std::span<const TaskSpec> tasks, SweepFrames& out, const RenderOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (!is_sweep(tasks))
    throw Error("render_sweep: " + std::to_string(tasks.size()) +
                " tasks; expected at least two isosurfaces, or single-field volume tasks, all of one field");
  if (!(opt.sample_distance > 0 && opt.sample_distance <= 16))
    throw Error("render_sweep: sample distance " + std::to_string(opt.sample_distance) + " voxels; expected 0 < d <= 16");
  const int fi = tasks[0].field;
  if (fi < 0 || std::size_t(fi) >= fields.size())
    throw Error("render_sweep: tasks read field " + std::to_string(fi) + " but " + std::to_string(fields.size()) +
                " fields were given");
  const PreparedField& field = fields[std::size_t(fi)];
  const GridGeometry& grid = field.view.grid;
  for (int a = 0; a < 3; ++a)
    if (field.view.brick.lo[a] != 0 || field.view.brick.hi[a] != grid.dims[a] - 1)
      throw Error("render_sweep: the field's brick does not cover the whole domain (axis " + std::to_string(a) +
                  ": cells " + std::to_string(field.view.brick.lo[a]) + " to " + std::to_string(field.view.brick.hi[a]) +
                  " of " + std::to_string(grid.dims[a] - 1) + "); a sweep is rendered on one brick");
  const std::span<const PreparedField> one(&field, 1);
  std::vector<TaskSpec> local(tasks.begin(), tasks.end());
  for (TaskSpec& t : local) t.field = 0;
  const SweepPlan SP = compile_sweep(one, local, opt);
  const int W = cam.width(), H = cam.height(), K = SP.K;
  out.resize(W, H, K, SP.iso ? 2 : 4);
  out.colour = SP.iso ? SP.colour : std::vector<std::array<float, 3>>{};
  // Isosurfaces are stored in the order of their isovalues (a segment's hits are then adjacent).
  out.slot.resize(std::size_t(K));
  for (int j = 0; j < K; ++j) out.slot[std::size_t(SP.iso ? SP.order[std::size_t(j)] : j)] = j;
  // Every pixel is written below (rays that miss: zeros), so the buffer is not cleared first.
  thread_local StaggeredGradients caller_gradients;
  const StaggeredGradients& G = caller_gradients;
  std::optional<IsoIndex> X;
  if (SP.iso) caller_gradients.build(field.view), X.emplace(SP.sorted);

  const double glo[3] = {0, 0, 0};
  const double ghi[3] = {double(grid.dims[0] - 1), double(grid.dims[1] - 1), double(grid.dims[2] - 1)};
  thread_local camera::PixelRays caller_rays;
  const camera::PixelRays& rays = caller_rays;
  caller_rays.reset(cam, 0, 0, W, H);
  double O_index[3];
  for (int a = 0; a < 3; ++a) O_index[a] = (rays.origin()[a] - grid.origin[a]) / grid.spacing[a];
  const int tile = std::max(1, opt.tile), ntx = (W + tile - 1) / tile, nty = (H + tile - 1) / tile;
  std::uint64_t n_rays = 0, n_marched = 0;
#pragma omp parallel reduction(+ : n_rays, n_marched)
  {
    IsoScratch is(K);
    VolumeScratch vs;
    vs.acc.resize(std::size_t(K));
    // A ray composes its pixel here (in cache), then streams it to the frames: they are far larger
    // than the caches, and ordinary stores would first read every line they write.
    std::vector<std::uint8_t> local(out.stride + 64);
    std::uint8_t* const px = local.data() + (64 - reinterpret_cast<std::uintptr_t>(local.data()) % 64) % 64;
#pragma omp for schedule(dynamic, 1)
    for (int ti = 0; ti < ntx * nty; ++ti) {
      const int x0 = (ti % ntx) * tile, y0 = (ti / ntx) * tile;
      for (int y = y0; y < std::min(H, y0 + tile); ++y)
        for (int x = x0; x < std::min(W, x0 + tile); ++x) {
          std::memset(px, 0, out.stride);  // what no hit writes, and a miss
          Ray r;
          r.dir = rays.direction(x, y);
          for (int a = 0; a < 3; ++a) r.O[a] = O_index[a], r.D[a] = r.dir[a] / grid.spacing[a];
          double tg0;
          int entry_axis = -1;
          bool in = ray_box(r.O, r.D, glo, ghi, tg0, r.tg1, entry_axis);
          r.t0 = std::max(tg0, 0.0);
          in = in && r.tg1 > r.t0;
          if (in) {
            ++n_rays;
            n_marched += SP.iso ? iso_ray(SP, G, *X, r, is, px) : volume_ray(SP, r, vs, px);
          }
          stream_pixel(px, out.pixel(x, y), out.stride);
        }
    }
#ifdef PANOPTES_RENDER_AVX2
    _mm_sfence();  // the streamed pixels are visible to the other threads after the region
#endif
  }
  RenderStats st;
  st.rays = n_rays;
  st.marched_samples = n_marched;
  st.samples = n_marched;
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return st;
}

}  // namespace panoptes::render
