#pragma once
// Framing: where cameras sit relative to the domain and how wide they look, so that the whole
// domain fills the frame from every camera.
#include "core/vec3.hpp"

namespace panoptes::camera {

/// The simulation domain as an axis-aligned box [origin, origin + extent] in world units.
struct Domain {
  Vec3 origin{0, 0, 0};
  Vec3 extent{1, 1, 1};

  /// Centre of the box: every rig camera looks here by default.
  Vec3 center() const { return origin + extent * 0.5; }
  /// Radius of the bounding sphere (half the diagonal); rig radii are in units of this.
  double radius() const { return 0.5 * norm(extent); }
  /// Throws panoptes::Error unless every extent component is positive and finite.
  void validate() const;
};

/// Default camera distance from the domain centre, in bounding-sphere radii. At 3 R the bounding
/// sphere subtends 2·asin(1/3) ≈ 38.9°, a moderate perspective.
inline constexpr double kDefaultRadius = 3.0;

/// Fractional margin around the bounding sphere: the sphere's silhouette fills 1/(1 + margin) of
/// the frame's half-height, so corners never land exactly on the border.
inline constexpr double kFramingMargin = 0.03;

/// The vertical field of view (degrees) at which a sphere of radius `sphere_radius` seen from
/// `distance` (> sphere_radius) from its centre fits a square frame with the margin above. Throws
/// panoptes::Error if distance <= sphere_radius (the camera is inside the sphere).
double fit_fov_y_degrees(double distance, double sphere_radius, double margin = kFramingMargin);

/// The vertical field of view to use for an image of aspect width/height when `fov_square_degrees`
/// is the field of view that frames the scene in a square image: unchanged for landscape images
/// (the narrow side is vertical), widened for portrait images so the horizontal field of view
/// equals fov_square_degrees.
double fov_y_for_aspect(double fov_square_degrees, double aspect);

}  // namespace panoptes::camera
