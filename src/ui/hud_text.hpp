#pragma once
// Numbers as the HUD prints them (no ImGui: unit-tested on their own).
#include <array>
#include <string>

#include "core/vec3.hpp"
#include "player/look.hpp"

namespace panoptes::ui {

/// A whole number of degrees with its sign ("+12", "-3"), and "0" for every value that rounds to
/// zero: printf's "%+.0f" of -0.2 reads "-0", which a camera on the equator or a view straight ahead
/// must never show. Non-finite values print as "?".
std::string signed_degrees(double degrees);

/// The 360° lines of the HUD: where the camera sits in the lattice (empty without a lattice shape) and
/// where the viewer looks, e.g. "lattice (1, 2, 0) of 4x4x3" and "look yaw +30  pitch 0  fov 90".
std::string lattice_position_text(const std::array<int, 3>& shape, int camera);
std::string look_text(const player::Look& look);

/// Where the viewer stands and faces in world terms (issue 32.2), e.g.
/// "at (120, 40, -35)   heading 045 NE   elevation +10": the camera's position in the domain's units and
/// the compass heading (0 = north, 90 = east) and elevation of the view direction. Directions are in
/// the domain's sky frame: `z_down` domains have north = +x, east = +y, sky = -z; others north = +y,
/// east = +x, sky = +z (as the mini-maps draw them).
std::string world_position_text(const Vec3& position, const Vec3& view_direction, bool z_down);

}  // namespace panoptes::ui
