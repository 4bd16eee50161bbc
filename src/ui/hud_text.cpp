#include "ui/hud_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace panoptes::ui {

std::string signed_degrees(double degrees) {
  if (!std::isfinite(degrees)) return "?";
  const double r = std::round(degrees) + 0.0;  // + 0.0 turns -0 into +0
  if (r == 0) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.0f", r);
  return buf;
}

std::string lattice_position_text(const std::array<int, 3>& shape, int camera) {
  if (shape[0] < 1) return {};
  const auto n = player::lattice_node(shape, camera);
  char buf[96];
  std::snprintf(buf, sizeof buf, "lattice (%d, %d, %d) of %dx%dx%d", n[0], n[1], n[2], shape[0], shape[1], shape[2]);
  return buf;
}

std::string look_text(const player::Look& look) {
  return "look yaw " + signed_degrees(look.yaw_deg) + "  pitch " + signed_degrees(look.pitch_deg) + "  fov " +
         signed_degrees(look.fov_deg).substr(look.fov_deg >= 0.5 ? 1 : 0);
}

std::string world_position_text(const Vec3& p, const Vec3& d, bool z_down) {
  const double east = z_down ? d.y : d.x, north = z_down ? d.x : d.y, sky = z_down ? -d.z : d.z;
  const double len = std::sqrt(east * east + north * north + sky * sky);
  char buf[160];
  if (!(len > 0)) {
    std::snprintf(buf, sizeof buf, "at (%.4g, %.4g, %.4g)", p.x, p.y, p.z);
    return buf;
  }
  double heading = std::atan2(east, north) * 180 / M_PI;
  heading = std::fmod(std::round(heading) + 360.0, 360.0);
  static const char* const kPoints[8] = {"N", "NE", "E", "SE", "S", "SW", "W", "NW"};
  const char* point = kPoints[int(std::lround(heading / 45)) % 8];
  const double elevation = std::asin(std::clamp(sky / len, -1.0, 1.0)) * 180 / M_PI;
  // Straight up or down there is no heading to speak of.
  if (std::abs(elevation) > 89.5)
    std::snprintf(buf, sizeof buf, "at (%.4g, %.4g, %.4g)   looking %s", p.x, p.y, p.z, elevation > 0 ? "up" : "down");
  else
    std::snprintf(buf, sizeof buf, "at (%.4g, %.4g, %.4g)   heading %03.0f %s   elevation %s", p.x, p.y, p.z, heading, point,
                  signed_degrees(elevation).c_str());
  return buf;
}

}  // namespace panoptes::ui
