#pragma once
// Double-click to step (issue 32.2, as 4D Street View): the world direction under a point of the
// look-around cut-out, and the lattice / path neighbour that lies that way.
#include "core/vec3.hpp"
#include "player/look.hpp"
#include "store/manifest.hpp"

namespace panoptes::player {

/// The world direction through pixel position (x, y) of a w x h perspective cut-out `look` of a camera
/// with frame `camera` (the mapping of perspective_cutout; the centre gives the view's forward).
Vec3 cutout_direction(const ViewBasis& camera, const Look& look, double x, double y, double w, double h);

/// The navigation-graph neighbour of `camera` whose displacement is best aligned with `direction`
/// (angle below 60°, as walking), or -1.
int neighbour_toward(const store::Manifest& manifest, int camera, const Vec3& direction);

}  // namespace panoptes::player
