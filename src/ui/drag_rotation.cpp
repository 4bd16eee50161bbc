#include "ui/drag_rotation.hpp"

#include <cmath>

namespace panoptes::ui {

Vec3 rotate(const Vec3& v, const Vec3& axis, double angle) {
  // Rodrigues' formula.
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1 - c));
}

void DragRotation::begin(const Vec3& position, const Vec3& up, const Vec3& center) {
  dir_ = normalize(position - center);
  // Make up orthogonal to the direction; a degenerate up (parallel to the view) gets any normal.
  Vec3 u = up - dir_ * dot(up, dir_);
  if (norm(u) < 1e-9) u = std::abs(dir_.z) < 0.9 ? Vec3{0, 0, 1} - dir_ * dir_.z : Vec3{1, 0, 0} - dir_ * dir_.x;
  up_ = normalize(u);
  active_ = true;
}

void DragRotation::move(double dx, double dy, double viewport_h) {
  if (!active_ || viewport_h <= 0) return;
  const double per_pixel = kDegreesPerHeight / viewport_h * M_PI / 180.0;
  // The viewer looks along -dir_; its screen-right vector is forward × up = (-dir) × up.
  const Vec3 right = normalize(cross(-dir_, up_));
  // Grab-the-object: a drag right moves the object's front right, so the viewpoint orbits towards
  // -right (about up by a negative angle); a drag down tips the top towards the viewer, so the
  // viewpoint rises towards +up (about right by a negative angle, since right x dir = up).
  if (dx != 0) dir_ = normalize(rotate(dir_, up_, -dx * per_pixel));
  if (dy != 0) {
    dir_ = normalize(rotate(dir_, right, -dy * per_pixel));
    up_ = rotate(up_, right, -dy * per_pixel);
  }
  // Keep the frame orthonormal against rounding drift.
  up_ = normalize(up_ - dir_ * dot(up_, dir_));
}

}  // namespace panoptes::ui
