#pragma once
// The compositing kernels of the march: LUT rows in the layouts the kernels read (VolRow, MixEntry),
// and front-to-back compositing of one block of samples for one single-field volume task, a
// two-field task, or G single-field tasks with their chains interleaved. During the march an
// accumulator's lane 3 holds the transmittance. Header-inline: called once per block and task.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "render/sample_blocks.hpp"
#include "render/transfer_function.hpp"

namespace panoptes::render::march {

// A single-field volume task's LUT row for the march (see vol_rows()).
struct alignas(16) VolRow {
  float pr, pg, pb, om;
};

// A LUT row of one field of a two-field volume task (see composite_volume2()): τ·rgb, τ and 1 − α.
struct alignas(32) MixEntry {
  float tr, tg, tb, tau;
  float om;
};

constexpr int kRowShift = 4, kMixShift = 5;  // log2 of sizeof(VolRow), sizeof(MixEntry)
static_assert(sizeof(VolRow) == 1 << kRowShift && sizeof(MixEntry) == 1 << kMixShift);

template <class Row>
inline const Row& row_at(const Row* table, int byte_offset) {
  return *reinterpret_cast<const Row*>(reinterpret_cast<const char*>(table) + byte_offset);
}

// The rows of `lut` as MixEntry (τ·rgb, τ, 1 − α).
std::vector<MixEntry> mix_entries(const TransferLut& lut);

// A single-field volume task's LUT row for the march: premultiplied colour and 1 − α (the factor of
// the transmittance) in 16 bytes, so a sample is one row load, one FMA and one multiply by the row's
// lane 3 (and ten tasks' LUTs take 160 KB of cache instead of 320 KB of LutEntry rows).
std::vector<VolRow> vol_rows(const TransferLut& lut);

// Composites lanes 0 … n−1 of a block (sample k0 + l, LUT bins `bin` as byte offsets of rows) of one single-field volume
// task into the accumulator (colour c0..c2, transmittance tr). Returns the lane where the ray became
// opaque, or −1. Shared by the fast path and the general path, so both give the same bits.
inline int composite_volume1_scalar(const VolRow* lut, const int* bin, int n, std::int64_t k0, std::int64_t k_partial,
                                    float partial, float tr_stop, float& c0, float& c1, float& c2, float& tr) {
  for (int l = 0; l < n; ++l) {
    const VolRow& e = row_at(lut, bin[l]);
    float pr = e.pr, pg = e.pg, pb = e.pb, om = e.om;
    if (k0 + l == k_partial) [[unlikely]] {
      const float al = 1.0f - om;
      const float an = al > 0 ? 1.0f - std::pow(om, partial) : 0.0f;
      const float sf = al > 0 ? an / al : 0.0f;
      pr *= sf, pg *= sf, pb *= sf, om = 1.0f - an;
    }
    c0 = std::fma(tr, pr, c0);
    c1 = std::fma(tr, pg, c1);
    c2 = std::fma(tr, pb, c2);
    tr *= om;
    if (tr <= tr_stop) [[unlikely]]
      return l;
  }
  return -1;
}

inline int composite_volume1(const VolRow* lut, const int* bin, int n, std::int64_t k0, std::int64_t k_partial,
                             float partial, float tr_stop, float& c0, float& c1, float& c2, float& tr) {
#ifdef PANOPTES_RENDER_AVX2
  // The common block (no shortened last sample) with the colour in one 4-lane register: per sample
  // one 16-byte row load, one FMA and the transmittance multiply (lane 3 of c collects junk), and no
  // termination test. The transmittance never increases, so the block's final value tells whether
  // some sample reached tr_stop; only then (once per ray) is the block redone sample by sample from
  // its start. The operations per sample are those of the scalar loop (fused multiply-adds, the
  // same order), so both loops give the same bits.
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c = _mm_setr_ps(c0, c1, c2, 0.0f);
    __m128 t = _mm_set1_ps(tr);
    for (int l = 0; l < n; ++l) {
      const __m128 r = _mm_load_ps(&row_at(lut, bin[l]).pr);
      c = _mm_fmadd_ps(t, r, c);
      t = _mm_mul_ps(t, _mm_permute_ps(r, 0xFF));
    }
    if (_mm_cvtss_f32(t) > tr_stop) [[likely]] {
      alignas(16) float cc[4];
      _mm_store_ps(cc, c);
      c0 = cc[0], c1 = cc[1], c2 = cc[2], tr = _mm_cvtss_f32(t);
      return -1;
    }
  }
#endif
  return composite_volume1_scalar(lut, bin, n, k0, k_partial, partial, tr_stop, c0, c1, c2, tr);
}

// The same for a two-field volume task (extinctions add, colours mix by extinction): per sample
// α = 1 − (1 − α1)(1 − α2) and colour (τ1·c1 + τ2·c2)·α/(τ1 + τ2). Rows of MixEntry hold τ·rgb, τ and
// 1 − α, so the numerator and τ are one 4-lane add of the two rows, and no per-sample branch is left:
// τ1 + τ2 = 0 means α1 = α2 = 0, so 1 − om = 0 and the sample adds 0·finite (the divisor is kept
// ≥ FLT_MIN). The division does not depend on the transmittance, so it stays off the loop-carried
// chain (T ← T·om, one multiply).
inline int composite_volume2_scalar(const MixEntry* m1, const MixEntry* m2, const int* bin1, const int* bin2, int n,
                                    std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop, float* a) {
  float c0 = a[0], c1 = a[1], c2 = a[2], tr = a[3];
  int stop = -1;
  for (int l = 0; l < n; ++l) {
    const MixEntry& e1 = row_at(m1, bin1[l]);
    const MixEntry& e2 = row_at(m2, bin2[l]);
    const float tau = e1.tau + e2.tau;
    float om = e1.om * e2.om;  // = exp(−(τ1 + τ2))
    if (k0 + l == k_partial) [[unlikely]] om = std::pow(om, partial);
    const float s = tr * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
    c0 = std::fma(s, e1.tr + e2.tr, c0);
    c1 = std::fma(s, e1.tg + e2.tg, c1);
    c2 = std::fma(s, e1.tb + e2.tb, c2);
    tr = tr * om;
    if (tr <= tr_stop) [[unlikely]] {
      stop = l;
      break;
    }
  }
  a[0] = c0, a[1] = c1, a[2] = c2, a[3] = tr;
  return stop;
}

inline int composite_volume2(const MixEntry* m1, const MixEntry* m2, const int* bin1, const int* bin2, int n,
                             std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop, float* a) {
#ifdef PANOPTES_RENDER_AVX2
  // As composite_volume1(): the colour accumulated as a 4-lane vector (the same operations as the
  // scalar loop, so the same bits; lane 3 collects s·τ, unused), termination tested once per block.
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c = _mm_load_ps(a);  // lane 3 (tr) collects junk, as in composite_group()
    float tr = a[3];
    for (int l = 0; l < n; ++l) {
      const MixEntry& e1 = row_at(m1, bin1[l]);
      const MixEntry& e2 = row_at(m2, bin2[l]);
      const float tau = e1.tau + e2.tau;
      const float om = e1.om * e2.om;
      const float s = tr * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
      c = _mm_fmadd_ps(_mm_set1_ps(s), _mm_add_ps(_mm_load_ps(&e1.tr), _mm_load_ps(&e2.tr)), c);
      tr = tr * om;
    }
    if (tr > tr_stop) [[likely]] {
      _mm_store_ps(a, c);
      a[3] = tr;
      return -1;
    }
  }
#endif
  return composite_volume2_scalar(m1, m2, bin1, bin2, n, k0, k_partial, partial, tr_stop, a);
}

// One block of G single-field volume tasks (composite_volume1()), sample-outer: each task's
// transmittance and colour form a latency chain of a multiply and an FMA per sample; interleaved,
// the G chains run side by side. Per task the operations and their order are those of
// composite_volume1(), so the same bits. The block is composited in registers; a task whose
// transmittance reached tr_stop (once per ray), or a block holding the shortened last sample, is
// redone by the scalar loop from its accumulator a[g] = {c0, c1, c2, tr}, written only on success.
// Fills stop[g] as composite_volume1() returns it.
template <int G>
inline void composite_group(const VolRow* const* luts, const int (*bins)[kBlock], float* const* a, int* stop, int n,
                            std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop) {
#ifdef PANOPTES_RENDER_AVX2
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c[G], t[G];  // lane 3 of c starts at tr and collects junk
    for (int g = 0; g < G; ++g) c[g] = _mm_load_ps(a[g]), t[g] = _mm_broadcast_ss(a[g] + 3);
    for (int l = 0; l < n; ++l)
      for (int g = 0; g < G; ++g) {
        const __m128 r = _mm_load_ps(&row_at(luts[g], bins[g][l]).pr);
        c[g] = _mm_fmadd_ps(t[g], r, c[g]);
        t[g] = _mm_mul_ps(t[g], _mm_permute_ps(r, 0xFF));
      }
    for (int g = 0; g < G; ++g) {
      const float tr = _mm_cvtss_f32(t[g]);
      if (tr > tr_stop) [[likely]] {
        _mm_store_ps(a[g], c[g]);
        a[g][3] = tr;
        stop[g] = -1;
      } else {
        stop[g] = composite_volume1_scalar(luts[g], bins[g], n, k0, k_partial, partial, tr_stop, a[g][0], a[g][1],
                                           a[g][2], a[g][3]);
      }
    }
    return;
  }
#endif
  for (int g = 0; g < G; ++g)
    stop[g] = composite_volume1_scalar(luts[g], bins[g], n, k0, k_partial, partial, tr_stop, a[g][0], a[g][1],
                                       a[g][2], a[g][3]);
}

}  // namespace panoptes::render::march
