#pragma once
// Isosurface hit shading on a field view: the renderer's evaluation and the scalar formula it used
// before issue 10, side by side for tests and for the reference renderer.
#include "core/vec3.hpp"
#include "render/field_view.hpp"
#include "render/field_access.hpp"
#include "render/renderer.hpp"

namespace panoptes::render {

/// Lit, opaque RGBA (alpha 1) of an isosurface hit at index-space position p of v's grid, seen along
/// world direction dir: gradient by central differences (±0.5 voxel, one-sided at the domain's
/// faces), two-sided headlight diffuse 0.15 + 0.85·|n·l| plus specular 0.25·|n·l|^32.
/// `renderer` = true: the renderer's evaluation (the six interpolations as one 8-lane gather,
/// |n·l|^32 by squarings); false: the pre-issue-10 scalar formula (six interpolations, std::pow).
void shade_isosurface_hit(const FieldView& v, const double p[3], const Vec3& dir, Rgb colour, bool renderer,
                          float rgba[4]);

}  // namespace panoptes::render

namespace panoptes::render::march {

/// The renderer's hit shading on the march's view of a field (what shade_isosurface_hit() with
/// renderer = true computes): the six gradient interpolations as one 8-lane gather evaluation.
/// `gradient` (optional, 3 values) receives ∇f in field units per world unit (anti-aliasing's distances);
/// `samples` (optional, 8 values) the field at p ∓ ½ voxel per axis (x−, x+, y−, y+, z−, z+) and at p twice.
void shade_hit(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
               const float colour[3], float* a, double* gradient = nullptr, float* samples = nullptr);
/// ∇f at index-space position p in field units per world unit: shade_hit()'s central differences
/// (the same six interpolations as one 8-lane evaluation), without the shading.
void field_gradient(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], double g[3],
                    float* samples = nullptr);
/// Anti-aliasing's hit shading filtered over the pixel footprint (`width` world units across at the
/// hit; issue 41's speckles: one shading sample where the reference's sub-rays see a grazing rim, a
/// crease or a highlight narrower than the pixel). On entry a = shade_hit()'s colour at p (gradient g
/// there, isovalue iso); where the shading bends across the footprint, replaced by the mean of 4 × 4
/// sub-rays meeting the surface modelled from the renderer's gradient (field_gradient()) at four
/// points up to `reach` (half a voxel, world units) from p on every axis along the tangent plane, each
/// sub-ray moved onto the surface by one Newton step along itself and shaded with the gradient there.
/// Its reads stay within `reach` + ½ voxel of p on every axis (one voxel: the ghost layers of
/// required_points() cover that for hits up to a step ≤ 1 voxel outside the brick). Returns whether
/// it filtered. `samples`: the eight values shade_hit() read for g (its `samples`), which let a hit
/// away from a rim skip the patch where a Hessian from them shows no bend (nullptr: always the patch).
bool shade_hit_footprint(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
                         const double g[3], double width, double reach, double iso, const float colour[3], float* a,
                         const float* samples = nullptr);
/// The same for a near miss near a rim (|n·d| < 0.3) at its point of closest approach p, `miss` world
/// units outside the surface: the mean of the sub-rays that meet the surface (the coverage is the near
/// miss's own), which see the rim farther in than its tangent point and so lighter. Returns whether
/// it filtered (not when no sub-ray meets the surface or the model puts the rim beyond the pixel).
bool shade_near_miss_footprint(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3],
                               const Vec3& dir, const double g[3], double width, double reach, double miss, double iso,
                               const float colour[3], float* a);
/// The pre-issue-10 hit shading (six scalar interpolations, std::pow): the reference renderer's.
void shade_hit_scalar(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3],
                      const Vec3& dir, const float colour[3], float* a);

}  // namespace panoptes::render::march
