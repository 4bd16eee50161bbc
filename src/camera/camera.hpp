#pragma once
// The pinhole camera: position, look-at, up, vertical field of view and image size.
#include <string_view>

#include "core/vec3.hpp"

namespace panoptes::camera {

/// How image points map to ray directions.
enum class Projection {
  perspective,      ///< pinhole: fov_y over the image height
  equirectangular,  ///< 360° x 180°: column → longitude, row → latitude in the camera's frame
};
/// "perspective" / "equirectangular".
std::string_view to_string(Projection projection);
/// Parses "perspective" or "equirectangular"; throws panoptes::Error naming the text otherwise.
Projection parse_projection(std::string_view text);

/// A ray with unit direction.
struct Ray {
  Vec3 origin;
  Vec3 direction;
};

/// A perspective camera. Pixel (0,0) is the top-left corner of the image; pixel centres are at
/// half-integer coordinates. The image-plane basis is right() (+x in the image) and up()
/// (−y in the image); forward() points from the position to the look-at point.
///
/// Up-vector rule: the given up is made orthogonal to the viewing direction. When it is (nearly)
/// parallel to the viewing direction (a camera above a pole looking down the up axis), the
/// fallback_up() axis is used instead, so every camera on a sphere has a well-defined, smoothly
/// varying image plane except exactly at the pole, where the result is still deterministic.
class Camera {
 public:
  Camera() = default;
  /// Throws panoptes::Error if position == look_at, fov is not in (0, 180) degrees or the
  /// image size is not positive. An equirectangular camera ignores the field of view (it sees all
  /// directions): longitude 0 (the forward direction) is the image's centre column, longitude grows
  /// to the right (towards right()), latitude +90° (up()) is the top row.
  Camera(Vec3 position, Vec3 look_at, Vec3 up, double fov_y_degrees, int width, int height,
         Projection projection = Projection::perspective);

  const Vec3& position() const { return position_; }
  const Vec3& look_at() const { return look_at_; }
  const Vec3& forward() const { return forward_; }
  const Vec3& right() const { return right_; }
  const Vec3& up() const { return up_; }
  double fov_y_degrees() const { return fov_y_deg_; }
  int width() const { return width_; }
  int height() const { return height_; }
  Projection projection() const { return projection_; }

  /// The ray through image point (px, py) in pixel coordinates (pixel centre of column i is i + 0.5).
  /// The single source of rays: renderers march whatever it returns, whatever the projection.
  /// Equirectangular: longitude = 360°·px/width − 180°, latitude = 90° − 180°·py/height.
  Ray ray(double px, double py) const;
  /// Projects a world point to pixel coordinates; returns false if it is behind a perspective camera
  /// (or, equirectangular, at the camera's position).
  bool project(const Vec3& p, double& px, double& py) const;

  /// The axis used when the requested up is parallel to the viewing direction.
  static Vec3 fallback_up(const Vec3& forward);

 private:
  friend class PixelRays;  // PixelRays (pixel_rays.hpp) repeats ray()'s expressions per column and row
  Vec3 position_{0, 0, 1}, look_at_{0, 0, 0};
  Vec3 forward_{0, 0, -1}, right_{1, 0, 0}, up_{0, 1, 0};
  double fov_y_deg_ = 45;
  double tan_half_ = 0.41421356237309503;  // tan(fov/2)
  int width_ = 1, height_ = 1;
  Projection projection_ = Projection::perspective;
};

}  // namespace panoptes::camera
