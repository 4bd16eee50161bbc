#include "player/look.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "player/engine.hpp"

namespace panoptes::player {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

Look clamped(Look l) {
  l.pitch_deg = std::clamp(l.pitch_deg, -kPitchMaxDeg, kPitchMaxDeg);
  l.fov_deg = std::clamp(l.fov_deg, kFovMinDeg, kFovMaxDeg);
  l.yaw_deg = std::remainder(l.yaw_deg, 360.0);
  if (l.yaw_deg == -180.0) l.yaw_deg = 180.0;
  return l;
}

ViewBasis camera_basis(const store::CameraEntry& c) {
  ViewBasis b;
  const Vec3 d = c.look_at - c.position;
  if (!(norm(d) > 0)) return b;
  b.forward = normalize(d);
  Vec3 u = c.up;
  if (norm(u) == 0 || norm(cross(b.forward, normalize(u))) < 1e-6) {
    const double ax = std::abs(b.forward.x), ay = std::abs(b.forward.y), az = std::abs(b.forward.z);
    u = az <= ax && az <= ay ? Vec3{0, 0, 1} : (ay <= ax ? Vec3{0, 1, 0} : Vec3{1, 0, 0});
  }
  b.right = normalize(cross(b.forward, u));
  b.up = cross(b.right, b.forward);
  return b;
}

ViewBasis look_basis(const ViewBasis& c, const Look& l) {
  const double cy = std::cos(l.yaw_deg * kDeg), sy = std::sin(l.yaw_deg * kDeg);
  const double cp = std::cos(l.pitch_deg * kDeg), sp = std::sin(l.pitch_deg * kDeg);
  ViewBasis b;
  const Vec3 heading = c.forward * cy + c.right * sy;  // yaw about the camera's up
  b.right = c.right * cy - c.forward * sy;
  b.forward = heading * cp + c.up * sp;
  b.up = cross(b.right, b.forward);
  return b;
}

Look look_towards(const ViewBasis& c, const Vec3& d, double fov_deg) {
  Look l;
  l.fov_deg = fov_deg;
  const double x = dot(d, c.right), y = dot(d, c.up), z = dot(d, c.forward);
  l.yaw_deg = std::atan2(x, z) / kDeg;
  l.pitch_deg = std::atan2(y, std::hypot(x, z)) / kDeg;
  return clamped(l);
}

bool is_equirectangular(const store::Manifest& m) {
  const auto it = m.rig.parameters.find("projection");
  return it != m.rig.parameters.end() && it->is_string() && it->get<std::string>() == "equirectangular";
}

std::array<int, 3> lattice_shape(const store::Manifest& m) {
  const auto it = m.rig.parameters.find("lattice");
  if (it == m.rig.parameters.end() || !it->is_array() || it->size() != 3) return {0, 0, 0};
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) {
    const auto& v = (*it)[std::size_t(a)];
    if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > (1 << 24)) return {0, 0, 0};
    n[std::size_t(a)] = v.get<int>();
  }
  // A shape that does not match the camera count is not trusted (hostile or hand-edited manifest).
  if ((long long)n[0] * n[1] * n[2] != (long long)m.cameras.size()) return {0, 0, 0};
  return n;
}

std::array<int, 3> lattice_node(const std::array<int, 3>& n, int c) {
  if (n[0] < 1 || n[1] < 1 || c < 0) return {0, 0, 0};
  return {c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])};
}

int walk_target(const store::Manifest& m, int camera, const Look& look, Walk walk) {
  if (camera < 0 || camera >= m.camera_count() || m.graph.neighbours.size() != m.cameras.size()) return -1;
  const store::CameraEntry& here = m.cameras[std::size_t(camera)];
  const ViewBasis cam = camera_basis(here);
  const ViewBasis view = look_basis(cam, look);
  Vec3 d;
  switch (walk) {
    case Walk::forward: d = view.forward; break;
    case Walk::back: d = -view.forward; break;
    case Walk::right: d = view.right; break;
    case Walk::left: d = -view.right; break;
    case Walk::up: d = cam.up; break;
    case Walk::down: d = -cam.up; break;
  }
  const store::Neighbours& n = m.graph.neighbours[std::size_t(camera)];
  int best = -1;
  double best_cos = kWalkMinCos;  // never walk sideways when nothing lies ahead
  for (int id : {n.left, n.right, n.up, n.down, n.in, n.out}) {
    if (id < 0 || id >= m.camera_count() || id == camera) continue;
    const Vec3 step = m.cameras[std::size_t(id)].position - here.position;
    const double len = norm(step);
    if (!(len > 0)) continue;
    const double c = dot(step, d) / len;
    if (c > best_cos) best_cos = c, best = id;
  }
  return best;
}

bool walk_keeping_view(Engine& engine, Look& look, Walk walk) {
  const store::Manifest& m = engine.manifest();
  const int from = engine.selection().camera;
  const int to = walk_target(m, from, look, walk);
  if (to < 0 || !engine.jump_to_camera(to)) return false;
  const ViewBasis view = look_basis(camera_basis(m.cameras[std::size_t(from)]), look);
  look = look_towards(camera_basis(m.cameras[std::size_t(to)]), view.forward, look.fov_deg);
  engine.set_view_direction(view.forward);  // prefetch the next camera ahead first
  return true;
}

void perspective_cutout(const Image& src, const ViewBasis& cam, const Look& look, Image& out) {
  const ViewBasis v = look_basis(cam, look);
  const int W = out.width, H = out.height, SW = src.width, SH = src.height;
  const int ch = std::min(out.channels, src.channels);
  const double tan_half = std::tan(look.fov_deg * kDeg / 2), aspect = double(W) / H;
  for (int y = 0; y < H; ++y) {
    std::uint8_t* o = out.row(y);
    for (int x = 0; x < W; ++x, o += out.channels) {
      const double sx = (2.0 * (x + 0.5) / W - 1.0) * tan_half * aspect, sy = (1.0 - 2.0 * (y + 0.5) / H) * tan_half;
      const Vec3 d = v.forward + v.right * sx + v.up * sy;
      const double cx = dot(d, cam.right), cy = dot(d, cam.up), cz = dot(d, cam.forward);
      const double lon = std::atan2(cx, cz), lat = std::atan2(cy, std::hypot(cx, cz));
      // Continuous pixel coordinates of the source, pixel centres at integers.
      const double u = (lon / std::numbers::pi + 1.0) * 0.5 * SW - 0.5, w = (0.5 - lat / std::numbers::pi) * SH - 0.5;
      const int x0 = int(std::floor(u)), y0 = int(std::floor(w));
      const double fx = u - x0, fy = w - y0;
      const int xa = ((x0 % SW) + SW) % SW, xb = (xa + 1) % SW;
      const int ya = std::clamp(y0, 0, SH - 1), yb = std::clamp(y0 + 1, 0, SH - 1);
      const std::uint8_t *p00 = src.at(xa, ya), *p10 = src.at(xb, ya), *p01 = src.at(xa, yb), *p11 = src.at(xb, yb);
      for (int c = 0; c < ch; ++c) {
        const double top = p00[c] + (p10[c] - p00[c]) * fx, bottom = p01[c] + (p11[c] - p01[c]) * fx;
        o[c] = std::uint8_t(std::clamp(top + (bottom - top) * fy + 0.5, 0.0, 255.0));
      }
      for (int c = ch; c < out.channels; ++c) o[c] = 255;
    }
  }
}

}  // namespace panoptes::player
