#pragma once
// Rigs inside the volume (issue 14): cameras at the nodes of a regular 3-D lattice over the domain, or
// along a polyline (a flight through a region of interest), and their navigation graphs, whose moves
// are world axes (with the domain's up) instead of each camera's image plane.
//
// Navigation slots of a lattice camera (the same six as every graph, so stores and players need no new
// fields): right = +east, left = −east, in = +north ("forward"), out = −north ("back"), up = +sky,
// down = −sky, in the sky frame of the rig's UpAxis (z_up: east = +x, north = +y, sky = +z; z_down:
// east = +y, north = +x, sky = −z). Every lattice camera looks north with the sky up, so for a
// perspective lattice the image-plane meaning of right/left/up/down is also right.
// Path cameras: in = next point of the path, out = previous one; no sideways moves.
#include <array>
#include <string>
#include <vector>

#include "camera/navigation.hpp"
#include "camera/rig.hpp"

namespace panoptes::camera {

/// Field of view of lattice and path cameras when none is given: 90°, a natural look-around width.
inline constexpr double kInsideFovDegrees = 90.0;

/// Lattice node (i, j, k) along world x, y, z → camera id i + nx·(j + ny·k).
inline int lattice_id(const std::array<int, 3>& n, int i, int j, int k) { return i + n[0] * (j + n[1] * k); }

/// Cameras at the nodes of an nx x ny x nz lattice: node (i, j, k) at origin + extent ⊙ (m + (1 − 2m)·(i + ½)/nx,
/// …), i.e. the cell centres of the box shrunk by the fraction `margin` (0 ≤ margin < 0.5) at every face.
/// Each camera looks north (horizontally) with the sky up and the given field of view (0 = 90°).
/// rig.lattice = {nx, ny, nz}; patch "lattice". Throws panoptes::Error on bad counts or margin.
Rig make_lattice_rig(const Domain& domain, std::array<int, 3> n, double margin, double fov_y_degrees = 0,
                     UpAxis up_axis = UpAxis::z_up);

/// Default radius of shell-interior rigs, in units of the domain's inscribed radius (half its smallest
/// extent, a shell grid's outer radius): the middle of a shell whose inner radius is 0.35 of its outer.
inline constexpr double kDefaultInShellRadius = 0.675;

/// Cameras inside a spherical shell centred in the domain (issue 33): on each sphere of `radii` (in
/// units of the domain's inscribed radius = half its smallest extent; sorted from the largest = shell
/// 0), n_rings latitude rings at colatitudes 180°·(i+1)/(n_rings+1) of n_per_ring cameras each, at
/// longitudes −180° + 360°·j/n_per_ring (the latlon pattern without poles, in the sky frame of
/// `up_axis`). Each camera looks along its ring towards the local east and its up is the local radial
/// direction (outwards), so the top of every image faces the outer surface and the bottom the core,
/// wherever the camera sits. Field of view `fov_y_degrees` (0 = 90°). Patch "inshell"; its own
/// navigation graph (build_shell_interior_graph). Throws panoptes::Error on counts < 1 or radii outside (0, 1].
Rig make_shell_interior_rig(const Domain& domain, int n_rings, int n_per_ring, std::vector<double> radii,
                            double fov_y_degrees = 0, UpAxis up_axis = UpAxis::z_up);

/// Cameras at the points of a polyline read from a text file (`x y z` per line, world coordinates,
/// '#' starts a comment, blanks or commas separate numbers): camera k sits at point k and looks towards
/// point k + 1 (the last one keeps the previous direction), with the sky up. rig.path = true, patch
/// "path". Throws FileError naming the file and line on bad numbers, fewer than 2 points or two equal
/// consecutive points.
Rig read_path_rig(const std::string& path, const Domain& domain, double fov_y_degrees = 0, UpAxis up_axis = UpAxis::z_up);

/// The lattice graph (see the file comment): neighbours along world axes, −1 at the lattice faces.
NavigationGraph build_lattice_graph(const Rig& rig);
/// The path graph: in = next, out = previous.
NavigationGraph build_path_graph(const Rig& rig);
/// The graph of an `inshell` rig (make_shell_interior_rig; rig.spec starts with "inshell"): in / out =
/// the next / previous camera along the ring (forward: every camera looks along its ring), right /
/// left = the neighbouring ring on the image's right / left side (same longitude), up / down = the next
/// shell outwards / inwards (same ring and longitude); −1 at the first and last ring and shell.
NavigationGraph build_shell_interior_graph(const Rig& rig);

/// The lattice move whose world axis is closest to `direction` (forward walking): Move::in for north,
/// Move::out for south, right/left for east/west, up/down for sky/ground. Ties go to the horizontal axes.
Move lattice_move_towards(const Vec3& direction, UpAxis up_axis);

}  // namespace panoptes::camera
