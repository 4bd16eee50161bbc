#pragma once
// Isosurface anti-aliasing in the march (issue 32): partial coverage where a ray passes within a
// pixel footprint of the surface, so silhouettes are not stair-stepped. Compositing-exact: every
// contribution is a sample of one ray at one owned position, and every decision uses the brick's
// data within its ghost layers, so bricks still composite to the single-brick image.
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
};

/// One block of an isosurface task's march with anti-aliasing (MarchPlan::iso_aa_pitch > 0).
/// v[0] is the value at sample k0 − 1 (valid when `prev`), v[1 + l] at sample k0 + l, l < n.
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
                       const double D[3], const Vec3& dir, double t0, std::int64_t k0, int n, const float* v, bool prev,
                       std::int64_t k_last, double t_exit, float tr_stop, float* a, IsoSliver& sliver);

}  // namespace panoptes::render::march
