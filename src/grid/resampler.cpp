#include "grid/resampler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace panoptes::grid {
namespace {

constexpr double kPi = std::numbers::pi;

std::string str(const render::Index3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

// A coordinate axis: coordinate → (lower index, weight of the upper one), or "outside".
struct AxisMap {
  const std::vector<double>* c = nullptr;
  double tol_lo = 0, tol_hi = 0;   // coordinates this far beyond an end clamp to it
  bool periodic = false;           // φ closing the circle: between c[last] and c[0] + 2π
  bool angular = false;            // a longitude: taken modulo 2π into [c[0], c[0] + 2π) first
  double period = 2 * kPi;

  // Returns false when v lies outside. Otherwise i ∈ [0, n − 2] (periodic: [0, n − 1], wrap when
  // i = n − 1) and w ∈ [0, 1].
  bool locate(double v, int& i, double& w, bool& wrap) const {
    const std::vector<double>& a = *c;
    const int n = int(a.size());
    wrap = false;
    if (angular) v = a.front() + std::fmod(std::fmod(v - a.front(), period) + period, period);
    if (periodic) {
      if (v >= a.back()) {
        i = n - 1;
        w = std::clamp((v - a.back()) / (a.front() + period - a.back()), 0.0, 1.0);
        wrap = true;
        return true;
      }
    } else {
      if (!(v >= a.front() - tol_lo && v <= a.back() + tol_hi)) return false;
      if (v <= a.front()) { i = 0; w = 0; return true; }
      if (v >= a.back()) { i = n - 2; w = 1; return true; }
    }
    i = int(std::upper_bound(a.begin(), a.end(), v) - a.begin()) - 1;
    i = std::clamp(i, 0, n - 2);
    w = std::clamp((v - a[std::size_t(i)]) / (a[std::size_t(i) + 1] - a[std::size_t(i)]), 0.0, 1.0);
    return true;
  }
};

std::uint16_t weight16(double w) { return std::uint16_t(std::lround(std::clamp(w, 0.0, 1.0) * 65535.0)); }

// The longitude of a patch's frame normalized into [φ0, φ0 + 2π), for edge distances.
double wrap_phi(double f, double phi0) { return phi0 + std::fmod(std::fmod(f - phi0, 2 * kPi) + 2 * kPi, 2 * kPi); }

}  // namespace

SourceBlock SourceBlock::whole(const GridDescription& grid, int patch, const float* data) {
  return of(patch, {{0, 0, 0}, grid.dims()}, data);
}

SourceBlock SourceBlock::of(int patch, const render::PointRange& points, const float* data) {
  SourceBlock b;
  b.patch = patch;
  b.points = points;
  b.data = data;
  const std::int64_t nx = points.hi[0] - points.lo[0], ny = points.hi[1] - points.lo[1];
  b.stride = {1, nx, nx * ny};
  return b;
}

Resampler::Resampler(const GridDescription& source, const render::GridGeometry& target,
                     const render::PointRange& points, float outside_value)
    : source_(source), target_(target), points_(points), outside_value_(outside_value) {
  source_.validate();
  target_.validate();
  for (int a = 0; a < 3; ++a)
    if (points.lo[a] < 0 || points.hi[a] > target.dims[a] || points.lo[a] >= points.hi[a])
      throw Error("resampler: target points " + str(points.lo) + "-" + str(points.hi) + " outside the grid of " +
                  str(target.dims) + " points or empty");
  if (source_.kind == GridKind::uniform) {
    // A uniform source is a rectilinear one with evenly spaced coordinates.
    const render::GridGeometry g = source_.uniform;
    std::array<std::vector<double>, 3> c;
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < g.dims[a]; ++i) c[std::size_t(a)].push_back(g.origin[a] + i * g.spacing[a]);
    source_ = GridDescription::rectilinear(c[0], c[1], c[2]);
  }
  const render::Index3 n = source_.dims();
  const int np = source_.patches();
  const std::int64_t nx = points.hi[0] - points.lo[0], ny = points.hi[1] - points.lo[1],
                     nz = points.hi[2] - points.lo[2];
  plan_.assign(std::size_t(nx * ny * nz), Stencil{0, 0, 0, 0, 0, 0, 0, kOutside});

  AxisMap axes[3];
  for (int a = 0; a < 3; ++a) axes[a].c = &source_.coords[std::size_t(a)];
  if (source_.kind == GridKind::rectilinear) {
    // The uniform cover may reach up to a spacing beyond the box: those points clamp to its faces.
    for (auto& ax : axes) ax.tol_lo = ax.tol_hi = target.voxel() * (1 + 1e-9);
  } else {
    const auto& t = source_.coords[1];
    // Pole caps: a colatitude grid that stops within 1.5 spacings of a pole extends its end ring.
    const std::array<double, 2> cover = source_.theta_cover();
    if (cover[0] < t.front()) axes[1].tol_lo = t.front() + 1e-12;
    if (cover[1] > t.back()) axes[1].tol_hi = kPi - t.back() + 1e-12;
    axes[2].periodic = source_.phi_periodic();
    axes[2].angular = true;
  }

  const bool sphere = source_.kind == GridKind::spherical || source_.kind == GridKind::yinyang;
  const auto& tc = source_.coords[1];
  const auto& pc = source_.coords[2];
  std::int64_t outside = 0;
#pragma omp parallel for schedule(dynamic) reduction(+ : outside)
  for (std::int64_t z = 0; z < nz; ++z) {
    for (std::int64_t y = 0; y < ny; ++y)
      for (std::int64_t x = 0; x < nx; ++x) {
        const Vec3 p{target.origin.x + double(points.lo[0] + x) * target.spacing.x,
                     target.origin.y + double(points.lo[1] + y) * target.spacing.y,
                     target.origin.z + double(points.lo[2] + z) * target.spacing.z};
        Stencil& s = plan_[std::size_t((z * ny + y) * nx + x)];
        double u[3];
        int patch = 0;
        if (!sphere) {
          u[0] = p.x, u[1] = p.y, u[2] = p.z;
        } else {
          const double r = norm(p);
          u[0] = r;
          u[1] = r > 0 ? std::acos(std::clamp(p.z / r, -1.0, 1.0)) : 0.0;
          u[2] = std::atan2(p.y, p.x);
          if (source_.kind == GridKind::yinyang) {
            // The patch the point lies farther inside: distances to the angular edges.
            const Vec3 q = yinyang_swap(p);
            const double t2 = r > 0 ? std::acos(std::clamp(q.z / r, -1.0, 1.0)) : 0.0, f2 = std::atan2(q.y, q.x);
            auto inside = [&](double th, double ph) {
              ph = wrap_phi(ph, pc.front());
              return std::min({th - tc.front(), tc.back() - th, ph - pc.front(), pc.back() - ph});
            };
            if (inside(t2, f2) > inside(u[1], u[2])) {
              patch = 1;
              u[1] = t2;
              u[2] = f2;
            }
          }
        }
        int idx[3];
        double w[3];
        bool wrap[3];
        bool in = true;
        for (int a = 0; a < 3 && in; ++a) in = axes[a].locate(u[a], idx[a], w[a], wrap[a]);
        if (!in) {
          ++outside;
          continue;
        }
        s = Stencil{std::uint16_t(idx[0]), std::uint16_t(idx[1]), std::uint16_t(idx[2]),
                    weight16(w[0]),        weight16(w[1]),        weight16(w[2]),
                    std::uint8_t(patch),   std::uint8_t(wrap[2] ? kWrap : 0)};
      }
  }
  outside_ = outside;

  // What the plan reads, per patch.
  std::vector<render::PointRange> need(std::size_t(np), render::PointRange{n, {0, 0, 0}});
  for (const Stencil& s : plan_) {
    if (s.flags & kOutside) continue;
    render::PointRange& r = need[s.patch];
    const int lo[3] = {s.i, s.j, (s.flags & kWrap) ? 0 : s.k};
    const int hi[3] = {s.i + 2, s.j + 2, (s.flags & kWrap) ? n[2] : s.k + 2};
    for (int a = 0; a < 3; ++a) {
      r.lo[a] = std::min(r.lo[a], lo[a]);
      r.hi[a] = std::max(r.hi[a], std::min(hi[a], n[a]));
    }
  }
  for (auto& r : need)
    if (r.lo[0] >= r.hi[0]) r = {};
  needed_ = std::move(need);
}

void Resampler::resample(std::span<const SourceBlock> blocks, std::span<float> out) const {
  if (std::int64_t(out.size()) < size())
    throw Error("resampler: output of " + std::to_string(out.size()) + " values; expected " + std::to_string(size()));
  const render::Index3 n = source_.dims();
  std::vector<const SourceBlock*> by_patch(needed_.size(), nullptr);
  for (std::size_t p = 0; p < needed_.size(); ++p) {
    const render::PointRange& need = needed_[p];
    if (need.lo == need.hi) continue;
    for (const SourceBlock& b : blocks)
      if (b.patch == int(p) && b.data && b.points.contains(need)) {
        by_patch[p] = &b;
        break;
      }
    if (!by_patch[p])
      throw Error("resampler: no source block of patch " + std::to_string(p) + " covers points " + str(need.lo) +
                  "-" + str(need.hi) + " that the target points " + str(points_.lo) + "-" + str(points_.hi) +
                  " read");
  }
  const float fill = outside_value_;
  const std::int64_t count = size();
  constexpr float kW = 1.0f / 65535.0f;
#pragma omp parallel for schedule(static, 4096)
  for (std::int64_t q = 0; q < count; ++q) {
    const Stencil& s = plan_[std::size_t(q)];
    if (s.flags & kOutside) {
      out[std::size_t(q)] = fill;
      continue;
    }
    const SourceBlock& b = *by_patch[s.patch];
    const std::int64_t sx = b.stride[0], sy = b.stride[1];
    const std::int64_t sz = (s.flags & kWrap) ? -std::int64_t(n[2] - 1) * b.stride[2] : b.stride[2];
    const float* c = b.data + (s.i - b.points.lo[0]) * sx + (s.j - b.points.lo[1]) * sy +
                     (s.k - b.points.lo[2]) * b.stride[2];
    const float fx = float(s.wi) * kW, fy = float(s.wj) * kW, fz = float(s.wk) * kW;
    // A zero weight at the last point of an axis must not read past it.
    const std::int64_t dx = s.i + 1 < n[0] ? sx : 0, dy = s.j + 1 < n[1] ? sy : 0;
    const std::int64_t dz = (s.flags & kWrap) || s.k + 1 < n[2] ? sz : 0;
    const float c00 = c[0] + fx * (c[dx] - c[0]);
    const float c10 = c[dy] + fx * (c[dy + dx] - c[dy]);
    const float c01 = c[dz] + fx * (c[dz + dx] - c[dz]);
    const float c11 = c[dz + dy] + fx * (c[dz + dy + dx] - c[dz + dy]);
    const float c0 = c00 + fy * (c10 - c00);
    const float c1 = c01 + fy * (c11 - c01);
    out[std::size_t(q)] = c0 + fz * (c1 - c0);
  }
}

}  // namespace panoptes::grid
