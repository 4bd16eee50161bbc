#pragma once
// The ray march: one ray through one brick for every live march task of a plan — the samples the
// brick owns, the macro-cell walk (runs of cells some task can see) and the run dispatch (which
// loop marches a run: march_runs.hpp for one volume task, the paper's mix or a sweep on one field;
// the general block for any other mix). Internal to the renderer (namespace march).
#include <cstdint>

#include "core/vec3.hpp"
#include "render/iso_edges.hpp"
#include "render/march_plan.hpp"

namespace panoptes::render::march {

/// Marches the ray O + t·D (index space; `dir` its world direction, for isosurface shading) from t0
/// (where it enters the domain, or 0 inside) for the march tasks of `plan` in the bit mask `tasks`.
/// [tb0, tb1] is its stretch inside the brick, tg1 where it leaves the domain. Fills acc[i]
/// (premultiplied RGBA; a MIP task: its maximum in [0], [3] = 1 when the ray has samples in the
/// brick) of each such task and adds the effective and marched sample counts. With isosurface
/// anti-aliasing (plan.iso_aa_pitch > 0) `sliver[i]` receives isosurface task i's sliver state
/// (iso_edges.hpp; its alt colour with opacity in [3], like acc): acc[i] is then the colour if a
/// sliver is open where the ray enters the brick, alt (when has_alt) the colour if none is.
void march_ray(const MarchPlan& plan, const double O[3], const double D[3], const Vec3& dir, double t0, double tg1,
               double tb0, double tb1, std::uint64_t tasks, float (*acc)[4], std::uint64_t& effective,
               std::uint64_t& marched, IsoSliver* sliver = nullptr);

}  // namespace panoptes::render::march
