#pragma once
// The eight-sample building blocks of the march: a ray's sample positions (RayPos), the field at
// kBlock consecutive samples (float field: AVX2 gathers; corner copies: one geometry for N fields),
// prefetch of the corner records ahead, and the LUT bins of a block. Header-inline: they are the
// inner loop (docs/rendering.md, "Rooms").
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "render/field_access.hpp"

namespace panoptes::render::march {

inline int lut_bin(float v, float lo, float sc, float last, bool absv) {
  if (absv) v = std::fabs(v);
  float u = (v - lo) * sc;
  u = u > 0 ? u : 0.0f;
  u = u < last ? u : last;
  return int(u);
}

#ifdef PANOPTES_RENDER_AVX2
// The trilinear field at 8 index-space positions (cell indices clamped into the data): eight AVX2
// gathers with 32-bit offsets and seven lerps. Shared by the march's sample blocks and the
// isosurface hit's gradient points, so both evaluate the field with the same operations.
// With `range`: also the range (max − min) of each lane's eight corners (isosurface anti-aliasing's
// near-miss test, iso_edges.hpp), from the gathered values at no extra load.
inline __m256 trilinear8(const FieldAcc& f, __m256 x, __m256 y, __m256 z, __m256* range = nullptr) {
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi));
  };
  const __m256i i = cell(x, f.ilo[0], f.ihi[0]), j = cell(y, f.ilo[1], f.ihi[1]), k = cell(z, f.ilo[2], f.ihi[2]);
  const __m256 fx = _mm256_sub_ps(x, _mm256_cvtepi32_ps(i));
  const __m256 fy = _mm256_sub_ps(y, _mm256_cvtepi32_ps(j));
  const __m256 fz = _mm256_sub_ps(z, _mm256_cvtepi32_ps(k));
  // Offsets from the point points.lo (= ilo), so they stay small whatever the brick's place.
  const int sx = int(f.sx), sy = int(f.sy), sz = int(f.sz);
  const __m256i off = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(i, _mm256_set1_epi32(f.ilo[0])), _mm256_set1_epi32(sx)),
                       _mm256_mullo_epi32(_mm256_sub_epi32(j, _mm256_set1_epi32(f.ilo[1])), _mm256_set1_epi32(sy))),
      _mm256_mullo_epi32(_mm256_sub_epi32(k, _mm256_set1_epi32(f.ilo[2])), _mm256_set1_epi32(sz)));
  const float* d = f.data;
  __m256 c000, c100, c010, c110, c001, c101, c011, c111;
  if (sx == 1) {
    // Neighbours along x are adjacent: each pair (x, x + 1) is one 64-bit element, so a corner pair
    // is two gathers of four elements instead of two of eight (the same values; Round 20).
    const __m128i off_lo = _mm256_castsi256_si128(off), off_hi = _mm256_extracti128_si256(off, 1);
    const auto pairs = [&](const float* base, __m256& c0, __m256& c1) {
      const double* b = reinterpret_cast<const double*>(base);
      // The masked form with a zero source: the unmasked one leaves its source undefined, which GCC 12
      // reports as a maybe-uninitialized read in every file that inlines this.
      const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), none = _mm256_setzero_pd();
      const __m256 lo = _mm256_castpd_ps(_mm256_mask_i32gather_pd(none, b, off_lo, all, 4));  // x0 x1 of lanes 0-3
      const __m256 hi = _mm256_castpd_ps(_mm256_mask_i32gather_pd(none, b, off_hi, all, 4));  // of lanes 4-7
      // [0 1 4 5 | 2 3 6 7] per 128-bit half, then the 64-bit quarters into order.
      c0 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0x88)), 0xD8));
      c1 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0xDD)), 0xD8));
    };
    pairs(d, c000, c100);
    pairs(d + sy, c010, c110);
    pairs(d + sz, c001, c101);
    pairs(d + sz + sy, c011, c111);
  } else {
    c000 = _mm256_i32gather_ps(d, off, 4), c100 = _mm256_i32gather_ps(d + sx, off, 4);
    c010 = _mm256_i32gather_ps(d + sy, off, 4), c110 = _mm256_i32gather_ps(d + sy + sx, off, 4);
    c001 = _mm256_i32gather_ps(d + sz, off, 4), c101 = _mm256_i32gather_ps(d + sz + sx, off, 4);
    c011 = _mm256_i32gather_ps(d + sz + sy, off, 4), c111 = _mm256_i32gather_ps(d + sz + sy + sx, off, 4);
  }
  if (range) {
    const __m256 lo = _mm256_min_ps(_mm256_min_ps(_mm256_min_ps(c000, c100), _mm256_min_ps(c010, c110)),
                                    _mm256_min_ps(_mm256_min_ps(c001, c101), _mm256_min_ps(c011, c111)));
    const __m256 hi = _mm256_max_ps(_mm256_max_ps(_mm256_max_ps(c000, c100), _mm256_max_ps(c010, c110)),
                                    _mm256_max_ps(_mm256_max_ps(c001, c101), _mm256_max_ps(c011, c111)));
    *range = _mm256_sub_ps(hi, lo);
  }
  const __m256 c00 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c100, c000), c000);
  const __m256 c10 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c110, c010), c010);
  const __m256 c01 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c101, c001), c001);
  const __m256 c11 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c111, c011), c011);
  const __m256 c0 = _mm256_fmadd_ps(fy, _mm256_sub_ps(c10, c00), c00);
  const __m256 c1 = _mm256_fmadd_ps(fy, _mm256_sub_ps(c11, c01), c01);
  return _mm256_fmadd_ps(fz, _mm256_sub_ps(c1, c0), c0);
}
#endif

#ifdef PANOPTES_RENDER_AVX2
// A block's values v[1 … 8] (one 32-byte store, interp_block()) and the sample before it, v[0] (a scalar
// store), as the lanes of samples l − 1, l and l + 1: `at` = v[1 … 8], `before` = v[0 … 7], `after` =
// v[2 … 8] and, in lane 7, v[8] again (callers do not use that lane: its successor lies past the
// block). Built from one load of `at`: loads at v and v + 2 would each span two stores in flight, which
// the store buffer cannot forward, and wait until both reach the cache (Round 19). Same values, so
// the same bits.
struct BlockNeighbours {
  __m256 before, at, after;
};
inline BlockNeighbours block_neighbours(const float* v) {
  const __m256 at = _mm256_loadu_ps(v + 1);
  const __m256 before =
      _mm256_blend_ps(_mm256_permutevar8x32_ps(at, _mm256_setr_epi32(0, 0, 1, 2, 3, 4, 5, 6)), _mm256_set1_ps(v[0]), 0x01);
  const __m256 after = _mm256_permutevar8x32_ps(at, _mm256_setr_epi32(1, 2, 3, 4, 5, 6, 7, 7));
  return {before, at, after};
}
#endif

// Sample positions are computed from the sample index alone, p_k = base + k·step in float (one
// multiply-add, no loop-carried chain): every path, run and brick evaluates sample k at the same
// bits, whatever the macro-cell walk did before it.
struct RayPos {
  float bx, by, bz, sx, sy, sz;
};

// Samples are interpolated in blocks of kBlock consecutive samples of one ray: the positions,
// cell indices, eight corner loads (gathers) and the seven lerps of a block run as vector
// instructions, while compositing, which carries the transmittance from sample to sample, stays
// scalar. Every path of the march (single volume task or general) interpolates through this one
// function, so they produce the same bits.
constexpr int kBlock = 8;

// v[l] = the field at sample k0 + l for l < n (1 ≤ n ≤ kBlock); lanes l ≥ n repeat sample
// k0 + n − 1 (valid memory, ignored). `safe`: every sample lies at least one cell inside the data,
// so the scalar fallback may skip the index clamps (the vector version always clamps: it is cheap).
// `range` (optional, 8 floats): each lane's cell's corner range, written only by the gather path
// (returns whether it did; the caller computes it otherwise).
inline bool interp_block(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, bool safe, float* v,
                         float* range = nullptr) {
  (void)range;  // only the gather path (AVX2) writes it
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i kk =
        _mm256_min_epi32(_mm256_add_epi32(_mm256_set1_epi32(int(k0)), lane), _mm256_set1_epi32(int(k0) + n - 1));
    const __m256 fk = _mm256_cvtepi32_ps(kk);
    const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
    const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
    const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
    if (!range) {
      _mm256_storeu_ps(v, trilinear8(f, x, y, z));
      return false;
    }
    __m256 r;
    _mm256_storeu_ps(v, trilinear8(f, x, y, z, &r));
    _mm256_storeu_ps(range, r);
    return true;
  }
#endif
  for (int l = 0; l < kBlock; ++l) {
    const float fk = float(k0 + std::min(l, n - 1));
    const float x = P.bx + fk * P.sx, y = P.by + fk * P.sy, z = P.bz + fk * P.sz;
    v[l] = safe ? interp<false>(f, x, y, z) : interp<true>(f, x, y, z);
  }
  return false;
}

// The same block from the CornerFields of N fields that share one corner layout (same ilo, ihi, ccx,
// ccxy: fields of one grid and brick), e.g. p and s of a two-field task: the sample positions, cell
// records and the eight trilinear weights are computed once for all N, and per field and sample
// only the 16-byte load of the cell's quantized corners, its widening and one multiply by the
// weights remain (then eight horizontal sums at once). Per field the operations are the same
// whatever N is, so a field's values do not depend on which other fields were read with it (one
// march for K tasks = K marches, bit for bit). Lanes l ≥ n repeat sample k0 + n − 1, as in
// interp_block().
template <int N>
[[gnu::always_inline]] inline void interp_block_corners_n(const FieldAcc* const (&fs)[N], const RayPos& P,
                                                          std::int64_t k0, int n, float* const (&vs)[N]) {
#ifdef PANOPTES_RENDER_AVX2
  const FieldAcc& f = *fs[0];
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i kk =
      _mm256_min_epi32(_mm256_add_epi32(_mm256_set1_epi32(int(k0)), lane), _mm256_set1_epi32(int(k0) + n - 1));
  const __m256 fk = _mm256_cvtepi32_ps(kk);
  const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
  const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
  const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi));
  };
  const __m256i i = cell(x, f.ilo[0], f.ihi[0]), j = cell(y, f.ilo[1], f.ihi[1]), k = cell(z, f.ilo[2], f.ihi[2]);
  alignas(32) float fx[kBlock], fy[kBlock], fz[kBlock];
  alignas(32) std::int32_t id[kBlock];
  _mm256_store_ps(fx, _mm256_sub_ps(x, _mm256_cvtepi32_ps(i)));
  _mm256_store_ps(fy, _mm256_sub_ps(y, _mm256_cvtepi32_ps(j)));
  _mm256_store_ps(fz, _mm256_sub_ps(z, _mm256_cvtepi32_ps(k)));
  _mm256_store_si256(reinterpret_cast<__m256i*>(id),
                     _mm256_add_epi32(_mm256_sub_epi32(i, _mm256_set1_epi32(f.ilo[0])),
                                      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(j, _mm256_set1_epi32(f.ilo[1])),
                                                                          _mm256_set1_epi32(f.ccx)),
                                                       _mm256_mullo_epi32(_mm256_sub_epi32(k, _mm256_set1_epi32(f.ilo[2])),
                                                                          _mm256_set1_epi32(f.ccxy)))));
  // Weight of corner c = wx·wy·wz with w = 1 − f or f: sign·f + offset per lane.
  const __m256 sx = _mm256_setr_ps(-1, 1, -1, 1, -1, 1, -1, 1), ox = _mm256_setr_ps(1, 0, 1, 0, 1, 0, 1, 0);
  const __m256 sy = _mm256_setr_ps(-1, -1, 1, 1, -1, -1, 1, 1), oy = _mm256_setr_ps(1, 1, 0, 0, 1, 1, 0, 0);
  const __m256 sz = _mm256_setr_ps(-1, -1, -1, -1, 1, 1, 1, 1), oz = _mm256_setr_ps(1, 1, 1, 1, 0, 0, 0, 0);
  __m256 p[N][kBlock];
  for (int l = 0; l < kBlock; ++l) {
    const __m256 wx = _mm256_fmadd_ps(_mm256_broadcast_ss(&fx[l]), sx, ox);
    const __m256 wy = _mm256_fmadd_ps(_mm256_broadcast_ss(&fy[l]), sy, oy);
    const __m256 wz = _mm256_fmadd_ps(_mm256_broadcast_ss(&fz[l]), sz, oz);
    const __m256 w = _mm256_mul_ps(wx, _mm256_mul_ps(wy, wz));
    const std::int64_t o = std::int64_t(f.crec) * id[l];
    for (int s = 0; s < N; ++s) {
      const __m128i q = _mm_loadu_si128(reinterpret_cast<const __m128i*>(fs[s]->corners + o));
      p[s][l] = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(q)), w);
    }
  }
  for (int s = 0; s < N; ++s) {
    // Eight horizontal sums at once: lanes of a = samples 0–3 (corners 0–3 | 4–7), of b = samples 4–7.
    const __m256 a = _mm256_hadd_ps(_mm256_hadd_ps(p[s][0], p[s][1]), _mm256_hadd_ps(p[s][2], p[s][3]));
    const __m256 b = _mm256_hadd_ps(_mm256_hadd_ps(p[s][4], p[s][5]), _mm256_hadd_ps(p[s][6], p[s][7]));
    const __m256 t = _mm256_add_ps(_mm256_permute2f128_ps(a, b, 0x20), _mm256_permute2f128_ps(a, b, 0x31));
    _mm256_storeu_ps(vs[s], _mm256_fmadd_ps(t, _mm256_set1_ps(fs[s]->qscale), _mm256_set1_ps(fs[s]->qoff)));
  }
#else
  for (int s = 0; s < N; ++s) {
    const FieldAcc& f = *fs[s];
    float* v = vs[s];
    for (int l = 0; l < kBlock; ++l) {
      const float fk = float(k0 + std::min(l, n - 1));
      const float x = P.bx + fk * P.sx, y = P.by + fk * P.sy, z = P.bz + fk * P.sz;
      const int i = std::min(std::max(int(x), f.ilo[0]), f.ihi[0]);
      const int j = std::min(std::max(int(y), f.ilo[1]), f.ihi[1]);
      const int k = std::min(std::max(int(z), f.ilo[2]), f.ihi[2]);
      const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
      const std::uint16_t* c = f.corners + f.crec * (std::int64_t(i - f.ilo[0]) + std::int64_t(j - f.ilo[1]) * f.ccx +
                                                std::int64_t(k - f.ilo[2]) * f.ccxy);
      const float c00 = c[0] + fx * (c[1] - c[0]), c10 = c[2] + fx * (c[3] - c[2]);
      const float c01 = c[4] + fx * (c[5] - c[4]), c11 = c[6] + fx * (c[7] - c[6]);
      const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
      v[l] = f.qoff + f.qscale * (c0 + fz * (c1 - c0));
    }
  }
#endif
}

// Software prefetch of the corner records of samples k0 … k0 + kBlock − 1 of the N fields (one
// corner layout, as interp_block_corners_n(); the same clamped cell records). The corner copies are
// far larger than L3 and a ray's cells are scattered through them, so without it every block waits
// for memory: in the general (K-task) path, whose blocks composite several tasks and fill the
// out-of-order window (Round 6k), and in the single-task loop too (Round 8: −17 % CPU for one volume
// task on the paper grid at 0.5 voxel; Round 5a's sparser prefetch, every other lane one block ahead,
// had not paid). Prefetches never fault and change no value, so images keep their bits.
constexpr int kPrefetchBlocks = 2;  // distance in blocks: Rounds 6k (K-task path: 1, 2, 3) and 8 (both: 1, 2, 4), docs/rendering.md
template <int N>
[[gnu::always_inline]] inline void prefetch_block_corners(const FieldAcc* const (&fs)[N], const RayPos& P,
                                                          std::int64_t k0) {
#ifdef PANOPTES_RENDER_AVX2
  const FieldAcc& f = *fs[0];
  const __m256 fk = _mm256_cvtepi32_ps(
      _mm256_add_epi32(_mm256_set1_epi32(int(k0)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
  const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
  const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
  const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_sub_epi32(
        _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi)),
        _mm256_set1_epi32(lo));
  };
  alignas(32) std::int32_t id[kBlock];
  _mm256_store_si256(reinterpret_cast<__m256i*>(id),
                     _mm256_add_epi32(cell(x, f.ilo[0], f.ihi[0]),
                                      _mm256_add_epi32(_mm256_mullo_epi32(cell(y, f.ilo[1], f.ihi[1]), _mm256_set1_epi32(f.ccx)),
                                                       _mm256_mullo_epi32(cell(z, f.ilo[2], f.ihi[2]), _mm256_set1_epi32(f.ccxy)))));
  // The two halves of one joint copy (CornerField::joint()): a 32-byte record lies in one cache line.
  const bool joint = N == 2 && (fs[N - 1]->corners == fs[0]->corners + 8 || fs[0]->corners == fs[N - 1]->corners + 8);
  for (int l = 0; l < kBlock; ++l)
    for (int s = 0; s < (joint ? 1 : N); ++s)
      _mm_prefetch(reinterpret_cast<const char*>(fs[s]->corners + std::int64_t(f.crec) * id[l]), _MM_HINT_T0);
#else
  (void)fs, (void)P, (void)k0;
#endif
}

inline void interp_block_corners(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, float* v) {
  const FieldAcc* const fs[1] = {&f};
  float* const vs[1] = {v};
  interp_block_corners_n<1>(fs, P, k0, n, vs);
}

// Whether two fields' corner copies have the same layout, so interp_block_corners_n() may share
// their geometry.
inline bool same_corner_layout(const FieldAcc& a, const FieldAcc& b) {
  if (!a.corners || !b.corners || a.ccx != b.ccx || a.ccxy != b.ccxy || a.crec != b.crec) return false;
  for (int k = 0; k < 3; ++k)
    if (a.ilo[k] != b.ilo[k] || a.ihi[k] != b.ihi[k]) return false;
  return true;
}

// Volume classification's values: from the corner copy when the field has one.
inline void volume_block(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, bool safe, float* v) {
  if (f.corners)
    interp_block_corners(f, P, k0, n, v);
  else
    interp_block(f, P, k0, n, safe, v);
}

// LUT bins of a block of values: lut_bin() lane by lane (same operations, so the same bins), as byte
// offsets bin·2^kShift of rows of 2^kShift bytes (the compositing loops then address a row with
// one add: x86 scales indices by at most 8).
template <int kShift>
inline void lut_bin_block(const float* v, float lo, float sc, float last, bool absv, int* bin) {
#ifdef PANOPTES_RENDER_AVX2
  __m256 u = _mm256_loadu_ps(v);
  if (absv) u = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), u);
  u = _mm256_mul_ps(_mm256_sub_ps(u, _mm256_set1_ps(lo)), _mm256_set1_ps(sc));
  u = _mm256_max_ps(u, _mm256_setzero_ps());  // NaN → 0, as in lut_bin()
  u = _mm256_min_ps(u, _mm256_set1_ps(last));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(bin), _mm256_slli_epi32(_mm256_cvttps_epi32(u), kShift));
#else
  for (int l = 0; l < kBlock; ++l) bin[l] = lut_bin(v[l], lo, sc, last, absv) << kShift;
#endif
}

}  // namespace panoptes::render::march
