#include "render/synthetic_fields.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace panoptes::render {

std::vector<float> wave_field(const GridGeometry& g, std::span<const WaveFront> fronts) {
  return wave_field(g, fronts, {});
}

std::vector<float> wave_field(const GridGeometry& g, std::span<const WaveFront> fronts,
                              std::span<const StandingWave> standing) {
  g.validate();
  const std::int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  std::vector<float> v(std::size_t(nx * ny * nz));
  constexpr double kTwoPi = 2 * std::numbers::pi;
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
        for (const StandingWave& w : standing) {
          double a = w.amplitude;
          for (int ax = 0; ax < 3; ++ax)
            if (w.wavelength[ax] != 0) a *= std::cos(kTwoPi * p[ax] / w.wavelength[ax] + w.phase[ax]);
          s += a;
        }
        v[std::size_t(i + nx * (j + ny * k))] = float(s);
      }
  return v;
}

DenseWaveScene dense_wave_scene(const GridGeometry& g) {
  // Everything is placed relative to the domain, so a small test grid holds the same picture.
  const Vec3 lo = g.domain_lo(), hi = g.domain_hi(), ext = hi - lo;
  auto at = [&](double fx, double fy, double fz) { return Vec3{lo.x + fx * ext.x, lo.y + fy * ext.y, lo.z + fz * ext.z}; };
  const double L = std::max({ext.x, ext.y, ext.z});
  const double w = std::max(L / 128, 1.5 * std::max({g.spacing.x, g.spacing.y, g.spacing.z}));
  const Vec3 src[3] = {at(0.5, 0.35, 0.55), at(0.3, 0.75, 0.35), at(0.7, 0.6, 0.8)};
  std::vector<WaveFront> pf, sf;
  for (int s = 0; s < 3; ++s)
    for (int n = 1; n <= 4; ++n) {
      // P shells travel ~1.7x faster than S shells: larger radii for the same sources.
      pf.push_back({src[s], L * (0.12 * n + 0.03 * s), 2 * w, (s % 2 ? -0.8 : 1.0) / std::sqrt(double(n))});
      sf.push_back({src[s], L * (0.07 * n + 0.02 * s), 1.5 * w, (s % 2 ? 0.9 : -0.7) / std::sqrt(double(n))});
    }
  const StandingWave ps[] = {{{ext.x / 1.5, ext.y / 2.5, ext.z / 1.2}, {0.3, 1.1, 0.2}, 0.55},
                             {{ext.x / 3.5, ext.y / 4.0, 0}, {1.7, 0.4, 0}, 0.2}};
  const StandingWave ss[] = {{{ext.x / 2.0, ext.y / 1.5, ext.z / 1.8}, {0.9, 0.2, 1.3}, 0.5},
                             {{0, ext.y / 5.0, ext.z / 2.5}, {0, 2.1, 0.6}, 0.2}};
  return {wave_field(g, pf, ps), wave_field(g, sf, ss)};
}

}  // namespace panoptes::render
