#pragma once
// "Face the action" (issue 32.2): the direction of the strongest signal in a decoded 360° frame, so the
// viewer can turn toward the waves instead of guessing in a black panorama. Computed from the frame
// itself (its luma), not from the simulation.
#include <optional>

#include "core/vec3.hpp"
#include "player/look.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::player {

/// The world direction of the strongest signal in an equirectangular frame seen from a camera with
/// frame `camera` (the mapping of perspective_cutout): the solid-angle weighted mean direction of the
/// brightest pixels (luma in the top 2 % and at least 16 levels above the median, weighted by how far
/// above the median). std::nullopt when nothing stands out of the background, or when the bright
/// pixels surround the camera evenly (their mean direction is too short to point anywhere).
std::optional<Vec3> strongest_signal_direction(const video::YuvFrame& frame, const ViewBasis& camera);

}  // namespace panoptes::player
