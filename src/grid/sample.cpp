#include "grid/sample.hpp"

#include <cmath>
#include <numbers>

namespace panoptes::grid {

std::vector<float> sample(const GridDescription& grid, int patch, const std::function<double(const Vec3&)>& f) {
  const render::Index3 n = grid.dims();
  std::vector<float> v(std::size_t(grid.points_per_patch()));
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        v[(std::size_t(k) * std::size_t(n[1]) + std::size_t(j)) * std::size_t(n[0]) + std::size_t(i)] =
            float(f(grid.point(patch, i, j, k)));
  return v;
}

std::vector<float> sample(const render::GridGeometry& grid, const std::function<double(const Vec3&)>& f) {
  return sample(GridDescription::make_uniform(grid), 0, f);
}

double ShellField::operator()(const Vec3& p) const {
  const double r = norm(p);
  if (!(r >= r_in && r <= r_out) || r == 0) return 0;
  const double radial = std::sin(std::numbers::pi * (r - r_in) / (r_out - r_in));
  const double x = p.x / r, y = p.y / r, z = p.z / r;  // unit vector: (sinθ cosφ, sinθ sinφ, cosθ)
  const double y20 = 0.5 * (3 * z * z - 1);
  // sin²θ·cos(2φ − t) and sinθ·(5cos²θ − 1)·cos(φ + t/2), expanded in x, y, z.
  const double y22 = (x * x - y * y) * std::cos(t) + 2 * x * y * std::sin(t);
  const double y31 = (5 * z * z - 1) * (x * std::cos(0.5 * t) - y * std::sin(0.5 * t));
  return radial * (0.6 * y20 + 0.9 * y22 + 0.5 * y31);
}

}  // namespace panoptes::grid
