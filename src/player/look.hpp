#pragma once
// Looking around inside 360° (equirectangular) streams and walking between lattice cameras, UI-free:
// the view (yaw, pitch, field of view) relative to the camera's own frame, the camera a walk leads to,
// and the perspective cut-out of an equirectangular frame (the CPU reference of the window's shader,
// used by headless runs and export-path).
#include <array>

#include "core/image.hpp"
#include "core/vec3.hpp"
#include "store/manifest.hpp"

namespace panoptes::player {

class Engine;

/// Where the viewer looks inside a 360° frame: yaw (degrees, positive to the camera's right), pitch
/// (degrees, positive up) relative to the camera's forward direction, and the cut-out's vertical field
/// of view (degrees).
struct Look {
  double yaw_deg = 0, pitch_deg = 0, fov_deg = 90;
  bool operator==(const Look&) const = default;
};
/// Range of the look (also published to the browser in keys.json).
inline constexpr double kPitchMaxDeg = 89, kFovMinDeg = 20, kFovMaxDeg = 120;
/// Range of the look: pitch within ±89°, field of view 20°..120°, yaw wrapped into (−180°, 180°].
Look clamped(Look look);

/// A right-handed view frame: forward, right and up (unit, orthogonal).
struct ViewBasis {
  Vec3 forward{0, 1, 0}, right{1, 0, 0}, up{0, 0, 1};
};
/// The frame of a database camera, by the rule of camera::Camera (up made orthogonal to the view; the
/// least aligned world axis when up is parallel to it).
ViewBasis camera_basis(const store::CameraEntry& camera);
/// The frame after turning by the look's yaw (about the camera's up) and then its pitch.
ViewBasis look_basis(const ViewBasis& camera, const Look& look);
/// The look (yaw, pitch; field of view `fov_deg`) of a camera facing the world direction `direction`.
Look look_towards(const ViewBasis& camera, const Vec3& direction, double fov_deg);

/// True when the database's rig records projection "equirectangular" (manifest rig parameters).
bool is_equirectangular(const store::Manifest& manifest);
/// The lattice shape {nx, ny, nz} the rig records, or {0, 0, 0}.
std::array<int, 3> lattice_shape(const store::Manifest& manifest);
/// Lattice node (i, j, k) of a camera id (i fastest), for the HUD.
std::array<int, 3> lattice_node(const std::array<int, 3>& shape, int camera);

/// Walking moves relative to the view: forward/back along the view direction, left/right along its
/// right vector, up/down along the camera's up (the sky for lattice cameras).
enum class Walk { forward, back, left, right, up, down };
/// A walk goes only to a neighbour whose direction is within 60° of the walk's (cos 60° = 0.5).
inline constexpr double kWalkMinCos = 0.5;
/// The neighbour of `camera` in the navigation graph (any of its six slots) whose displacement is best
/// aligned with the walk's world direction (angle below 60°), or −1. Lattice graphs have their
/// neighbours on the world axes, so facing roughly along an axis walks along it.
int walk_target(const store::Manifest& manifest, int camera, const Look& look, Walk walk);

/// Walks to walk_target() and keeps the world view direction (the look is re-expressed in the new
/// camera's frame). False (nothing changes) when there is no camera that way.
bool walk_keeping_view(Engine& engine, Look& look, Walk walk);

/// Renders the perspective view `look` (square pixels, vertical field of view look.fov_deg) out of an
/// equirectangular RGB(A) frame seen from a camera with frame `camera`, into `out` (its size and channel
/// count are kept; bilinear sampling, longitude wraps). The same mapping as the window's shader.
void perspective_cutout(const Image& equirect, const ViewBasis& camera, const Look& look, Image& out);

}  // namespace panoptes::player
