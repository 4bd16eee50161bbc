#include "camera/volume_rigs.hpp"

#include <algorithm>
#include <functional>
#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

#include "camera/number_line.hpp"
#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/file_read.hpp"

namespace panoptes::camera {

namespace {

constexpr long long kMaxInsideCameras = 10'000'000;  // same bound as the sphere rigs

double checked_fov(double fov) {
  if (fov == 0) return kInsideFovDegrees;
  if (!(fov > 0 && fov < 180))
    throw Error("rig: field of view " + std::to_string(fov) + " degrees; expected 0 < fov < 180");
  return fov;
}

// Labels as on the sphere rigs: latitude/longitude of the direction from the domain centre (0, 0 for a
// camera at the centre), radius = distance from the centre.
void label(RigCamera& c, const Rig& rig, const SkyFrame& frame) {
  const Vec3 d = c.position - rig.center;
  c.radius = norm(d);
  if (c.radius > 0) sky_latitude_longitude(frame, d * (1.0 / c.radius), c.latitude_deg, c.longitude_deg);
}

}  // namespace

Rig make_shell_interior_rig(const Domain& domain, int n_rings, int n_per_ring, std::vector<double> radii,
                            double fov_y_degrees, UpAxis up_axis) {
  domain.validate();
  if (n_rings < 1 || n_per_ring < 1)
    throw Error("shell-interior rig: " + std::to_string(n_rings) + " rings of " + std::to_string(n_per_ring) +
                " cameras; expected at least 1 of each");
  if (radii.empty()) radii = {kDefaultInShellRadius};
  if ((long long)n_rings * n_per_ring * (long long)radii.size() > kMaxInsideCameras)
    throw Error("shell-interior rig: more than " + std::to_string(kMaxInsideCameras) + " cameras");
  std::sort(radii.begin(), radii.end(), std::greater<>());
  for (std::size_t k = 0; k < radii.size(); ++k) {
    if (!(radii[k] > 0 && radii[k] <= 1))
      throw Error("shell-interior rig: radius " + std::to_string(radii[k]) +
                  "; expected 0 < radius <= 1 (a fraction of the domain's inscribed radius)");
    if (k && radii[k] == radii[k - 1]) throw Error("shell-interior rig: radius " + std::to_string(radii[k]) + " given twice");
  }
  const double fov = checked_fov(fov_y_degrees);
  const SkyFrame frame = SkyFrame::of(up_axis);
  const double inscribed = 0.5 * std::min({domain.extent.x, domain.extent.y, domain.extent.z});
  Rig rig;
  rig.center = domain.center();
  rig.up_axis = up_axis;
  rig.shell_count = int(radii.size());
  const std::vector<PatternPoint> pattern = latlon_pattern(n_rings, n_per_ring, false);
  for (std::size_t k = 0; k < radii.size(); ++k)
    for (const PatternPoint& p : pattern) {
      const Vec3 radial = normalize(frame.to_world(p.direction));
      // The ring's tangent towards increasing longitude: sky × radial, never zero (no poles).
      const Vec3 east = normalize(cross(frame.sky, radial));
      RigCamera c;
      c.position = rig.center + radial * (radii[k] * inscribed);
      c.look_at = c.position + east * inscribed;
      c.up = radial;
      c.fov_y_degrees = fov;
      c.patch = "inshell";
      c.shell = int(k);
      label(c, rig, frame);
      rig.cameras.push_back(std::move(c));
    }
  return rig;
}

Rig make_lattice_rig(const Domain& domain, std::array<int, 3> n, double margin, double fov_y_degrees, UpAxis up_axis) {
  domain.validate();
  for (int a = 0; a < 3; ++a)
    if (n[a] < 1)
      throw Error("lattice rig: " + std::to_string(n[a]) + " nodes along axis " + "xyz"[a] + "; expected at least 1");
  if ((long long)n[0] * n[1] * n[2] > kMaxInsideCameras)
    throw Error("lattice rig: " + std::to_string((long long)n[0] * n[1] * n[2]) + " cameras; expected at most " +
                std::to_string(kMaxInsideCameras));
  if (!(margin >= 0 && margin < 0.5))
    throw Error("lattice rig: margin " + std::to_string(margin) + "; expected 0 <= margin < 0.5 (fraction of the extent)");
  const double fov = checked_fov(fov_y_degrees);
  const SkyFrame frame = SkyFrame::of(up_axis);
  Rig rig;
  rig.center = domain.center();
  rig.up_axis = up_axis;
  rig.lattice = n;
  rig.cameras.reserve(std::size_t(n[0]) * n[1] * n[2]);
  // The look-at point only fixes a direction; one cell ahead keeps it at the lattice's own scale.
  const double step = std::max({domain.extent.x / n[0], domain.extent.y / n[1], domain.extent.z / n[2]});
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        RigCamera c;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a)
          c.position[a] = domain.origin[a] + domain.extent[a] * (margin + (1 - 2 * margin) * (idx[a] + 0.5) / n[a]);
        c.look_at = c.position + frame.north * step;
        c.up = frame.sky;
        c.fov_y_degrees = fov;
        c.patch = "lattice";
        label(c, rig, frame);
        rig.cameras.push_back(std::move(c));
      }
  return rig;
}

Rig read_path_rig(const std::string& path, const Domain& domain, double fov_y_degrees, UpAxis up_axis) {
  domain.validate();
  const double fov = checked_fov(fov_y_degrees);
  const std::string text = read_regular_file(path, kMaxRigFileBytes, "path file");
  std::vector<Vec3> points;
  std::vector<int> lines;
  std::istringstream in(text);
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::vector<double> v = parse_number_line(line, path, "line " + std::to_string(line_no));
    if (v.empty()) continue;
    if (v.size() != 3)
      throw FileError(path, "line " + std::to_string(line_no) + ": " + std::to_string(v.size()) +
                                " numbers; expected a path point x y z");
    if (!points.empty() && norm(Vec3{v[0], v[1], v[2]} - points.back()) == 0)
      throw FileError(path, "line " + std::to_string(line_no) +
                                ": the same point as the previous one; expected distinct consecutive points");
    points.push_back({v[0], v[1], v[2]});
    lines.push_back(line_no);
    if ((long long)points.size() > kMaxInsideCameras)
      throw FileError(path, "more than " + std::to_string(kMaxInsideCameras) + " points");
  }
  if (points.size() < 2)
    throw FileError(path, std::to_string(points.size()) + " path points; expected at least 2 (a camera looks towards the next one)");
  const SkyFrame frame = SkyFrame::of(up_axis);
  Rig rig;
  rig.center = domain.center();
  rig.up_axis = up_axis;
  rig.path = true;
  rig.spec = "path:" + path;
  for (std::size_t k = 0; k < points.size(); ++k) {
    RigCamera c;
    c.position = points[k];
    c.look_at = k + 1 < points.size() ? points[k + 1] : points[k] + (points[k] - points[k - 1]);
    c.up = frame.sky;
    c.fov_y_degrees = fov;
    c.patch = "path";
    label(c, rig, frame);
    rig.cameras.push_back(std::move(c));
  }
  return rig;
}

NavigationGraph build_lattice_graph(const Rig& rig) {
  const std::array<int, 3> n = rig.lattice;
  if ((long long)n[0] * n[1] * n[2] != rig.size())
    throw Error("lattice graph: " + std::to_string(rig.size()) + " cameras for a " + std::to_string(n[0]) + "x" +
                std::to_string(n[1]) + "x" + std::to_string(n[2]) + " lattice; expected one per node");
  const SkyFrame frame = SkyFrame::of(rig.up_axis);
  // The world axis (0..2) and sign of each sky-frame direction.
  auto axis_of = [](const Vec3& d, int& axis, int& sign) {
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0) axis = a, sign = d[a] > 0 ? 1 : -1;
  };
  int ea = 0, es = 1, na = 1, ns = 1, sa = 2, ss = 1;
  axis_of(frame.east, ea, es);
  axis_of(frame.north, na, ns);
  axis_of(frame.sky, sa, ss);
  NavigationGraph g;
  g.neighbours.resize(std::size_t(rig.size()));
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int idx[3] = {i, j, k};
        auto step = [&](int axis, int sign) {
          int m[3] = {idx[0], idx[1], idx[2]};
          m[axis] += sign;
          if (m[axis] < 0 || m[axis] >= n[axis]) return -1;
          return lattice_id(n, m[0], m[1], m[2]);
        };
        Neighbours& nb = g.neighbours[std::size_t(lattice_id(n, i, j, k))];
        nb.right = step(ea, es);
        nb.left = step(ea, -es);
        nb.in = step(na, ns);
        nb.out = step(na, -ns);
        nb.up = step(sa, ss);
        nb.down = step(sa, -ss);
      }
  return g;
}

NavigationGraph build_path_graph(const Rig& rig) {
  NavigationGraph g;
  g.neighbours.resize(std::size_t(rig.size()));
  for (int c = 0; c < rig.size(); ++c) {
    g.neighbours[std::size_t(c)].in = c + 1 < rig.size() ? c + 1 : -1;
    g.neighbours[std::size_t(c)].out = c - 1;
  }
  return g;
}

NavigationGraph build_shell_interior_graph(const Rig& rig) {
  const RigSpec spec = RigSpec::parse(rig.spec);
  const int rings = spec.rows, per_ring = spec.columns, per_shell = rings * per_ring;
  if (spec.kind != RigSpec::Kind::inshell || (long long)per_shell * rig.shell_count != rig.size())
    throw Error("shell-interior graph: rig \"" + rig.spec + "\" with " + std::to_string(rig.size()) +
                " cameras is not an inshell rig");
  NavigationGraph g;
  g.neighbours.resize(std::size_t(rig.size()));
  for (int id = 0; id < rig.size(); ++id) {
    const int shell = id / per_shell, ring = id % per_shell / per_ring, col = id % per_ring;
    const int base = shell * per_shell + ring * per_ring;
    Neighbours& n = g.neighbours[std::size_t(id)];
    if (per_ring > 1) {
      n.in = base + (col + 1) % per_ring;
      n.out = base + (col + per_ring - 1) % per_ring;
    }
    n.up = shell > 0 ? id - per_shell : -1;
    n.down = shell + 1 < rig.shell_count ? id + per_shell : -1;
    // Rings run north to south; which of them is on the image's right depends on the up axis: ask the
    // camera's own image plane.
    const int north = ring > 0 ? id - per_ring : -1, south = ring + 1 < rings ? id + per_ring : -1;
    const RigCamera& rc = rig.cameras[std::size_t(id)];
    const Camera cam(rc.position, rc.look_at, rc.up, rc.fov_y_degrees, 1, 1);
    const Vec3 radial = normalize(rc.position - rig.center), sky = SkyFrame::of(rig.up_axis).sky;
    const Vec3 southward = radial * dot(sky, radial) - sky;  // the local tangent away from the sky
    const bool south_is_right = dot(cam.right(), southward) > 0;
    n.right = south_is_right ? south : north;
    n.left = south_is_right ? north : south;
  }
  return g;
}

Move lattice_move_towards(const Vec3& direction, UpAxis up_axis) {
  const Vec3 l = SkyFrame::of(up_axis).to_local(direction);
  const double ax = std::abs(l.x), ay = std::abs(l.y), az = std::abs(l.z);
  if (az > ax && az > ay) return l.z > 0 ? Move::up : Move::down;
  if (ax > ay) return l.x > 0 ? Move::right : Move::left;
  return l.y >= 0 ? Move::in : Move::out;
}

}  // namespace panoptes::camera
