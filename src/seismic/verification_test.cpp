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

// One OpenMP thread per test process unless OMP_NUM_THREADS says otherwise: ctest runs the cases in
// parallel on a shared 2-core machine, where spinning thread teams only slow each other down.
static const bool kThreads = panoptes::seismic::test_util::default_single_thread();

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
  const double rmax = 200;
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
  const std::vector<double> dist = {120, 160, 200, 150, 185, 170, 135};
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const auto& d = dirs[i];
    const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    cfg.receivers.push_back(ReceiverSpec{"r" + std::to_string(i),
                                         {c + dist[i] * d[0] / l, c + dist[i] * d[1] / l, c + dist[i] * d[2] / l}});
  }
  const double t_end = src.stf.delay + 1.2 / kF0 + rmax / kVs + 0.03;
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

void convergence(const SourceSpec& src, const char* name, std::vector<double> ppws) {
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
  convergence(SourceSpec::explosion({0, 0, 0}, 1e15, SourceTimeFunction::ricker(kF0, 1.2 / kF0)), "explosion", {6, 8});
}

TEST(SeismicVerification, DoubleCoupleWholeSpaceMatchesAkiRichards) {
  convergence(SourceSpec::double_couple({0, 0, 0}, 30, 60, 45, 1e15, SourceTimeFunction::ricker(kF0, 1.2 / kF0)),
              "double couple", {6, 8});
}

namespace {

/// Spectral amplitude |∫ v(t) e^{−2πift} dt| of a sampled trace.
double spectral_amplitude(const std::vector<double>& t, const std::vector<double>& v, double f) {
  std::complex<double> s = 0;
  for (std::size_t i = 0; i < t.size(); ++i) s += v[i] * std::exp(std::complex<double>(0, -2 * std::numbers::pi * f * t[i]));
  return std::abs(s);
}

/// Lag (in samples, sub-sample by parabolic fit) maximising the cross-correlation of b against a.
double xcorr_lag(const std::vector<double>& a, const std::vector<double>& b, int max_lag) {
  std::vector<double> c(max_lag + 1, 0.0);
  for (int L = 0; L <= max_lag; ++L)
    for (std::size_t i = 0; i + L < b.size(); ++i) c[L] += a[i] * b[i + L];
  int best = int(std::max_element(c.begin(), c.end()) - c.begin());
  if (best == 0 || best == max_lag) return best;
  const double y0 = c[best - 1], y1 = c[best], y2 = c[best + 1];
  return best + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2);
}

}  // namespace

TEST(SeismicVerification, RayleighWaveSpeedAtFreeSurface) {
  // Vertical force at the surface of a Poisson half-space; vz along the surface at two distances.
  const double h = kVs / kF0 / 20;  // 20 nodes per S wavelength at f0
  const int pml = 8;
  SolverConfig cfg;
  const int r1 = 30, r2 = 70, x0 = pml + 5;
  cfg.grid = {x0 + r2 + 5 + pml + 1, 2 * (pml + 12) + 1, 36 + pml, h};
  cfg.medium = MediumSpec::homogeneous(kRho, kVp, kVs);
  cfg.boundary.pml_cells = pml;
  const double yc = (pml + 12) * h;
  cfg.sources = {SourceSpec::point_force({x0 * h, yc, 0.5 * h}, {0, 0, 1e9}, SourceTimeFunction::ricker(kF0, 1.2 / kF0))};
  cfg.receivers = {ReceiverSpec{"near", {(x0 + r1) * h, yc, 0}}, ReceiverSpec{"far", {(x0 + r2) * h, yc, 0}}};
  const double cr = 0.9194 * kVs;
  const double t_end = cfg.sources[0].stf.end_time() + r2 * h / cr + 0.1;
  Solver s(cfg);
  s.run(int(std::ceil(t_end / s.dt())));
  const auto g = s.gather_seismograms();
  // Window each trace around its Rayleigh arrival (cuts the faster, weaker P and S arrivals).
  auto windowed = [&](const Seismogram& tr, double r) {
    std::vector<double> w(tr.time.size());
    const double tc = cfg.sources[0].stf.delay + r / cr, half = 1.2 / kF0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const double x = (tr.time[i] - tc) / half;
      w[i] = std::abs(x) < 1 ? tr.vz[i] * 0.5 * (1 + std::cos(std::numbers::pi * x)) : 0.0;
    }
    return w;
  };
  const auto a = windowed(g[0], r1 * h), b = windowed(g[1], r2 * h);
  const double lag = xcorr_lag(a, b, int(a.size()) - 1) * s.dt();
  const double speed = (r2 - r1) * h / lag;
  std::printf("[rayleigh] measured speed %.2f m/s, theory 0.9194*Vs = %.2f m/s, error %.3f %%\n", speed, cr,
              100 * (speed / cr - 1));
  EXPECT_NEAR(speed / cr, 1.0, 0.01);
}

TEST(SeismicVerification, AbsorbingBoundariesRemoveTheEnergy) {
  // Explosion in a small whole-space box: after the waves have left, < 1 % of the peak energy stays.
  const double h = kLambdaMin / 6;
  const int pml = 10, half = 14;
  const int n = 2 * (pml + half) + 1;
  SolverConfig cfg;
  cfg.grid = {n, n, n, h};
  cfg.medium = MediumSpec::homogeneous(kRho, kVp, kVs);
  cfg.boundary.free_surface = false;
  cfg.boundary.pml_cells = pml;
  const double c = (pml + half) * h;
  cfg.sources = {SourceSpec::double_couple({c, c, c}, 10, 70, 20, 1e15, SourceTimeFunction::ricker(kF0))};
  Solver s(cfg);
  const double t_end = cfg.sources[0].stf.end_time() + 3 * half * h / kVs;
  double peak = 0, last = 0;
  while (s.steps_done() * s.dt() < t_end) {
    s.step();
    last = s.energy();
    peak = std::max(peak, last);
  }
  std::printf("[cpml] peak energy %.4e J, energy after %.2f s: %.4e J = %.4f %% of peak\n", peak, t_end, last,
              100 * last / peak);
  EXPECT_GT(peak, 0);
  EXPECT_LT(last, 0.01 * peak);
}

TEST(SeismicVerification, ConstantQAmplitudeDecay) {
  // P pulse of an explosion recorded at r1 and r2; the viscoelastic/elastic spectral ratio at f0
  // must equal exp(−π f0 (r2 − r1)/(Vp Q)) (geometric spreading and numerics cancel in the ratio).
  const double Q = 10, h = 16;
  const int pml = 10, side = 8;
  const double r1 = 100, r2 = 400;
  auto run = [&](double q) {
    SolverConfig cfg;
    const int nx = 2 * pml + 4 + int(r2 / h) + 6;
    const int n = 2 * (pml + side) + 1;
    cfg.grid = {nx, n, n, h};
    cfg.medium = MediumSpec::homogeneous(kRho, kVp, kVs, q, q);
    cfg.boundary.free_surface = false;
    cfg.boundary.pml_cells = pml;
    const double x0 = (pml + 4) * h, c = (pml + side) * h;
    cfg.sources = {SourceSpec::explosion({x0, c, c}, 1e15, SourceTimeFunction::ricker(kF0))};
    cfg.receivers = {ReceiverSpec{"r1", {x0 + r1, c, c}}, ReceiverSpec{"r2", {x0 + r2, c, c}}};
    Solver s(cfg);
    EXPECT_EQ(s.viscoelastic(), std::isfinite(q));
    s.run(int(std::ceil((cfg.sources[0].stf.end_time() + r2 / kVp + 0.25) / s.dt())));
    const auto g = s.gather_seismograms();
    return spectral_amplitude(g[1].time, g[1].vx, kF0) / spectral_amplitude(g[0].time, g[0].vx, kF0);
  };
  const double elastic = run(std::numeric_limits<double>::infinity());
  const double visco = run(Q);
  const double measured = visco / elastic;
  const double expected = std::exp(-std::numbers::pi * kF0 * (r2 - r1) / kVp / Q);
  std::printf("[attenuation] Q = %.0f: amplitude ratio at f0 measured %.4f, exp(-pi f t/Q) = %.4f, error %.2f %%; "
              "apparent Q = %.2f\n",
              Q, measured, expected, 100 * (measured / expected - 1),
              -std::numbers::pi * kF0 * (r2 - r1) / kVp / std::log(measured));
  EXPECT_NEAR(measured / expected, 1.0, 0.05);
}

TEST(SeismicVerification, LongRunStable) {
  // 10,000 steps on a tiny grid with CPML, free surface and attenuation: the energy must decay.
  SolverConfig cfg;
  const int n = 18;
  const double h = 20;
  cfg.grid = {n, n, n, h};
  cfg.boundary.pml_cells = 6;
  cfg.medium = MediumSpec::homogeneous(kRho, kVp, kVs, 40, 20);
  cfg.sources = {SourceSpec::explosion({9 * h, 9 * h, 5 * h}, 1e15, SourceTimeFunction::ricker(kF0))};
  Solver s(cfg);
  double peak = 0, tail = 0;
  for (int i = 0; i < 10000; ++i) {
    s.step();
    if (i % 50 == 0 || i >= 9990) {
      const double e = s.energy();
      ASSERT_TRUE(std::isfinite(e)) << "step " << i;
      peak = std::max(peak, e);
      if (i >= 9990) tail = std::max(tail, e);
    }
  }
  std::printf("[stability] 10000 steps: peak energy %.4e J, final %.4e J (ratio %.2e)\n", peak, tail, tail / peak);
  EXPECT_LT(tail, 1e-3 * peak);
}
