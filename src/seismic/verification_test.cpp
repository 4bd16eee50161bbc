// Verification against exact solutions: homogeneous whole space (Aki & Richards), Rayleigh-wave
// speed at a free surface, CPML energy decay, constant-Q amplitude decay, long-run stability.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "seismic/analytic.hpp"
#include "seismic/solver.hpp"
#include "seismic/test_util.hpp"

using namespace panoptes::seismic;

namespace {

constexpr double kRho = 2000, kVp = 1732.0508, kVs = 1000;  // Poisson solid
constexpr double kF0 = 5.0;                                  // Ricker peak: f_max = 12.5 Hz, λ_min(S) = 80 m
constexpr double kLambdaMin = kVs / (2.5 * kF0);

struct WholeSpaceResult {
  std::vector<double> misfits;  // one per receiver
  double worst = 0, total = 0;
};

/// Source at the centre node, receivers at 200–300 m in several directions, top absorbing.
WholeSpaceResult whole_space(const SourceSpec& proto, double ppw) {
  const double h = kLambdaMin / ppw;
  const int pml = 10;
  const double rmax = 300;
  const int half = int(std::ceil(rmax / h)) + 3;
  const int n = 2 * (half + pml) + 1;
  const double c = (half + pml) * h;
  SolverConfig cfg;
  cfg.grid = {n, n, n, h};
  cfg.medium = MediumSpec::homogeneous(kRho, kVp, kVs);
  cfg.boundary.free_surface = false;
  cfg.boundary.pml_cells = pml;
  SourceSpec src = proto;
  src.position = {c, c, c};
  cfg.sources = {src};
  const std::vector<std::array<double, 3>> dirs = {
      {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {-1, 2, 0.5}, {0.3, -1, -0.7}, {-1, -0.2, 0.4}};
  const std::vector<double> dist = {200, 250, 300, 230, 280, 260, 215};
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const auto& d = dirs[i];
    const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    cfg.receivers.push_back(ReceiverSpec{"r" + std::to_string(i),
                                         {c + dist[i] * d[0] / l, c + dist[i] * d[1] / l, c + dist[i] * d[2] / l}});
  }
  const double t_end = src.stf.end_time() + 300 / kVs + 0.05;
  Solver s(cfg);
  s.run(int(std::ceil(t_end / s.dt())));
  const auto seis = s.gather_seismograms();
  WholeSpaceResult r;
  double num = 0, den = 0;
  for (const auto& g : seis) {
    const double m = test_util::misfit(g, src, kRho, kVp, kVs);
    r.misfits.push_back(m);
    r.worst = std::max(r.worst, m);
    // Weight by the exact energy for the total.
    double e = 0;
    for (std::size_t t = 0; t < g.time.size(); ++t) {
      const auto x = whole_space_velocity(src, g.position, g.time[t], kRho, kVp, kVs);
      e += x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    }
    num += m * m * e;
    den += e;
  }
  r.total = std::sqrt(num / den);
  return r;
}

void convergence(const SourceSpec& src, const char* name) {
  const std::vector<double> ppws = {5, 6, 8};
  std::vector<double> tot;
  for (double p : ppws) {
    const auto r = whole_space(src, p);
    std::printf("[%s] %.0f points per minimum wavelength: total misfit %.4f, worst receiver %.4f (", name, p, r.total,
                r.worst);
    for (double m : r.misfits) std::printf(" %.4f", m);
    std::printf(" )\n");
    tot.push_back(r.total);
    if (p == 8) {
      EXPECT_LE(r.worst, 0.03) << name << " at 8 points per wavelength";
    }
  }
  for (std::size_t i = 1; i < tot.size(); ++i) {
    EXPECT_LT(tot[i], tot[i - 1]) << name << ": misfit must decrease under refinement";
    const double order = std::log(tot[i - 1] / tot[i]) / std::log(ppws[i] / ppws[i - 1]);
    std::printf("[%s] measured order of accuracy %.0f -> %.0f ppw: %.2f\n", name, ppws[i - 1], ppws[i], order);
  }
}

}  // namespace

TEST(SeismicVerification, ExplosionWholeSpaceMatchesAkiRichards) {
  convergence(SourceSpec::explosion({0, 0, 0}, 1e15, SourceTimeFunction::ricker(kF0)), "explosion");
}
