#pragma once
// The rig mini-map: the camera sphere seen from above the current camera's longitude, every camera a
// dot (current one highlighted, its graph neighbours marked), drawn with ImGui draw lists; a click on
// a dot picks that camera.
#include <vector>

#include "core/vec3.hpp"

namespace panoptes::ui {

/// A point of the mini-map's orthographic projection: x right, y down (unit sphere → [-1, 1]),
/// depth > 0 on the hemisphere facing the viewer.
struct MapPoint {
  double x = 0, y = 0, depth = 0;
};

/// Projects a direction (unit vector, z = polar axis) seen from azimuth `azimuth` (radians) and
/// elevation `elevation` (radians above the equator).
MapPoint project_to_map(const Vec3& direction, double azimuth, double elevation);

/// The mini-map widget. Camera data is set once; draw() is called inside an ImGui window each frame.
class MiniMap {
 public:
  /// directions: unit vectors from the rig centre to each camera; shells: shell index per camera
  /// (0 = outermost); inner shells are drawn on smaller spheres.
  void set_cameras(std::vector<Vec3> directions, std::vector<int> shells);
  /// Draws a `size` x `size` pixel map at the ImGui cursor. `neighbours` are highlighted. Returns
  /// the camera clicked this frame, or -1.
  int draw(int current, const std::vector<int>& neighbours, float size);

 private:
  std::vector<Vec3> dirs_;
  std::vector<int> shells_;
  int shell_count_ = 1;
  double azimuth_ = 0;  // eased towards the current camera's longitude, so switches glide
  bool azimuth_set_ = false;
};

}  // namespace panoptes::ui
