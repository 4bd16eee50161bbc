// Bad input is a clear error before any step: media, sources, receivers, CFL, medium files.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <fstream>

#include "core/error.hpp"
#include "seismic/attenuation.hpp"
#include "seismic/medium.hpp"
#include "seismic/solver.hpp"

using namespace panoptes::seismic;
using panoptes::Error;

namespace {

SolverConfig small() {
  SolverConfig cfg;
  cfg.grid = {20, 20, 20, 10};
  cfg.boundary.pml_cells = 5;
  cfg.medium = MediumSpec::homogeneous(2000, 2000, 1000);
  cfg.sources = {SourceSpec::explosion({100, 100, 100}, 1e12, SourceTimeFunction::ricker(10))};
  cfg.receivers = {ReceiverSpec{"a", {120, 100, 0}}};
  return cfg;
}

std::string error_of(const SolverConfig& cfg) {
  try {
    Solver s(cfg);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SeismicInput, ValidConfigConstructs) { EXPECT_EQ(error_of(small()), ""); }

TEST(SeismicInput, NonPositiveVelocitiesAndDensity) {
  auto c = small();
  c.medium.layers[0].vp = 0;
  EXPECT_NE(error_of(c).find("Vp 0"), std::string::npos) << error_of(c);
  c = small();
  c.medium.layers[0].vs = -5;
  EXPECT_NE(error_of(c).find("Vs -5"), std::string::npos) << error_of(c);
  c = small();
  c.medium.layers[0].rho = 0;
  EXPECT_NE(error_of(c).find("density"), std::string::npos) << error_of(c);
}

TEST(SeismicInput, VsAboveVpOverSqrt2) {
  auto c = small();
  c.medium.layers.push_back(Layer{100, 2000, 2000, 1500});
  const auto e = error_of(c);
  EXPECT_NE(e.find("Vp/sqrt(2)"), std::string::npos) << e;
  EXPECT_NE(e.find("node (0, 0, 10)"), std::string::npos) << e;
}

TEST(SeismicInput, SourceAndReceiverOutsideTheDomain) {
  auto c = small();
  c.sources[0].position = {100, 100, 190};  // inside the bottom CPML
  EXPECT_NE(error_of(c).find("source 0"), std::string::npos) << error_of(c);
  c = small();
  c.receivers[0].position = {-1, 100, 10};
  EXPECT_NE(error_of(c).find("receiver 'a'"), std::string::npos) << error_of(c);
  c = small();
  c.receivers[0].position = {100, 100, -0.5};  // above the free surface
  EXPECT_NE(error_of(c).find("outside"), std::string::npos);
}

TEST(SeismicInput, CflViolationNamesTheLargestStableStep) {
  auto c = small();
  c.dt = 1e-2;
  const auto e = error_of(c);
  const double limit = stable_time_step(10, 2000);
  EXPECT_NE(e.find("largest stable time step"), std::string::npos) << e;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", limit);
  EXPECT_NE(e.find(buf), std::string::npos) << e << " should name " << buf;
  c.dt = 0.99 * limit;
  EXPECT_EQ(error_of(c), "");
}

TEST(SeismicInput, MalformedMediumFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "panoptes_seismic_input_test";
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "vp.npy").string(), shape = (dir / "shape.npy").string(),
                    junk = (dir / "junk.npy").string(), trunc = (dir / "trunc.npy").string();
  const int n = 20;
  write_npy(good, std::vector<float>(n * n * n, 2000.0f), n, n, n);
  write_npy(shape, std::vector<float>(n * n * (n - 1), 2000.0f), n, n, n - 1);
  { std::ofstream(junk) << "not a numpy file"; }
  {
    std::ifstream in(good, std::ios::binary);
    std::string s((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(trunc, std::ios::binary) << s.substr(0, s.size() / 2);
  }
  auto c = small();
  c.medium.kind = MediumSpec::Kind::file;
  c.medium.rho_file = good;
  c.medium.vp_file = good;
  c.medium.vs_file = good;
  EXPECT_NE(error_of(c).find("Vp/sqrt(2)"), std::string::npos);  // vs = vp
  c.medium.vs_file = shape;
  EXPECT_NE(error_of(c).find("does not match the grid"), std::string::npos) << error_of(c);
  c.medium.vs_file = junk;
  EXPECT_NE(error_of(c).find("bad magic"), std::string::npos) << error_of(c);
  c.medium.vs_file = trunc;
  EXPECT_NE(error_of(c).find("truncated"), std::string::npos) << error_of(c);
  c.medium.vs_file = (dir / "missing.npy").string();
  EXPECT_NE(error_of(c).find("cannot open"), std::string::npos) << error_of(c);
  // A valid file medium runs and equals the homogeneous one.
  write_npy((dir / "vs.npy").string(), std::vector<float>(n * n * n, 1000.0f), n, n, n);
  c.medium.vs_file = (dir / "vs.npy").string();
  c.medium.rho_file = (dir / "vp.npy").string();  // ρ = 2000
  EXPECT_EQ(error_of(c), "");
  Solver a(c), b(small());
  a.run(30);
  b.run(30);
  const auto ga = a.gather_seismograms(), gb = b.gather_seismograms();
  ASSERT_EQ(ga.size(), 1u);
  EXPECT_EQ(ga[0].vz, gb[0].vz);
  std::filesystem::remove_all(dir);
}

TEST(SeismicInput, ZenerFitIsConstantQOverTheBand) {
  for (double q : {10.0, 50.0, 200.0}) {
    const auto fit = fit_constant_q(q, 0.5, 50, 3);
    for (double f = 0.5; f <= 50; f *= 1.25) EXPECT_NEAR(fit.q(2 * M_PI * f) / q, 1.0, 0.06) << "f = " << f;
  }
  const auto off = fit_constant_q(std::numeric_limits<double>::infinity(), 0.5, 50, 3);
  for (double y : off.weight) EXPECT_EQ(y, 0.0);
}

TEST(SeismicInput, ElasticRunAllocatesNoMemoryVariables) {
  Solver e(small());
  auto c = small();
  c.medium.layers[0].qp = 100;
  c.medium.layers[0].qs = 50;
  Solver v(c);
  EXPECT_FALSE(e.viscoelastic());
  EXPECT_TRUE(v.viscoelastic());
  EXPECT_GT(v.memory_bytes(), 2 * e.memory_bytes());
}

TEST(SeismicInput, DerivedFieldsOfAKnownVelocityField) {
  // After one step with a body force only vz near the source is non-zero; φp and φs must be finite
  // and the views must describe the local block.
  auto c = small();
  c.sources = {SourceSpec::point_force({100, 100, 100}, {0, 0, 1e9}, SourceTimeFunction::ricker(10, 0))};
  Solver s(c);
  s.run(5);
  s.compute_derived();
  const auto p = s.phi_p(), q = s.phi_s(), vz = s.vz();
  EXPECT_EQ(p.nx, 20);
  EXPECT_EQ(p.nz, s.k_end() - s.k_begin());
  EXPECT_EQ(vz.stagger[2], 0.5);
  double ps = 0, qs = 0;
  for (int k = 0; k < p.nz; ++k)
    for (int j = 0; j < p.ny; ++j)
      for (int i = 0; i < p.nx; ++i) {
        ps += std::abs(p.at(i, j, k));
        qs += std::abs(q.at(i, j, k));
      }
  EXPECT_GT(ps, 0);
  EXPECT_GT(qs, 0);
  // A vertical force: div v is antisymmetric about the source node (z = 100 m = node 10).
  EXPECT_NEAR(p.at(10, 10, 12), -p.at(10, 10, 8), 1e-3 * std::abs(p.at(10, 10, 12)) + 1e-30);
}

namespace {
std::vector<double> run_traces(const SolverConfig& c, int steps, bool dense) {
  if (dense) setenv("PANOPTES_SEISMIC_DENSE_MATERIALS", "1", 1);
  Solver s(c);
  unsetenv("PANOPTES_SEISMIC_DENSE_MATERIALS");
  s.run(steps);
  std::vector<double> all;
  for (const auto& g : s.gather_seismograms())
    for (const auto* v : {&g.vx, &g.vy, &g.vz}) all.insert(all.end(), v->begin(), v->end());
  return all;
}
}  // namespace

TEST(SeismicInput, MaterialStorageDoesNotChangeResults) {
  // The kernels read the material from a per-row constant (layered rows), a table indexed by a
  // per-cell id (rows with several materials) or one array per coefficient (> 65,536 distinct
  // cells, forced here by PANOPTES_SEISMIC_DENSE_MATERIALS): all three must give the same bits.
  const auto dir = std::filesystem::temp_directory_path() / "panoptes_seismic_storage_test";
  std::filesystem::create_directories(dir);
  const int n = 20;
  std::vector<float> vp(n * n * n), vs(n * n * n), rho(n * n * n, 2000.0f);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int q = (i / 3 + 2 * (j / 4) + k / 5) % 4;  // blocks of 4 materials, varying along x
        vp[(k * n + j) * n + i] = 2000.0f + 150.0f * q;
        vs[(k * n + j) * n + i] = 1000.0f + 80.0f * q;
      }
  write_npy((dir / "vp.npy").string(), vp, n, n, n);
  write_npy((dir / "vs.npy").string(), vs, n, n, n);
  write_npy((dir / "rho.npy").string(), rho, n, n, n);
  for (double q : {std::numeric_limits<double>::infinity(), 40.0}) {
    auto c = small();
    c.sources.push_back(SourceSpec::point_force({90, 110, 0}, {1e8, 0, 1e9}, SourceTimeFunction::ricker(10)));
    c.receivers.push_back(ReceiverSpec{"b", {70, 130, 60}});
    c.medium.layers = {Layer{0, 2000, 2000, 1000, q, q}, Layer{55, 2300, 2600, 1400, q, q}};
    EXPECT_EQ(run_traces(c, 40, false), run_traces(c, 40, true)) << "layered, Q = " << q;
    c.medium.kind = MediumSpec::Kind::file;
    c.medium.vp_file = (dir / "vp.npy").string();
    c.medium.vs_file = (dir / "vs.npy").string();
    c.medium.rho_file = (dir / "rho.npy").string();
    c.medium.qp = c.medium.qs = q;
    const auto table = run_traces(c, 40, false);
    EXPECT_EQ(table, run_traces(c, 40, true)) << "blocky file medium, Q = " << q;
    double peak = 0;
    for (double v : table) peak = std::max(peak, std::abs(v));
    EXPECT_GT(peak, 0);
  }
  // Many distinct cells: the solver falls back to one array per coefficient by itself.
  const int m = 42;  // 74,088 cells, each its own velocity
  std::vector<float> hv(m * m * m), hs(m * m * m), hr(m * m * m, 2000.0f);
  for (std::size_t c = 0; c < hv.size(); ++c) {
    hv[c] = 2000.0f + 0.01f * float(c);
    hs[c] = 1000.0f;
  }
  write_npy((dir / "hv.npy").string(), hv, m, m, m);
  write_npy((dir / "hs.npy").string(), hs, m, m, m);
  write_npy((dir / "hr.npy").string(), hr, m, m, m);
  auto c = small();
  c.grid = {m, m, m, 10};
  c.medium.kind = MediumSpec::Kind::file;
  c.medium.vp_file = (dir / "hv.npy").string();
  c.medium.vs_file = (dir / "hs.npy").string();
  c.medium.rho_file = (dir / "hr.npy").string();
  Solver s(c);
  const double cells = double(m + 4) * (m + 4) * (m + 4);
  EXPECT_GT(double(s.memory_bytes()) / cells, 9 * 4 + 8 * 4 - 1);  // fields + 8 coefficient arrays
  s.run(3);
  std::filesystem::remove_all(dir);
}

TEST(SeismicInput, ThreadCountDoesNotChangeResults) {
  // Each OpenMP thread sweeps its own range of rows and the stress rows at the seams follow after a
  // barrier: 1, 2 and 3 threads (ny = 40: two ranges of ≥ 16 rows) must give the same bits.
  auto c = small();
  c.grid = {20, 40, 20, 10};
  c.medium.layers = {Layer{0, 2000, 2000, 1000, 60, 30}, Layer{75, 2300, 2600, 1400, 80, 40}};
  c.sources = {SourceSpec::double_couple({100, 200, 100}, 30, 60, 45, 1e12, SourceTimeFunction::ricker(10))};
  c.receivers = {ReceiverSpec{"a", {120, 190, 0}}, ReceiverSpec{"b", {80, 215, 95}}, ReceiverSpec{"c", {100, 60, 60}}};
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = run_traces(c, 60, false);
  omp_set_num_threads(2);
  const auto two = run_traces(c, 60, false);
  omp_set_num_threads(3);
  const auto three = run_traces(c, 60, false);
  omp_set_num_threads(saved);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, three);
  double peak = 0;
  for (double v : one) peak = std::max(peak, std::abs(v));
  EXPECT_GT(peak, 0);
}
