#include "ui/hud_text.hpp"

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

}  // namespace panoptes::ui
