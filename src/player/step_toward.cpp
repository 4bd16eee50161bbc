#include "player/step_toward.hpp"

#include <cmath>
#include <numbers>

namespace panoptes::player {

Vec3 cutout_direction(const ViewBasis& camera, const Look& look, double x, double y, double w, double h) {
  const ViewBasis v = look_basis(camera, look);
  const double tan_half = std::tan(look.fov_deg * std::numbers::pi / 360.0), aspect = h > 0 ? w / h : 1.0;
  const double sx = (2.0 * x / w - 1.0) * tan_half * aspect, sy = (1.0 - 2.0 * y / h) * tan_half;
  return normalize(v.forward + v.right * sx + v.up * sy);
}

int neighbour_toward(const store::Manifest& m, int camera, const Vec3& direction) {
  if (camera < 0 || camera >= m.camera_count() || m.graph.neighbours.size() != m.cameras.size()) return -1;
  const double len_d = norm(direction);
  if (!(len_d > 0)) return -1;
  const store::CameraEntry& here = m.cameras[std::size_t(camera)];
  const store::Neighbours& n = m.graph.neighbours[std::size_t(camera)];
  int best = -1;
  double best_cos = 0.5;  // cos 60°, as walk_target
  for (int id : {n.left, n.right, n.up, n.down, n.in, n.out}) {
    if (id < 0 || id >= m.camera_count() || id == camera) continue;
    const Vec3 step = m.cameras[std::size_t(id)].position - here.position;
    const double len = norm(step);
    if (!(len > 0)) continue;
    const double c = dot(step, direction) / (len * len_d);
    if (c > best_cos) best_cos = c, best = id;
  }
  return best;
}

}  // namespace panoptes::player
