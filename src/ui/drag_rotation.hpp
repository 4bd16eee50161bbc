#pragma once
// Left-drag rotation: the drag turns a virtual viewing direction around the rig centre, and the
// front end asks the engine for the camera nearest to it. Pure maths, no SDL.
#include "core/vec3.hpp"

namespace panoptes::ui {

/// Accumulates a drag as a rotation of the viewing direction. "Grab the object" semantics: dragging
/// right turns the object's front to the right, i.e. the viewpoint orbits to the left.
class DragRotation {
 public:
  /// Degrees of orbit per window height of drag (a drag across the window turns half-way round).
  static constexpr double kDegreesPerHeight = 180.0;

  /// Starts a drag at a camera: `position` and `up` of the camera, `center` the point the rig's
  /// directions are measured from (the look-at point).
  void begin(const Vec3& position, const Vec3& up, const Vec3& center);
  /// Adds a mouse motion of (dx, dy) window pixels in a viewport `viewport_h` pixels high.
  void move(double dx, double dy, double viewport_h);
  /// Direction from the centre towards the virtual viewpoint (unit vector).
  const Vec3& direction() const { return dir_; }
  /// The virtual viewpoint's up vector (unit, orthogonal to direction()).
  const Vec3& up() const { return up_; }
  bool active() const { return active_; }
  void end() { active_ = false; }

 private:
  bool active_ = false;
  Vec3 dir_{0, 0, 1};
  Vec3 up_{0, 1, 0};
};

/// Rotates v about the unit axis by angle (radians, right-handed).
Vec3 rotate(const Vec3& v, const Vec3& axis, double angle);

}  // namespace panoptes::ui
