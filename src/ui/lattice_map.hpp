#pragma once
// The mini-map of rigs inside the volume (issue 14): a small 3-D overview of the domain box and the
// lattice (or path) cameras, seen obliquely from above in the domain's sky frame, the current camera
// highlighted with the direction it looks, graph neighbours marked; a click on a dot picks that camera.
#include <vector>

#include "core/vec3.hpp"
#include "ui/minimap.hpp"

namespace panoptes::ui {

/// The 3-D overview widget. Positions and the box are in the sky frame (x east, y north, z sky).
class LatticeMap {
 public:
  void set_scene(std::vector<Vec3> positions, Vec3 box_lo, Vec3 box_hi);
  bool empty() const { return positions_.empty(); }
  /// Screen point (x right, y down, in units of the box's half diagonal) and depth of a sky-frame point.
  MapPoint project(const Vec3& p) const;
  /// Draws a `size` x `size` pixel map at the ImGui cursor; `view` is the current view direction (sky
  /// frame), drawn as a cone `half_fov_deg` wide either side (0: an arrow), with north (N) and sky marks
  /// at the box's corner. Returns the camera clicked this frame, or -1.
  int draw(int current, const std::vector<int>& neighbours, const Vec3& view, float size, double half_fov_deg = 0);

 private:
  std::vector<Vec3> positions_;
  Vec3 lo_, hi_, centre_;
  double scale_ = 1;
};

}  // namespace panoptes::ui
