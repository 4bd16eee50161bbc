#pragma once
// Camera rigs: many cameras around the domain, each with labels, in a stable numbering.
//
// Numbering (stable: the same spec always gives the same ids):
//   id = shell * cameras_per_shell + local index, shell 0 = outermost radius (see RigSpec).
//   Local index by pattern:
//   - yinyang n_theta x n_phi: patch-major (Yin first, then Yang), then colatitude row (north to
//     south in the patch's own coordinates), then longitude (west to east): Yin camera (row, column)
//     is row * n_phi + column; Yang cameras follow in the same order, skipping the few left out in
//     the overlap (see yinyang_pattern; none at the default 5x13, where Yang (r, c) is 65 + 13r + c).
//   - latlon n_lat x n_lon: north pole first (if poles are included), then rings from north to
//     south, each from longitude −180° eastwards, then the south pole.
//   - fibonacci N: k = 0..N−1 from the north (z = 1 − (2k+1)/N) southwards.
//   - file: the order of the file.
#include <array>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/framing.hpp"
#include "camera/orientation.hpp"
#include "core/vec3.hpp"

namespace panoptes::camera {

/// A point of a rig pattern: a unit direction from the domain centre and its patch label.
struct PatternPoint {
  Vec3 direction;
  const char* patch = "";  ///< "yin", "yang", "latlon", "fibonacci", ... (static string)
};

/// Yin-Yang pattern (Kageyama & Sato 2004): two congruent patches of a latitude-longitude grid,
/// colatitude 45°..135°, longitude −135°..135°, each split into n_theta x n_phi cells; one camera
/// at each cell centre (never at the nodes, where Yin and Yang points would coincide). Yang is the
/// same patch in rotated coordinates (x, y, z) = (−x', z', y'). Where the patches overlap, a Yang
/// centre closer than yinyang_min_separation() to a Yin centre is left out (none at the default
/// 5x13, which has all 130), so no two cameras are ever closer than that angle. Yin points come
/// first (n_theta·n_phi of them), then the kept Yang points in the same row/column order.
/// Throws panoptes::Error if n_theta or n_phi < 1.
std::vector<PatternPoint> yinyang_pattern(int n_theta, int n_phi);

/// The smallest angle (radians) between two cameras of yinyang_pattern(n_theta, n_phi): half the
/// smallest spacing inside a patch (along a meridian, or along the row nearest the patch's pole).
double yinyang_min_separation(int n_theta, int n_phi);

/// Latitude-longitude pattern: n_lat rings at colatitudes 180°·(i+1)/(n_lat+1), i = 0..n_lat−1, each
/// with n_lon cameras at longitudes −180° + 360°·j/n_lon; plus one camera at each pole if `poles`.
std::vector<PatternPoint> latlon_pattern(int n_lat, int n_lon, bool poles);

/// Fibonacci (golden-angle spiral) pattern of n nearly uniform points: z_k = 1 − (2k+1)/n,
/// longitude_k = k · 137.507…°.
std::vector<PatternPoint> fibonacci_pattern(int n);

/// One camera of a rig with its labels.
struct RigCamera {
  Vec3 position;
  Vec3 look_at;
  Vec3 up{0, 0, 1};         ///< requested up (the Camera makes it orthogonal; fallback at the poles)
  double fov_y_degrees = 45;  ///< vertical field of view for a square (or landscape) image
  std::string patch;          ///< "yin", "yang", "latlon", "fibonacci", "file", ...
  double latitude_deg = 0;    ///< of the direction from the domain centre to the camera, towards the sky
  double longitude_deg = 0;   ///< atan2(north, east) of that direction (sky frame), in (−180°, 180°]
  int shell = 0;              ///< 0 = outermost radius
  double radius = 0;          ///< distance from the domain centre, world units
};

/// A set of cameras around a domain. Cameras on one shell share a radius; shells are numbered from
/// the outermost (0) inwards.
struct Rig {
  std::string spec;    ///< canonical spec string it was made from (see RigSpec::to_string)
  Vec3 center;         ///< domain centre (look-at of the generated rigs)
  std::vector<RigCamera> cameras;
  int shell_count = 1;
  UpAxis up_axis = UpAxis::z_up;  ///< the domain's sky: poles, latitudes and up vectors follow it
  /// Lattice rigs (camera/volume_rigs.hpp): nodes along world x, y, z; all zero for other rigs.
  std::array<int, 3> lattice{0, 0, 0};
  bool path = false;  ///< a path rig (cameras along a polyline; graph in = next, out = previous)

  bool is_lattice() const { return lattice[0] > 0; }

  int size() const { return int(cameras.size()); }
  /// A pinhole camera for camera `id` rendering width x height pixels; the field of view is widened
  /// for portrait images (fov_y_for_aspect). Throws panoptes::Error for a bad id or size.
  /// An equirectangular camera keeps the position and orientation (the field of view does not apply).
  Camera camera(int id, int width, int height, Projection projection = Projection::perspective) const;
  /// Unit direction from the centre to camera `id`.
  Vec3 direction(int id) const;
};

/// Places pattern points on shells around the domain: for each radius (in bounding-sphere radii,
/// sorted from the largest = shell 0), a camera at centre + direction·radius·R looking at the centre
/// with the requested up. Pattern directions are in the sky frame of `up_axis` (pattern +z = sky,
/// SkyFrame::to_world); a zero `up` (the default) asks for the sky direction, so the images show the
/// sky side at the top. The field of view is the same on every shell (so a
/// closer shell magnifies: zoom by switching camera): `fov_y_degrees` if > 0, else the one that fits
/// the bounding sphere from the outermost shell (fit_fov_y_degrees). Throws panoptes::Error on an
/// empty pattern, non-positive or duplicate radii, or an outermost radius <= 1 with automatic fov.
Rig place_on_shells(const std::vector<PatternPoint>& pattern, const Domain& domain, std::vector<double> radii,
                    double fov_y_degrees = 0, Vec3 up = {0, 0, 0}, UpAxis up_axis = UpAxis::z_up);

/// Latitude and longitude (degrees) of a direction.
void latitude_longitude(const Vec3& direction, double& latitude_deg, double& longitude_deg);

}  // namespace panoptes::camera
