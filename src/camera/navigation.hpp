#pragma once
// The navigation graph of a rig (DESIGN decision 7: navigation is data) and nearest-camera lookup
// for mouse-drag snapping.
#include <vector>

#include "camera/rig.hpp"
#include "camera/sphere_index.hpp"

namespace panoptes::camera {

/// The six moves between cameras.
enum class Move { right, left, up, down, in, out };

/// Neighbours of one camera; −1 = none. right/left/up/down are in the camera's own image plane:
/// `right` is the camera lying towards the image's right edge (so the view turns as if the viewer
/// walked right around the object). `in` is the camera on the next closer shell in the same
/// direction, `out` the one on the next farther shell.
struct Neighbours {
  int right = -1, left = -1, up = -1, down = -1;
  int in = -1, out = -1;
  int operator[](Move m) const;
  bool operator==(const Neighbours&) const = default;
};

/// The opposite move (right <-> left, up <-> down, in <-> out).
Move opposite(Move move);

/// The players' arrow-key rule on top of the graph (issue 34, "navigation that undoes itself"): a
/// move opposite to the last move(s) retraces them, so Up, Up, Down, Down comes back to the start
/// camera even where the graph's pairs are not mutual. No static graph can make them mutual on the
/// shipped 130-camera rigs: near the sky poles each camera's Up points at the pole, so several
/// cameras share the camera above them, which has one Down (docs/cameras.md, "Moves that undo
/// themselves"). Every other move follows the graph. Front ends (window, headless, Python, browser)
/// keep one trail per viewer; a selection made otherwise (drag, mini-map, jump) starts a new trail.
class MoveTrail {
 public:
  /// Steps remembered; older ones are forgotten (a retrace stops there and follows the graph).
  static constexpr int kMaxSteps = 256;
  /// The camera that `move` from `camera` leads to, given the graph's neighbour `graph_target` in that
  /// direction (−1 = none): the camera the last step came from when `move` reverses that step and we
  /// are where it led, else graph_target. Records the step (a retrace removes it). O(1), and it
  /// allocates only until kMaxSteps steps were recorded once.
  int next(int camera, Move move, int graph_target);
  /// The camera the opposite of the last move leads back to from `camera`, or −1 when the trail does
  /// not end at `camera` (players prefetch it with the graph's neighbours).
  int previous(int camera) const { return !steps_.empty() && steps_.back().to == camera ? steps_.back().from : -1; }
  /// Forgets every step.
  void clear() { steps_.clear(); }
  int size() const { return int(steps_.size()); }

 private:
  struct Step {
    int from, to;
    Move move;
  };
  std::vector<Step> steps_;
};

/// Plain-data graph: exactly one entry per camera of the rig it was built for.
struct NavigationGraph {
  std::vector<Neighbours> neighbours;
  int size() const { return int(neighbours.size()); }
  /// The neighbour of `camera` in direction `move`, or −1.
  int next(int camera, Move move) const { return neighbours[camera][move]; }
};

/// How the image-plane neighbours are chosen.
struct GraphOptions {
  /// Half-angle (degrees) of the cone around each image-plane axis: a camera j is a candidate for
  /// camera i's `right` if the initial heading of the great circle from i to j, measured in i's image
  /// plane, is within ±cone of i's right vector. 45° makes the four cones tile the plane, so a
  /// camera always finds a neighbour unless the rig is too sparse.
  double cone_degrees = 45;
  /// Among candidates, the one with the smallest angle·(1 + alignment_weight·(1 − cos deviation))
  /// wins: 0 = plainly the closest; larger values prefer cameras straight along the axis.
  double alignment_weight = 1.0;
  /// Reversibility: a candidate whose score is within (1 + tolerance) of the best may be chosen
  /// instead when the opposite move then leads straight back (right then left returns). Pairs are
  /// matched greedily by summed score; 0 = always the best candidate.
  double reversible_tolerance = 0.5;
};

/// Finds the nearest camera of a shell to a direction from the rig centre (mouse-drag snapping).
/// Built once (O(N)); each query visits only nearby cameras and does not allocate.
class CameraLocator {
 public:
  CameraLocator() = default;
  explicit CameraLocator(const Rig& rig);
  /// From plain data (e.g. a manifest): camera positions, their shell indices (0..shells−1) and the
  /// centre the directions are measured from. Throws panoptes::Error on mismatched sizes, negative
  /// shells or a camera at the centre.
  CameraLocator(const std::vector<Vec3>& positions, const std::vector<int>& shells, const Vec3& center);

  /// Id of the camera on `shell` whose direction from the centre is closest to `direction`
  /// (need not be unit); −1 if the shell has no camera or direction is zero.
  int nearest(const Vec3& direction, int shell = 0) const;
  int shell_count() const { return int(shells_.size()); }
  /// The index of one shell (its query results are local indices; see global_id).
  const SphereIndex& shell_index(int shell) const { return shells_[shell].index; }
  /// Global camera id of local index k on `shell`.
  int global_id(int shell, int k) const { return shells_[shell].ids[k]; }

 private:
  struct Shell {
    SphereIndex index;
    std::vector<int> ids;
  };
  std::vector<Shell> shells_;
};

/// Lattice and path rigs (Rig::is_lattice, Rig::path) get their world-axis graph (camera/volume_rigs.hpp).
/// Builds the graph in O(N · cameras per query cap): each camera searches only cameras of its own
/// shell in a growing cap around it. Cameras at (numerically) the same direction as camera i are
/// never its neighbours, and no camera is its own neighbour.
NavigationGraph build_navigation_graph(const Rig& rig, const GraphOptions& options = {});

}  // namespace panoptes::camera
