#include "camera/camera.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace panoptes::camera {

std::string_view to_string(Projection projection) {
  return projection == Projection::equirectangular ? "equirectangular" : "perspective";
}

Projection parse_projection(std::string_view text) {
  if (text == "perspective") return Projection::perspective;
  if (text == "equirectangular") return Projection::equirectangular;
  throw Error("projection \"" + std::string(text) + "\"; expected \"perspective\" or \"equirectangular\"");
}

Vec3 Camera::fallback_up(const Vec3& forward) {
  // Choose the world axis least aligned with the view direction: deterministic and never parallel.
  const double ax = std::abs(forward.x), ay = std::abs(forward.y), az = std::abs(forward.z);
  if (az <= ax && az <= ay) return {0, 0, 1};
  if (ay <= ax) return {0, 1, 0};
  return {1, 0, 0};
}

Camera::Camera(Vec3 position, Vec3 look_at, Vec3 up, double fov_y_degrees, int width, int height,
               Projection projection)
    : position_(position), look_at_(look_at), fov_y_deg_(fov_y_degrees), width_(width), height_(height),
      projection_(projection) {
  const Vec3 d = look_at - position;
  if (norm(d) <= 0) throw Error("camera: position equals look-at point; expected distinct points");
  if (!(fov_y_degrees > 0 && fov_y_degrees < 180))
    throw Error("camera: field of view " + std::to_string(fov_y_degrees) + " degrees; expected 0 < fov < 180");
  if (width <= 0 || height <= 0)
    throw Error("camera: image size " + std::to_string(width) + "x" + std::to_string(height) +
                "; expected positive width and height");
  forward_ = normalize(d);
  Vec3 u = up;
  constexpr double kParallel = 1e-6;  // sin of the smallest accepted angle between up and view
  if (norm(cross(forward_, normalize(u))) < kParallel || norm(u) == 0) u = fallback_up(forward_);
  right_ = normalize(cross(forward_, u));
  up_ = cross(right_, forward_);
  tan_half_ = std::tan(fov_y_degrees * std::numbers::pi / 360.0);
}

Ray Camera::ray(double px, double py) const {
  if (projection_ == Projection::equirectangular) {
    const double lon = (2.0 * px / width_ - 1.0) * std::numbers::pi;
    const double lat = (0.5 - py / height_) * std::numbers::pi;
    const double c = std::cos(lat);
    return {position_, forward_ * (c * std::cos(lon)) + right_ * (c * std::sin(lon)) + up_ * std::sin(lat)};
  }
  const double aspect = double(width_) / height_;
  const double sx = (2.0 * px / width_ - 1.0) * tan_half_ * aspect;
  const double sy = (1.0 - 2.0 * py / height_) * tan_half_;
  return {position_, normalize(forward_ + right_ * sx + up_ * sy)};
}

bool Camera::project(const Vec3& p, double& px, double& py) const {
  const Vec3 d = p - position_;
  const double z = dot(d, forward_);
  if (projection_ == Projection::equirectangular) {
    const double x = dot(d, right_), y = dot(d, up_);
    const double h = std::hypot(x, z);
    if (h == 0 && y == 0) return false;
    px = (std::atan2(x, z) / std::numbers::pi + 1.0) * 0.5 * width_;
    py = (0.5 - std::atan2(y, h) / std::numbers::pi) * height_;
    return true;
  }
  if (z <= 0) return false;
  const double aspect = double(width_) / height_;
  const double sx = dot(d, right_) / z, sy = dot(d, up_) / z;
  px = (sx / (tan_half_ * aspect) + 1.0) * 0.5 * width_;
  py = (1.0 - sy / tan_half_) * 0.5 * height_;
  return true;
}

}  // namespace panoptes::camera
