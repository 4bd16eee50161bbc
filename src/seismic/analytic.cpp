#include "seismic/analytic.hpp"

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace panoptes::seismic {

namespace {

/// ∫_{a}^{b} τ·f(t − τ) dτ by composite Simpson (f smooth; 400 panels resolve ≥ 10 periods).
template <class F>
double near_field_integral(F f, double t, double a, double b) {
  const int n = 800;
  const double hq = (b - a) / n;
  double s = a * f(t - a) + b * f(t - b);
  for (int i = 1; i < n; ++i) {
    const double tau = a + i * hq;
    s += (i % 2 ? 4.0 : 2.0) * tau * f(t - tau);
  }
  return s * hq / 3.0;
}

}  // namespace

std::array<double, 3> whole_space_velocity(const SourceSpec& src, const std::array<double, 3>& x, double t,
                                           double rho, double alpha, double beta) {
  const double d[3] = {x[0] - src.position[0], x[1] - src.position[1], x[2] - src.position[2]};
  const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  require(r > 0, "analytic solution: receiver at the source position");
  const double g[3] = {d[0] / r, d[1] / r, d[2] / r};
  const double ta = r / alpha, tb = r / beta;
  const auto& stf = src.stf;
  auto rate = [&](double tt) { return stf.rate(tt); };
  auto val = [&](double tt) { return stf.value(tt); };
  const double c = 1.0 / (4 * std::numbers::pi * rho);
  std::array<double, 3> v{0, 0, 0};
  auto delta = [](int a, int b) { return a == b ? 1.0 : 0.0; };
  if (src.kind == SourceSpec::Kind::moment) {
    // Velocity: the displacement formula with S replaced by dS/dt.
    const double In = near_field_integral(rate, t, ta, tb);
    const double Sa = stf.rate(t - ta), Sb = stf.rate(t - tb);
    const double Da = stf.rate2(t - ta), Db = stf.rate2(t - tb);
    const auto& m6 = src.moment;
    const double M[3][3] = {{m6[0], m6[3], m6[4]}, {m6[3], m6[1], m6[5]}, {m6[4], m6[5], m6[2]}};
    for (int n = 0; n < 3; ++n) {
      double s = 0;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) {
          if (M[p][q] == 0) continue;
          const double ggg = g[n] * g[p] * g[q];
          const double AN = 15 * ggg - 3 * g[n] * delta(p, q) - 3 * g[p] * delta(n, q) - 3 * g[q] * delta(n, p);
          const double AIP = 6 * ggg - g[n] * delta(p, q) - g[p] * delta(n, q) - g[q] * delta(n, p);
          const double AIS = 6 * ggg - g[n] * delta(p, q) - g[p] * delta(n, q) - 2 * g[q] * delta(n, p);
          const double AFP = ggg;
          const double AFS = ggg - g[q] * delta(n, p);
          s += M[p][q] * (AN / (r * r * r * r) * In + AIP / (alpha * alpha * r * r) * Sa -
                          AIS / (beta * beta * r * r) * Sb + AFP / (alpha * alpha * alpha * r) * Da -
                          AFS / (beta * beta * beta * r) * Db);
        }
      v[n] = c * s;
    }
  } else {
    const double In = near_field_integral(rate, t, ta, tb);
    (void)val;
    const double Sa = stf.rate(t - ta), Sb = stf.rate(t - tb);
    for (int i = 0; i < 3; ++i) {
      double s = 0;
      for (int j = 0; j < 3; ++j) {
        const double F = src.force[j];
        if (F == 0) continue;
        const double gg = g[i] * g[j];
        s += F * ((3 * gg - delta(i, j)) / (r * r * r) * In + gg / (alpha * alpha * r) * Sa -
                  (gg - delta(i, j)) / (beta * beta * r) * Sb);
      }
      v[i] = c * s;
    }
  }
  return v;
}

}  // namespace panoptes::seismic
