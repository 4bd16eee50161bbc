#pragma once
// Quality measures of a rig and its navigation graph, for tests, `panoptes rig` and docs.
#include <array>
#include <vector>

#include "camera/navigation.hpp"
#include "camera/rig.hpp"
#include "camera/sphere_index.hpp"

namespace panoptes::camera {

/// Angle (radians) from each point of the index to its nearest other point (π if it is alone).
std::vector<double> nearest_neighbour_angles(const SphereIndex& index);

/// Covering radius (radians): the largest angle from any direction on the sphere to the nearest
/// point. Estimated from `samples` Fibonacci directions (0 = automatic: max(20000, 100·N) capped at
/// 2·10^6), then refined exactly: the farthest samples are replaced by the circumcentre of their three
/// nearest points when that circumcentre has no closer point (a Voronoi vertex, where the true
/// maximum lies). The result is a lower bound that is exact when a refined vertex is the maximum.
double covering_radius(const SphereIndex& index, int samples = 0);

/// Summary of a rig and its graph; angles in degrees, per-shell measures taken over every shell.
struct RigStatistics {
  int cameras = 0;
  int shells = 0;
  double min_nearest_deg = 0;  ///< smallest nearest-neighbour angle (within a shell)
  double max_nearest_deg = 0;  ///< largest nearest-neighbour angle
  double covering_deg = 0;     ///< largest covering radius of the shells
  double right_left_return = 0;  ///< fraction of cameras c with left(right(c)) == c
  double up_down_return = 0;     ///< fraction of cameras c with down(up(c)) == c
  double left_right_return = 0;  ///< fraction of cameras c with right(left(c)) == c
  double down_up_return = 0;     ///< fraction of cameras c with up(down(c)) == c
  /// As the four above, but through the players' MoveTrail (what a user sees): the fraction of cameras
  /// where the move then the opposite move, and the move twice then the opposite twice, come back.
  double right_left_undo = 0, left_right_undo = 0, up_down_undo = 0, down_up_undo = 0;
  double missing_moves = 0;      ///< fraction of (camera, right/left/up/down) with no neighbour
  int reachable_from_0 = 0;      ///< cameras reachable from camera 0 along graph edges
  bool strongly_connected = false;  ///< every camera reaches every other one
};

/// Computes the statistics (covering radius by covering_radius with automatic samples).
RigStatistics rig_statistics(const Rig& rig, const NavigationGraph& graph);

/// Summary of a rig inside the volume (lattice, path), where angles seen from the centre mean nothing:
/// distances in world units between cameras the graph connects.
struct VolumeRigStatistics {
  int cameras = 0;
  std::array<int, 3> lattice{0, 0, 0};  ///< nodes along x, y, z (all 0 for a path)
  Vec3 spacing;                         ///< lattice: distance between adjacent nodes along x, y, z (0: one node)
  Vec3 box_lo, box_hi;                  ///< bounding box of the camera positions
  double min_step = 0, max_step = 0;    ///< shortest / longest graph edge (a walk's step)
  double path_length = 0;               ///< path: sum of the steps along `in` from camera 0 (0 for lattices)
  double reverse_return = 0;  ///< fraction of existing moves that the opposite move undoes (right/left, up/down, in/out)
  double missing_moves = 0;   ///< fraction of (camera, six moves) with no neighbour (lattice faces, path ends)
  int reachable_from_0 = 0;
  bool strongly_connected = false;
};

/// Computes VolumeRigStatistics in O(cameras).
VolumeRigStatistics volume_rig_statistics(const Rig& rig, const NavigationGraph& graph);

/// Cameras reachable from `start` along the graph's directed edges (all six moves), by BFS.
int reachable_count(const NavigationGraph& graph, int start);

}  // namespace panoptes::camera
