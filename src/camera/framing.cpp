#include "camera/framing.hpp"

#include <cmath>
#include <string>

#include "camera/angles.hpp"
#include "core/error.hpp"

namespace panoptes::camera {

void Domain::validate() const {
  for (int i = 0; i < 3; ++i)
    if (!(extent[i] > 0 && std::isfinite(extent[i])))
      throw Error("domain: extent component " + std::to_string(i) + " is " + std::to_string(extent[i]) +
                  "; expected a positive finite length");
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(origin[i])) throw Error("domain: origin is not finite; expected finite coordinates");
}

double fit_fov_y_degrees(double distance, double sphere_radius, double margin) {
  if (!(distance > sphere_radius) || !(sphere_radius > 0))
    throw Error("framing: camera distance " + std::to_string(distance) + " is not outside the bounding sphere of radius " +
                std::to_string(sphere_radius) + "; expected distance > radius");
  // The silhouette of the sphere is the cone of half-angle asin(R/d); widen its tangent by the margin.
  const double half = std::asin(sphere_radius / distance);
  return 2.0 * std::atan(std::tan(half) * (1.0 + margin)) / kDeg;
}

double fov_y_for_aspect(double fov_square_degrees, double aspect) {
  if (aspect >= 1.0) return fov_square_degrees;
  return 2.0 * std::atan(std::tan(fov_square_degrees * kDeg / 2) / aspect) / kDeg;
}

}  // namespace panoptes::camera
