#pragma once
// Isosurface anti-aliasing in the march (issue 32): partial coverage where a ray passes within a
// pixel footprint of the surface, so silhouettes are not stair-stepped. Compositing-exact: every
// contribution is a sample of one ray at one owned position, every local decision uses the brick's
// data within its ghost layers, and the one that needs the ray's history (was a grazing sliver
// entered before this exit?) is carried across bricks by compositing (IsoSliver, PartialImage::slivers),
// so bricks still composite to the single-brick image.
#include <cmath>
#include <cstdint>

#include "core/vec3.hpp"
#include "render/field_access.hpp"
#include "render/march_plan.hpp"
#include "render/partial_image.hpp"
#include "render/sample_blocks.hpp"

namespace panoptes::render::march {

/// Angular pitch of a pixel (radians) at the image centre: what RenderOptions::iso_antialias
/// converts a ray-to-surface distance into pixels with (footprint = distance along the ray × pitch).
double pixel_pitch(const camera::Camera& cam);

/// One ray's grazing-sliver state of one isosurface task, from where the ray enters a brick to
/// where it leaves (anti-aliasing only). A grazing ray's entry gets the coverage and its exit adds
/// nothing; an exit with no entry before it on the ray is no exit but a hit (a valley where two
/// sheets meet, open towards the camera: issue 41's speckles and cracks). The entry may lie in a
/// brick in front, so a brick marches as if a sliver were open at its front and keeps, in `alt`, the
/// colour as if none were (its first exit an opaque hit); compositing picks per brick the colour its
/// front's state calls for (PartialImage::rgba_open, SliverEnd).
struct IsoSliver {
  SliverEnd state;  ///< the ray's state so far in this brick: pass = no entry, exit or hit yet
  bool has_alt;     ///< the first such event was an exit: `alt` differs from the march's accumulator
  float alt[4];     ///< colour (premultiplied) and transmittance [3] with no sliver open at the front
  /// A block's last lane whose |s| falls is a near-miss candidate only if |s| rises again at the
  /// sample after the block, which the next block interpolates anyway: the lane waits for it
  /// (`pending`, sample pend_k with the values pend_v of samples pend_k − 1 and pend_k and its cell
  /// range) instead of interpolating that sample alone (most such lanes are then no minimum).
  bool pending;
  bool pend_ranged;
  float pend_v[2];
  float pend_range;
  std::int64_t pend_k;
};

/// The lanes of a block that an anti-aliased isosurface must look at (bit j − 1 for sample k0 − 1 + j,
/// values as march_iso_block_aa() takes them): crossings between samples j − 1 and j, and local
/// minima of |s| (s = f − iso) within their cell's corner range (`range`, null: not known here).
/// The last lane's minimum needs the sample after the block: it is a candidate when |s| falls there.
/// Inline, so that the most blocks, which have none, cost the march a few vector instructions.
inline unsigned iso_aa_candidates(const float* v, const float* range, int n, bool prev, float iso) {
  unsigned cand = 0;
#ifdef PANOPTES_RENDER_AVX2
  {
    const __m256 isov = _mm256_set1_ps(iso), sign = _mm256_set1_ps(-0.0f);
    const BlockNeighbours w = block_neighbours(v);
    const __m256 a0 = _mm256_sub_ps(w.before, isov), b0 = _mm256_sub_ps(w.at, isov), c0 = _mm256_sub_ps(w.after, isov);
    const __m256 aa = _mm256_andnot_ps(sign, a0), ab = _mm256_andnot_ps(sign, b0), ac = _mm256_andnot_ps(sign, c0);
    const __m256 zero = _mm256_setzero_ps();
    const __m256 na = _mm256_cmp_ps(a0, zero, _CMP_LT_OQ), nb = _mm256_cmp_ps(b0, zero, _CMP_LT_OQ),
                 nc = _mm256_cmp_ps(c0, zero, _CMP_LT_OQ);
    const __m256 cross = _mm256_xor_ps(na, nb);
    __m256 minimum = _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(ab, aa, _CMP_LT_OQ), _mm256_cmp_ps(ab, ac, _CMP_LE_OQ)),
                                   _mm256_andnot_ps(_mm256_xor_ps(nb, nc), _mm256_castsi256_ps(_mm256_set1_epi32(-1))));
    // The near-miss cell test (|s| within the cell's corner range, march_iso_block_aa()) for every
    // lane at once when the gathers gave the ranges: most local minima of |s| in a wavy field end there.
    if (range) minimum = _mm256_and_ps(minimum, _mm256_cmp_ps(ab, _mm256_loadu_ps(range), _CMP_LE_OQ));
    cand = unsigned(_mm256_movemask_ps(_mm256_or_ps(cross, minimum)));
  }
#else
  for (int j = 1; j <= kBlock; ++j) {
    const float sp = v[j - 1] - iso, sc = v[j] - iso, sn = v[j + 1] - iso;
    const bool cross = (sp < 0) != (sc < 0);
    const bool minimum = std::abs(sc) < std::abs(sp) && std::abs(sc) <= std::abs(sn) && (sc < 0) == (sn < 0) &&
                         !(range && std::abs(sc) > range[j - 1]);
    cand |= unsigned(cross || minimum) << (j - 1);
  }
#endif
  {  // lane n: its successor is not in v
    const float sp = v[n - 1] - iso, sc = v[n] - iso;
    const bool maybe = (sp < 0) != (sc < 0) || (std::abs(sc) < std::abs(sp) && !(range && std::abs(sc) > range[n - 1]));
    cand = (cand & ((1u << (n - 1)) - 1)) | (unsigned(maybe) << (n - 1));
  }
  if (!prev) cand &= ~1u;
  return cand;
}

/// One block of an isosurface task's march with anti-aliasing (MarchPlan::iso_aa_pitch > 0), for the
/// candidate lanes `cand` of iso_aa_candidates() (called when there are some, when a lane of the
/// previous block is pending, or when the block holds the ray's last sample in the domain).
/// v[0] is the value at sample k0 − 1 (valid when bit 0 of cand may be set), v[1 + l] at sample
/// k0 + l, l < n; range[l] (may be null: then read here) the range of the eight corners of sample
/// k0 + l's cell.
/// Events in sample order:
/// - a crossing between samples k − 1 and k: the parabola through s(k−1), s(k), s(k+1) (s = f − iso)
///   proposes a grazing ray (a second root within max_reach); the surface's bend along the ray,
///   s'' = u·Hu − (n·Hu)(n·u) from the gradients at samples k − 1 and k, must curve the same way and
///   sets the depth s'²/(2|s''|)/|∇f| (the field's own curvature across the surface bends the
///   parabola too: issue 41). Coverage c = 0.5 + depth / footprint (box filter); the entry (vertex
///   ahead) gets α = c and opens the sliver, the exit (vertex behind) adds nothing and closes it, so
///   both together cover c; a crossing with c ≥ 1 is opaque (the old hit). An exit while no sliver
///   is open is a hit (two sheets meeting); while the brick does not know yet (`sliver.state` pass:
///   the entry may lie in a brick in front) it adds nothing and `sliver.alt` keeps the hit.
/// - a local minimum of |s| at sample k (no sign change): the field at the parabola's vertex, one
///   extra sample, tells a sliver pierced between two samples (a hit, found by regula falsi towards
///   the vertex: the saw teeth of grazing views came from missing those) from a near miss, which
///   gets coverage 0.5 − distance / footprint for distances up to half a voxel where a Newton step
///   lands in a grid cell that brackets the isovalue (so every brick decomposition marches it).
/// - the stretch between the ray's last sample in the domain (k_last) and where it leaves the domain
///   (t_exit): a crossing there is a hit (a surface clipped by the domain's face showed saw teeth of
///   the sample spacing along its cut edge).
/// Accumulates into a (colour premultiplied, a[3] = transmittance). Returns the lane (0 … n − 1)
/// where the task became opaque, or −1.
int march_iso_block_aa(const MarchPlan& S, const MarchTask& T, const FieldAcc& f, const RayPos& P, const double O[3],
                       const double D[3], const Vec3& dir, double t0, std::int64_t k0, int n, const float* v,
                       const float* range, unsigned cand, std::int64_t k_last, double t_exit, float tr_stop, float* a,
                       IsoSliver& sliver);

/// A pending last lane (IsoSliver::pending) whose next block did not follow (the run or the brick's
/// part of the ray ended): looks at it with the sample after it interpolated alone. Returns ≥ 0
/// when the task became opaque there, else −1.
int resolve_pending_lane(const MarchPlan& S, const MarchTask& T, const FieldAcc& f, const RayPos& P, const double O[3],
                         const double D[3], const Vec3& dir, double t0, std::int64_t k_last, double t_exit, float tr_stop,
                         float* a, IsoSliver& sliver);

}  // namespace panoptes::render::march
