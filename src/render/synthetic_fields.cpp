#include "render/synthetic_fields.hpp"

#include <algorithm>
#include <cmath>

namespace panoptes::render {

std::vector<float> wave_field(const GridGeometry& g, std::span<const WaveFront> fronts) {
  g.validate();
  const std::int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  std::vector<float> v(std::size_t(nx * ny * nz));
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < nz; ++k)
    for (std::int64_t j = 0; j < ny; ++j)
      for (std::int64_t i = 0; i < nx; ++i) {
        const Vec3 p{g.origin.x + i * g.spacing.x, g.origin.y + j * g.spacing.y, g.origin.z + k * g.spacing.z};
        double s = 0;
        for (const WaveFront& f : fronts) {
          const double r = norm(p - f.centre);
          const double u = (r - f.radius) / f.width;
          if (std::abs(u) > 6) continue;  // exp(−36): below float resolution of the peak
          s += f.amplitude * (1 - 2 * u * u) * std::exp(-u * u);
        }
        v[std::size_t(i + nx * (j + ny * k))] = float(s);
      }
  return v;
}

}  // namespace panoptes::render
