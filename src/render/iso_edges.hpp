#pragma once
// Isosurface anti-aliasing in the march (issue 32): partial coverage where a ray passes within a
// pixel footprint of the surface, so silhouettes are not stair-stepped. Every contribution is a
// sample of one ray at one owned position, so bricks composite to the single-brick image — within
// 1/255 except where a grazing sliver is cut by a brick face (its entry and exit in two bricks).
#include <cstdint>

#include "core/vec3.hpp"
#include "render/field_access.hpp"
#include "render/march_plan.hpp"
#include "render/sample_blocks.hpp"

namespace panoptes::render::march {

/// Angular pitch of a pixel (radians) at the image centre: what RenderOptions::iso_antialias
/// converts a ray-to-surface distance into pixels with (footprint = distance along the ray × pitch).
double pixel_pitch(const camera::Camera& cam);

/// One ray's open sliver of one isosurface task: an entry composited with partial coverage whose
/// exit has not come yet. Valid only while `open`. No initializers: the march keeps one per task per
/// ray on the stack and sets `open` before use.
struct IsoSliver {
  bool open;
  double t_end;      ///< ray parameter by which the exit must have come; past it the entry was no sliver
  float before[4];   ///< the task's accumulator before the entry (colour, transmittance)
  float rgb[4];      ///< the entry's shading
};

/// The open sliver's entry made an ordinary opaque hit (its exit never came: the surface did not
/// bend away as its local fit said, e.g. where two sheets meet); what was added after it is behind it.
inline void close_as_hit(IsoSliver& s, float* a) {
  for (int c = 0; c < 3; ++c) a[c] = s.before[c] + s.before[3] * s.rgb[c];
  a[3] = 0;
  s.open = false;
}

/// One block of an isosurface task's march with anti-aliasing (MarchPlan::iso_aa_pitch > 0).
/// v[0] is the value at sample k0 − 1 (valid when `prev`), v[1 + l] at sample k0 + l, l < n.
/// Events in sample order:
/// - a crossing between samples k − 1 and k: the parabola through s(k−1), s(k), s(k+1) (s = f − iso)
///   proposes a grazing ray (a second root within max_reach); the surface's bend along the ray,
///   s'' = u·Hu − (n·Hu)(n·u) from the gradients at samples k − 1 and k, must curve the same way and
///   sets the depth s'²/(2|s''|)/|∇f| (the field's own curvature across the surface bends the
///   parabola too: issue 41). Coverage c = 0.5 + depth / footprint (box filter); the entry (vertex
///   ahead) gets α = c and opens `sliver`, the exit adds nothing — only after such an entry in this
///   march or when the entry may lie in a brick in front, else it is an opaque hit (a sliver the
///   fit claims behind the first crossing is open towards the camera: valleys where sheets meet).
///   An entry whose exit has not come by twice the predicted chord (+ a voxel) becomes an opaque
///   hit (close_as_hit(); also at the end of the brick's samples). A crossing with c ≥ 1 is opaque.
/// - a local minimum of |s| at sample k (no sign change): the field at the parabola's vertex, one
///   extra sample, tells a sliver pierced between two samples (a hit, found by regula falsi towards
///   the vertex: the saw teeth of grazing views came from missing those) from a near miss, which
///   gets coverage 0.5 − distance / footprint for distances up to half a voxel where a Newton step
///   lands in a grid cell that brackets the isovalue (so every brick decomposition marches it).
/// - the stretch between the ray's last sample in the domain (k_last) and where it leaves the domain
///   (t_exit): a crossing there is a hit (a surface clipped by the domain's face showed saw teeth of
///   the sample spacing along its cut edge).
/// Accumulates into a (colour premultiplied, a[3] = transmittance). Returns the lane (0 … n − 1)
/// where the task became opaque, or −1. `k_first`: the first sample the brick owns. Bricks composite
/// to the single-brick image within 1/255 except for the few pixels of slivers cut by a brick face.
int march_iso_block_aa(const MarchPlan& S, const MarchTask& T, const FieldAcc& f, const RayPos& P, const double O[3],
                       const double D[3], const Vec3& dir, double t0, std::int64_t k0, int n, const float* v, bool prev,
                       std::int64_t k_first, std::int64_t k_last, double t_exit, float tr_stop, float* a,
                       IsoSliver& sliver);

}  // namespace panoptes::render::march
