#include "camera/orientation.hpp"

#include <string>

#include "camera/rig.hpp"
#include "core/error.hpp"

namespace panoptes::camera {

std::string_view to_string(UpAxis axis) { return axis == UpAxis::z_down ? "z_down" : "z_up"; }

UpAxis parse_up_axis(std::string_view text) {
  if (text == "z_up") return UpAxis::z_up;
  if (text == "z_down") return UpAxis::z_down;
  throw Error("up axis \"" + std::string(text) + "\"; expected \"z_up\" or \"z_down\" (z is depth, positive down)");
}

SkyFrame SkyFrame::of(UpAxis axis) {
  if (axis == UpAxis::z_down) return {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}};
  return {};
}

void sky_latitude_longitude(const SkyFrame& frame, const Vec3& direction, double& latitude_deg, double& longitude_deg) {
  latitude_longitude(frame.to_local(direction), latitude_deg, longitude_deg);
}

}  // namespace panoptes::camera
