#pragma once
// Runs of samples for the task mixes that have a loop of their own (the ray march's run dispatch
// picks them, ray_march.cpp): one single-field volume task (march_volume1), the paper's three tasks
// p, s, p+s (march_trio), and a sweep of single-field volume tasks on one field (march_volumes).
// Per task they do the general path's operations in its order, so every path gives the same bits.
// Header-inline templates, included by ray_march.cpp only.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

#include "render/compositing_kernels.hpp"
#include "render/march_plan.hpp"
#include "render/sample_blocks.hpp"

namespace panoptes::render::march {

// The single-volume-task loop over samples kb … kend with field, LUT and accumulator in registers.
// Returns one past the last sample marched (< kend + 1 when the ray became opaque).
inline std::int64_t march_volume1(const FieldAcc& f, const MarchTask& T, float* a, std::int64_t kb, std::int64_t kend,
                           const RayPos& P, bool safe, std::int64_t k_partial, float partial, float tr_stop,
                           bool& opaque) {
  // Transmittance form: the loop-carried chain is one multiply (T ← T·(1 − α)) instead of
  // α ← α + (1 − α)·α_s, which shortens the per-sample latency.
  float a0 = a[0], a1 = a[1], a2 = a[2], tr = a[3];
  alignas(32) float v[kBlock];
  alignas(32) int bin[kBlock];
  for (std::int64_t k0 = kb; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (f.corners && k0 + kPrefetchBlocks * kBlock <= kend) {
      const FieldAcc* const fs[1] = {&f};
      prefetch_block_corners<1>(fs, P, k0 + kPrefetchBlocks * kBlock);
    }
    volume_block(f, P, k0, n, safe, v);
    lut_bin_block<kRowShift>(v, T.lo1, T.sc1, T.last1, T.abs1, bin);
    const int stop = composite_volume1(T.row1, bin, n, k0, k_partial, partial, tr_stop, a0, a1, a2, tr);
    if (stop >= 0) [[unlikely]] {
      opaque = true;
      a[0] = a0, a[1] = a1, a[2] = a2, a[3] = tr;
      return k0 + stop + 1;
    }
  }
  a[0] = a0, a[1] = a1, a[2] = a2, a[3] = tr;
  return kend + 1;
}

// The paper's three tasks (p, s and p+s: single-field volume tasks 1 and 2 on fields a and b, and
// the two-field task 3 on both), or those of them in the bits of M that are still live (at least
// two, or task 3 alone), in one loop with their accumulators in registers: per task the operations
// are those of composite_group() and composite_volume2(), so the same bits. Returns one past the
// last sample consumed; `done` receives the tasks (bits 0–2) that became opaque in the last block;
// a block holding k_partial is left to the caller.
template <unsigned M>
std::int64_t march_trio(const FieldAcc& fa, const FieldAcc& fb, const MarchTask& T1, const MarchTask& T2, const MarchTask& T3,
                        float* a1, float* a2, float* a3, std::int64_t kb, std::int64_t kend, const RayPos& P,
                        std::int64_t k_partial, float partial, float tr_stop, unsigned& done) {
  done = 0;
#ifdef PANOPTES_RENDER_AVX2
  constexpr bool t1 = M & 1, t2 = M & 2, t3 = M & 4;
  static_assert(t3 || (t1 && t2), "a single single-field task takes march_volume1()");
  const FieldAcc* const fs[2] = {&fa, &fb};  // every such subset reads both fields
  alignas(32) float vp[kBlock], vs[kBlock];
  float* const vv[2] = {vp, vs};
  alignas(32) int b1[kBlock], b2[kBlock], m1[kBlock], m2[kBlock];
  __m128 c1{}, w1{}, c2{}, w2{}, c3{};
  float tr3 = 0;
  if constexpr (t1) c1 = _mm_load_ps(a1), w1 = _mm_broadcast_ss(a1 + 3);
  if constexpr (t2) c2 = _mm_load_ps(a2), w2 = _mm_broadcast_ss(a2 + 3);
  if constexpr (t3) c3 = _mm_load_ps(a3), tr3 = a3[3];
  std::int64_t k0 = kb;
  for (; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (std::uint64_t(k_partial - k0) < std::uint64_t(n)) break;
    if (k0 + kPrefetchBlocks * kBlock <= kend) prefetch_block_corners<2>(fs, P, k0 + kPrefetchBlocks * kBlock);
    interp_block_corners_n<2>(fs, P, k0, n, vv);
    if constexpr (t1) lut_bin_block<kRowShift>(vp, T1.lo1, T1.sc1, T1.last1, T1.abs1, b1);
    if constexpr (t2) lut_bin_block<kRowShift>(vs, T2.lo1, T2.sc1, T2.last1, T2.abs1, b2);
    if constexpr (t3) {
      lut_bin_block<kMixShift>(vp, T3.lo1, T3.sc1, T3.last1, T3.abs1, m1);
      lut_bin_block<kMixShift>(vs, T3.lo2, T3.sc2, T3.last2, T3.abs2, m2);
    }
    const __m128 c1s = c1, w1s = w1, c2s = c2, w2s = w2, c3s = c3;
    const float tr3s = tr3;
    for (int l = 0; l < n; ++l) {
      if constexpr (t1) {
        const __m128 r1 = _mm_load_ps(&row_at(T1.row1, b1[l]).pr);
        c1 = _mm_fmadd_ps(w1, r1, c1);
        w1 = _mm_mul_ps(w1, _mm_permute_ps(r1, 0xFF));
      }
      if constexpr (t2) {
        const __m128 r2 = _mm_load_ps(&row_at(T2.row1, b2[l]).pr);
        c2 = _mm_fmadd_ps(w2, r2, c2);
        w2 = _mm_mul_ps(w2, _mm_permute_ps(r2, 0xFF));
      }
      if constexpr (t3) {
        const MixEntry& e1 = row_at(T3.mix1, m1[l]);
        const MixEntry& e2 = row_at(T3.mix2, m2[l]);
        const float tau = e1.tau + e2.tau;
        const float om = e1.om * e2.om;
        const float s = tr3 * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
        c3 = _mm_fmadd_ps(_mm_set1_ps(s), _mm_add_ps(_mm_load_ps(&e1.tr), _mm_load_ps(&e2.tr)), c3);
        tr3 = tr3 * om;
      }
    }
    const bool o1 = t1 && !(_mm_cvtss_f32(w1) > tr_stop), o2 = t2 && !(_mm_cvtss_f32(w2) > tr_stop),
               o3 = t3 && !(tr3 > tr_stop);
    if (o1 || o2 || o3) [[unlikely]] {
      // As composite_group() / composite_volume2(): a task that reached tr_stop is redone sample by
      // sample from the block's start; the others keep the block's result.
      auto keep = [](float* a, __m128 c, float tr) { _mm_store_ps(a, c), a[3] = tr; };
      int used = 0;  // as the general path counts marched samples: n unless every task stopped
      auto finish1 = [&](bool opaque, unsigned bit, const MarchTask& T, const int* b, float* a, __m128 c, __m128 w,
                         __m128 cs, __m128 ws) {
        if (!opaque) return keep(a, c, _mm_cvtss_f32(w));
        keep(a, cs, _mm_cvtss_f32(ws));
        used = std::max(used, 1 + composite_volume1_scalar(T.row1, b, n, k0, k_partial, partial, tr_stop, a[0], a[1],
                                                           a[2], a[3]));
        done |= bit;
      };
      if constexpr (t1) finish1(o1, 1, T1, b1, a1, c1, w1, c1s, w1s);
      if constexpr (t2) finish1(o2, 2, T2, b2, a2, c2, w2, c2s, w2s);
      if constexpr (t3) {
        if (o3) {
          keep(a3, c3s, tr3s);
          used = std::max(used, 1 + composite_volume2_scalar(T3.mix1, T3.mix2, m1, m2, n, k0, k_partial, partial,
                                                             tr_stop, a3));
          done |= 4;
        } else {
          keep(a3, c3, tr3);
        }
      }
      return k0 + (done == M ? used : n);
    }
  }
  if constexpr (t1) _mm_store_ps(a1, c1), a1[3] = _mm_cvtss_f32(w1);
  if constexpr (t2) _mm_store_ps(a2, c2), a2[3] = _mm_cvtss_f32(w2);
  if constexpr (t3) _mm_store_ps(a3, c3), a3[3] = tr3;
  return std::min(k0, kend + 1);  // the last block may have held fewer than kBlock samples
#else
  (void)fa, (void)fb, (void)T1, (void)T2, (void)T3, (void)a1, (void)a2, (void)a3, (void)kend, (void)P, (void)k_partial,
      (void)partial, (void)tr_stop;
  return kb;
#endif
}

constexpr int kMaxSweep = 12;  // march_volumes(): up to this many tasks on one field (more take the general path)

// G ≥ 2 single-field volume tasks on ONE field (a sweep of transfer functions or windows), all of
// them live: blocks of samples kb … kend run without the general path's per-block bookkeeping (which
// tasks read which fields, their kinds, their slots), the per-task constants loaded once. Per task
// the operations are those of composite_group(), so the same bits. Returns one past the last sample
// marched and, in `done`, the bits (of 0 … G−1) of the tasks that became opaque — at the first block
// where any did, so the caller can drop them and go on with fewer.
template <int G>
std::int64_t march_volumes(const FieldAcc& f, const MarchTask* const* T, float* const* as, std::int64_t kb,
                           std::int64_t kend, const RayPos& P, bool safe, std::int64_t k_partial, float partial,
                           float tr_stop, unsigned& done) {
  done = 0;
  const VolRow* luts[G];
  float lo[G], sc[G], last[G];
  bool absv[G];
  for (int g = 0; g < G; ++g) luts[g] = T[g]->row1, lo[g] = T[g]->lo1, sc[g] = T[g]->sc1, last[g] = T[g]->last1,
                              absv[g] = T[g]->abs1;
  alignas(32) float v[kBlock];
  alignas(32) int bins[G][kBlock];
  int stops[G];
  std::int64_t k0 = kb;
  for (; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (f.corners && k0 + kPrefetchBlocks * kBlock <= kend) {
      const FieldAcc* const fs[1] = {&f};
      prefetch_block_corners<1>(fs, P, k0 + kPrefetchBlocks * kBlock);
    }
    volume_block(f, P, k0, n, safe, v);
    for (int g = 0; g < G; ++g) lut_bin_block<kRowShift>(v, lo[g], sc[g], last[g], absv[g], bins[g]);
    // In groups of four, as the general path composites them (the chains of a group interleaved).
    [&]<int... Q>(std::integer_sequence<int, Q...>) {
      (composite_group<std::min(4, G - 4 * Q)>(luts + 4 * Q, bins + 4 * Q, as + 4 * Q, stops + 4 * Q, n, k0, k_partial,
                                               partial, tr_stop),
       ...);
    }(std::make_integer_sequence<int, (G + 3) / 4>{});
    int used = 0;
    for (int g = 0; g < G; ++g)
      if (stops[g] >= 0) done |= 1u << g, used = std::max(used, stops[g] + 1);
    if (done) [[unlikely]]
      return k0 + (done == (1u << G) - 1 ? used : n);
  }
  return std::min(k0, kend + 1);  // the last block may have held fewer than kBlock samples
}

}  // namespace panoptes::render::march
