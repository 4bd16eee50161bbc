#pragma once
// The angle constants of the camera module, defined once: its sources are compiled in unity batches,
// where file-local copies of the same name collide.
#include <numbers>

namespace panoptes::camera {

/// π, and one degree in radians.
inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDeg = kPi / 180.0;

}  // namespace panoptes::camera
