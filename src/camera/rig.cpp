#include "camera/rig.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "camera/angles.hpp"
#include "camera/sphere_index.hpp"
#include "core/error.hpp"

namespace panoptes::camera {

namespace {

Vec3 from_spherical(double colatitude, double longitude) {
  const double s = std::sin(colatitude);
  return {s * std::cos(longitude), s * std::sin(longitude), std::cos(colatitude)};
}
}  // namespace

double yinyang_min_separation(int n_theta, int n_phi) {
  const double dtheta = 90.0 * kDeg / n_theta, dphi = 270.0 * kDeg / n_phi;
  // Closest pair inside one patch: neighbours in a row nearest the pole (colatitude 45° + half a
  // cell), or neighbours along a meridian.
  const double row = 2 * std::asin(std::sin(45.0 * kDeg + dtheta / 2) * std::sin(dphi / 2));
  return 0.5 * std::min(dtheta, row);
}

std::vector<PatternPoint> yinyang_pattern(int n_theta, int n_phi) {
  if (n_theta < 1 || n_phi < 1)
    throw Error("yinyang rig: resolution " + std::to_string(n_theta) + "x" + std::to_string(n_phi) +
                "; expected at least 1x1 cells per patch");
  std::vector<PatternPoint> points;
  points.reserve(2 * std::size_t(n_theta) * n_phi);
  const double dtheta = 90.0 * kDeg / n_theta, dphi = 270.0 * kDeg / n_phi;
  // Cell centres: the patches overlap at their edges, so nodes would put Yin and Yang cameras on
  // the same points; centres stay half a cell inside each patch.
  for (int i = 0; i < n_theta; ++i)
    for (int j = 0; j < n_phi; ++j)
      points.push_back({from_spherical(45.0 * kDeg + (i + 0.5) * dtheta, -135.0 * kDeg + (j + 0.5) * dphi), "yin"});
  const std::size_t yin = points.size();
  std::vector<Vec3> yin_dirs;
  yin_dirs.reserve(yin);
  for (const PatternPoint& p : points) yin_dirs.push_back(p.direction);
  const SphereIndex yin_index(yin_dirs);
  // Centres can still come arbitrarily close in the overlap at some resolutions (e.g. 0.004 cell at
  // 13x39): a Yang centre closer than the guaranteed separation to a Yin centre is left out, the Yin
  // camera there serves both patches.
  const double min_sep = yinyang_min_separation(n_theta, n_phi);
  for (std::size_t k = 0; k < yin; ++k) {
    const Vec3 p = points[k].direction;
    const Vec3 q{-p.x, p.z, p.y};
    bool too_close = false;
    yin_index.for_each_within(q, min_sep * (1 - 1e-12), [&](int, const Vec3&, double) { too_close = true; });
    if (!too_close) points.push_back({q, "yang"});
  }
  return points;
}

std::vector<PatternPoint> latlon_pattern(int n_lat, int n_lon, bool poles) {
  if (n_lat < 1 || n_lon < 1)
    throw Error("latlon rig: resolution " + std::to_string(n_lat) + "x" + std::to_string(n_lon) +
                "; expected at least 1 ring of 1 camera");
  std::vector<PatternPoint> points;
  points.reserve(std::size_t(n_lat) * n_lon + 2);
  if (poles) points.push_back({{0, 0, 1}, "latlon"});
  for (int i = 0; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j)
      points.push_back({from_spherical(kPi * (i + 1) / (n_lat + 1), -kPi + 2 * kPi * j / n_lon), "latlon"});
  if (poles) points.push_back({{0, 0, -1}, "latlon"});
  return points;
}

std::vector<PatternPoint> fibonacci_pattern(int n) {
  if (n < 1) throw Error("fibonacci rig: " + std::to_string(n) + " cameras; expected at least 1");
  std::vector<PatternPoint> points;
  points.reserve(n);
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * k;
    points.push_back({{r * std::cos(phi), r * std::sin(phi), z}, "fibonacci"});
  }
  return points;
}

void latitude_longitude(const Vec3& d, double& latitude_deg, double& longitude_deg) {
  latitude_deg = std::atan2(d.z, std::hypot(d.x, d.y)) / kDeg;
  longitude_deg = (d.x == 0 && d.y == 0) ? 0.0 : std::atan2(d.y, d.x) / kDeg;
}

Rig place_on_shells(const std::vector<PatternPoint>& pattern, const Domain& domain, std::vector<double> radii,
                    double fov_y_degrees, Vec3 up, UpAxis up_axis) {
  domain.validate();
  if (pattern.empty()) throw Error("rig: the camera pattern is empty; expected at least one camera");
  if (radii.empty()) throw Error("rig: no shell radius given; expected at least one");
  for (double r : radii)
    if (!(r > 0 && std::isfinite(r)))
      throw Error("rig: shell radius " + std::to_string(r) + "; expected a positive number of bounding-sphere radii");
  std::sort(radii.begin(), radii.end(), std::greater<>());
  for (std::size_t s = 1; s < radii.size(); ++s)
    if (radii[s] == radii[s - 1])
      throw Error("rig: shell radius " + std::to_string(radii[s]) + " given twice; expected distinct radii");
  const SkyFrame frame = SkyFrame::of(up_axis);
  if (norm(up) == 0) up = frame.sky;
  if (!std::isfinite(norm(up))) throw Error("rig: up vector is not finite; expected a direction");
  const double R = domain.radius();
  double fov = fov_y_degrees;
  if (fov <= 0) {
    if (!(radii.front() > 1.0))
      throw Error("rig: outermost shell radius " + std::to_string(radii.front()) +
                  " is inside the domain's bounding sphere, so no field of view frames the domain; expected a "
                  "radius > 1 or an explicit field of view");
    fov = fit_fov_y_degrees(radii.front() * R, R);
  }
  if (!(fov > 0 && fov < 180))
    throw Error("rig: field of view " + std::to_string(fov) + " degrees; expected 0 < fov < 180");

  Rig rig;
  rig.center = domain.center();
  rig.shell_count = int(radii.size());
  rig.up_axis = up_axis;
  rig.cameras.reserve(pattern.size() * radii.size());
  for (int s = 0; s < int(radii.size()); ++s)
    for (const PatternPoint& p : pattern) {
      RigCamera c;
      const Vec3 local = normalize(p.direction);
      const Vec3 d = frame.to_world(local);
      c.radius = radii[s] * R;
      c.position = rig.center + d * c.radius;
      c.look_at = rig.center;
      c.up = up;
      c.fov_y_degrees = fov;
      c.patch = p.patch;
      latitude_longitude(local, c.latitude_deg, c.longitude_deg);
      c.shell = s;
      rig.cameras.push_back(std::move(c));
    }
  return rig;
}

Camera Rig::camera(int id, int width, int height, Projection projection) const {
  if (id < 0 || id >= size())
    throw Error("rig: camera id " + std::to_string(id) + " out of range; expected 0.." + std::to_string(size() - 1));
  if (width <= 0 || height <= 0)
    throw Error("rig: image size " + std::to_string(width) + "x" + std::to_string(height) + "; expected positive");
  const RigCamera& c = cameras[id];
  return Camera(c.position, c.look_at, c.up, fov_y_for_aspect(c.fov_y_degrees, double(width) / height), width, height,
                projection);
}

Vec3 Rig::direction(int id) const { return normalize(cameras[id].position - center); }

}  // namespace panoptes::camera
