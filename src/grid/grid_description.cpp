#include "grid/grid_description.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/error.hpp"

namespace panoptes::grid {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxAxisPoints = 65535;  // the resampling plan stores source indices as uint16

const char* axis_name(GridKind kind, int axis) {
  static const char* const box[3] = {"x", "y", "z"};
  static const char* const sphere[3] = {"r", "theta", "phi"};
  return kind == GridKind::rectilinear || kind == GridKind::uniform ? box[axis] : sphere[axis];
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

double max_gap(const std::vector<double>& c) {
  double g = 0;
  for (std::size_t i = 1; i < c.size(); ++i) g = std::max(g, c[i] - c[i - 1]);
  return g;
}

}  // namespace

std::string_view to_string(GridKind kind) {
  switch (kind) {
    case GridKind::uniform: return "uniform";
    case GridKind::rectilinear: return "rectilinear";
    case GridKind::spherical: return "spherical";
    case GridKind::yinyang: return "yinyang";
  }
  return "?";
}

GridKind parse_grid_kind(std::string_view text) {
  for (GridKind k : {GridKind::uniform, GridKind::rectilinear, GridKind::spherical, GridKind::yinyang})
    if (text == to_string(k)) return k;
  throw Error("grid kind '" + std::string(text.substr(0, 40)) +
              "'; expected uniform, rectilinear, spherical or yinyang");
}

GridDescription GridDescription::make_uniform(const render::GridGeometry& g) {
  GridDescription d;
  d.kind = GridKind::uniform;
  d.uniform = g;
  return d;
}

GridDescription GridDescription::rectilinear(std::vector<double> x, std::vector<double> y, std::vector<double> z) {
  GridDescription d;
  d.kind = GridKind::rectilinear;
  d.coords = {std::move(x), std::move(y), std::move(z)};
  return d;
}

GridDescription GridDescription::spherical(std::vector<double> r, std::vector<double> theta, std::vector<double> phi) {
  GridDescription d;
  d.kind = GridKind::spherical;
  d.coords = {std::move(r), std::move(theta), std::move(phi)};
  return d;
}

GridDescription GridDescription::yinyang(std::vector<double> r, std::vector<double> theta, std::vector<double> phi) {
  GridDescription d = spherical(std::move(r), std::move(theta), std::move(phi));
  d.kind = GridKind::yinyang;
  return d;
}

GridDescription GridDescription::of_kind(GridKind kind, std::vector<double> a, std::vector<double> b,
                                         std::vector<double> c) {
  switch (kind) {
    case GridKind::rectilinear: return rectilinear(std::move(a), std::move(b), std::move(c));
    case GridKind::spherical: return spherical(std::move(a), std::move(b), std::move(c));
    case GridKind::yinyang: return yinyang(std::move(a), std::move(b), std::move(c));
    case GridKind::uniform: break;
  }
  throw Error("a " + std::string(to_string(kind)) + " grid is given by its origin and spacing, not by coordinate arrays");
}

GridDescription GridDescription::yinyang_standard(std::vector<double> r, int n_theta, int n_phi, double margin_cells) {
  if (n_theta < 2 || n_phi < 2 || !(margin_cells >= 0 && margin_cells < 8))
    throw Error("yinyang: " + std::to_string(n_theta) + " x " + std::to_string(n_phi) + " angles with margin " +
                num(margin_cells) + " cells; expected at least 2 x 2 and a margin in [0, 8)");
  // The spacing d of n points over [a − m·d, b + m·d] is (b − a) / (n − 1 − 2m).
  const double dt = (kPi / 2) / (n_theta - 1 - 2 * margin_cells);
  const double dp = (3 * kPi / 2) / (n_phi - 1 - 2 * margin_cells);
  if (!(dt > 0 && dp > 0)) throw Error("yinyang: the margin leaves no cells for the patch");
  std::vector<double> theta(static_cast<std::size_t>(n_theta)), phi(static_cast<std::size_t>(n_phi));
  for (int j = 0; j < n_theta; ++j) theta[std::size_t(j)] = kPi / 4 - margin_cells * dt + j * dt;
  for (int k = 0; k < n_phi; ++k) phi[std::size_t(k)] = -3 * kPi / 4 - margin_cells * dp + k * dp;
  return yinyang(std::move(r), std::move(theta), std::move(phi));
}

render::Index3 GridDescription::dims() const {
  if (kind == GridKind::uniform) return uniform.dims;
  return {int(coords[0].size()), int(coords[1].size()), int(coords[2].size())};
}

std::int64_t GridDescription::points_per_patch() const {
  const render::Index3 n = dims();
  return std::int64_t(n[0]) * n[1] * n[2];
}

void GridDescription::validate() const {
  const std::string what = std::string(to_string(kind)) + " grid: ";
  if (kind == GridKind::uniform) {
    uniform.validate();
    return;
  }
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& c = coords[std::size_t(a)];
    const std::string axis = axis_name(kind, a);
    if (c.size() < 2 || c.size() > std::size_t(kMaxAxisPoints))
      throw Error(what + std::to_string(c.size()) + " " + axis + " coordinates; expected 2 to " +
                  std::to_string(kMaxAxisPoints));
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (!std::isfinite(c[i])) throw Error(what + axis + "[" + std::to_string(i) + "] is not finite");
      if (i > 0 && !(c[i] > c[i - 1]))
        throw Error(what + axis + " coordinates are not strictly increasing: " + axis + "[" + std::to_string(i - 1) +
                    "] = " + num(c[i - 1]) + ", " + axis + "[" + std::to_string(i) + "] = " + num(c[i]));
    }
  }
  if (kind == GridKind::rectilinear) return;
  const auto& r = coords[0];
  const auto& t = coords[1];
  const auto& p = coords[2];
  if (r.front() < 0) throw Error(what + "r[0] = " + num(r.front()) + "; expected a radius >= 0");
  if (t.front() < 0 || t.back() > kPi)
    throw Error(what + "theta spans [" + num(t.front()) + ", " + num(t.back()) +
                "]; expected colatitudes in [0, pi] (radians)");
  if (p.back() - p.front() > 2 * kPi + 1e-9)
    throw Error(what + "phi spans [" + num(p.front()) + ", " + num(p.back()) + "]; expected at most 2 pi (radians)");
  if (kind == GridKind::yinyang) {
    const double eps = 1e-9;
    if (t.front() > kPi / 4 + eps || t.back() < 3 * kPi / 4 - eps || p.front() > -3 * kPi / 4 + eps ||
        p.back() < 3 * kPi / 4 - eps)
      throw Error(what + "a patch spans theta [" + num(t.front()) + ", " + num(t.back()) + "], phi [" +
                  num(p.front()) + ", " + num(p.back()) +
                  "]; Yin and Yang then leave a gap: each patch must cover theta [pi/4, 3pi/4] and phi [-3pi/4, 3pi/4]");
    if (t.front() <= 0 || t.back() >= kPi || p.front() <= -kPi || p.back() >= kPi)
      throw Error(what + "a patch spans theta [" + num(t.front()) + ", " + num(t.back()) + "], phi [" +
                  num(p.front()) + ", " + num(p.back()) +
                  "]; a Yin-Yang patch is a low-latitude one: theta within (0, pi), phi within (-pi, pi)");
  }
}

bool GridDescription::phi_periodic() const {
  if (kind != GridKind::spherical) return false;
  const auto& p = coords[2];
  const double gap = p.front() + 2 * kPi - p.back();
  return gap > 0 && gap <= 1.5 * max_gap(p);
}

std::array<double, 2> GridDescription::theta_cover() const {
  const auto& t = coords[1];
  if (t.size() < 2) return {0, 0};
  const std::size_t n = t.size();
  return {t[0] <= 1.5 * (t[1] - t[0]) ? 0.0 : t[0], kPi - t[n - 1] <= 1.5 * (t[n - 1] - t[n - 2]) ? kPi : t[n - 1]};
}

Vec3 GridDescription::point(int patch, int i, int j, int k) const {
  if (kind == GridKind::uniform)
    return {uniform.origin.x + i * uniform.spacing.x, uniform.origin.y + j * uniform.spacing.y,
            uniform.origin.z + k * uniform.spacing.z};
  if (kind == GridKind::rectilinear)
    return {coords[0][std::size_t(i)], coords[1][std::size_t(j)], coords[2][std::size_t(k)]};
  const double r = coords[0][std::size_t(i)], t = coords[1][std::size_t(j)], f = coords[2][std::size_t(k)];
  const Vec3 q{r * std::sin(t) * std::cos(f), r * std::sin(t) * std::sin(f), r * std::cos(t)};
  return patch == 1 ? yinyang_swap(q) : q;
}

Vec3 GridDescription::bounds_lo() const {
  if (kind == GridKind::uniform) return uniform.domain_lo();
  if (kind == GridKind::rectilinear) return {coords[0].front(), coords[1].front(), coords[2].front()};
  const double ro = coords[0].back();
  if (kind == GridKind::yinyang) return {-ro, -ro, -ro};
  // A sector: the box of a dense sampling of its bounding surfaces, padded by the sagitta of the
  // sampling step (the arc between two samples bulges at most r·(1 − cos(step/2)) beyond them).
  const int n = 256;
  const std::array<double, 2> t = theta_cover();
  const auto& p = coords[2];
  const double pt = phi_periodic() ? 2 * kPi : p.back() - p.front();
  const double step = std::max(t.back() - t.front(), pt) / n;
  Vec3 lo{1e300, 1e300, 1e300};
  for (double r : {coords[0].front(), ro})
    for (int a = 0; a <= n; ++a)
      for (int b = 0; b <= n; ++b) {
        const double th = t.front() + (t.back() - t.front()) * a / n, ph = p.front() + pt * b / n;
        const Vec3 q{r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th)};
        for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], q[c]);
      }
  const double pad = ro * (1 - std::cos(step / 2));
  for (int c = 0; c < 3; ++c) lo[c] = std::max(-ro, lo[c] - pad);
  return lo;
}

Vec3 GridDescription::bounds_hi() const {
  if (kind == GridKind::uniform) return uniform.domain_hi();
  if (kind == GridKind::rectilinear) return {coords[0].back(), coords[1].back(), coords[2].back()};
  const double ro = coords[0].back();
  if (kind == GridKind::yinyang) return {ro, ro, ro};
  // The mirror image of bounds_lo(): the box of the sector reflected through the origin.
  GridDescription m = *this;
  for (double& t : m.coords[1]) t = kPi - t;
  std::reverse(m.coords[1].begin(), m.coords[1].end());  // (its caps are the mirrored ones)
  for (double& p : m.coords[2]) p += kPi;
  const Vec3 lo = m.bounds_lo();
  return {-lo.x, -lo.y, -lo.z};
}

std::string GridDescription::summary() const {
  const render::Index3 n = dims();
  std::string s = std::string(to_string(kind)) + " " + std::to_string(n[0]) + "x" + std::to_string(n[1]) + "x" +
                  std::to_string(n[2]);
  if (kind == GridKind::spherical || kind == GridKind::yinyang)
    s += ", r in [" + num(coords[0].front()) + ", " + num(coords[0].back()) + "]";
  if (kind == GridKind::yinyang) s += ", 2 patches";
  return s;
}

render::GridGeometry uniform_cover(const GridDescription& grid, int longest_axis_points) {
  if (longest_axis_points < 2)
    throw Error("uniform cover: " + std::to_string(longest_axis_points) + " points; expected at least 2");
  grid.validate();
  const Vec3 lo = grid.bounds_lo(), hi = grid.bounds_hi();
  const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double h = longest / (longest_axis_points - 1);
  render::GridGeometry g;
  for (int a = 0; a < 3; ++a) {
    const int n = std::max(2, int(std::ceil((hi[a] - lo[a]) / h - 1e-9)) + 1);
    g.dims[a] = n;
    // Centre the (slightly larger) cover on the domain's box.
    g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * (n - 1) * h;
  }
  g.spacing = {h, h, h};
  g.validate();
  return g;
}

}  // namespace panoptes::grid
