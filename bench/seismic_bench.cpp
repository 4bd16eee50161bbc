// Seismic solver throughput: million cell-updates per second (one cell update = one time step of
// one cell for all its fields, CPML and memory variables included) on a 256×512×32 slab of the
// paper's 256×512×160 grid, one process, 1 or 2 OpenMP threads. The full grid under MPI (1 and 2
// ranks) is bench/seismic_mpi_bench.cpp.
//   BM_Run   the solver exactly as `panoptes run` sets it up from examples/paper.toml (256x512x160,
//            elastic, 16-node CPML) and examples/demo.toml (64x128x40), 1 or 2 OpenMP threads: CPU and
//            wall seconds per step and of one compute_derived() (phi_p, phi_s: once per snapshot), and
//            the CPU seconds of one snapshot's simulation (every_steps steps + one compute_derived).
#include <benchmark/benchmark.h>
#include <omp.h>
#include <time.h>

#include <ctime>
#include <fstream>
#include <sstream>

#include "insitu/config.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/solver.hpp"

using namespace panoptes::seismic;

namespace {

SolverConfig paper_slab(bool visco) {
  SolverConfig cfg;
  cfg.grid = {256, 512, 32, 100.0};
  cfg.boundary.pml_cells = 10;
  const double q = visco ? 50.0 : std::numeric_limits<double>::infinity();
  cfg.medium.layers = {Layer{0, 2300, 3000, 1700, q, q}, Layer{1000, 2700, 5500, 3200, q, q}};
  cfg.sources = {SourceSpec::double_couple({12800, 25600, 1500}, 30, 60, 90, 1e16, SourceTimeFunction::ricker(1.0))};
  cfg.steps = 4;
  return cfg;
}

void BM_Step(benchmark::State& state) {
  const bool visco = state.range(0) != 0;
  const int threads = int(state.range(1));
  omp_set_num_threads(threads);
  Solver s(paper_slab(visco));
  s.step();  // first touch
  const double cells = 256.0 * 512 * 32;
  // Process CPU time (all threads): on a shared, oversubscribed machine wall-clock rates measure
  // the other users; cell updates per CPU second is the per-core throughput of the kernels.
  const std::clock_t c0 = std::clock();
  for (auto _ : state) s.step();
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  state.counters["Mcell_updates_per_cpu_s"] = cells * 1e-6 * double(state.iterations()) / cpu;
  state.counters["Mcell_updates_per_s"] =
      benchmark::Counter(cells * 1e-6 * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["Mcell_updates_per_s_per_core"] =
      benchmark::Counter(cells * 1e-6 * double(state.iterations()) / threads, benchmark::Counter::kIsRate);
  state.counters["bytes_per_cell"] = double(s.memory_bytes()) / cells;
  state.SetLabel(std::string(visco ? "viscoelastic (3 mechanisms)" : "elastic") + ", " + std::to_string(threads) +
                 " OpenMP thread(s), 256x512x32 slab of the paper grid");
}

double cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Arg 0: 0 = examples/paper.toml, 1 = examples/demo.toml; arg 1: OpenMP threads; arg 2 (optional):
// steps run before the timed ones (default 2). From the start the fields are zero and every step is
// cheap; at step 200 of the paper's run the front has spread over half the grid and the values ahead of
// it shrink through the subnormal range (seismic/denormals.hpp): the hard case of the run's first third.
void BM_Run(benchmark::State& state) {
  const char* name = state.range(0) == 0 ? "paper" : "demo";
  const std::string path = std::string(PANOPTES_SOURCE_DIR) + "/examples/" + name + ".toml";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string seis_text;
  const auto session = panoptes::insitu::parse_combined_config(
      text.str(), path, {"grid", "time", "medium", "boundary", "attenuation", "source", "receiver", "receiver_line"},
      seis_text);
  const RunConfig rc = parse_run_config(seis_text, path, std::string(PANOPTES_SOURCE_DIR) + "/examples");
  const int threads = int(state.range(1));
  omp_set_num_threads(threads);
  Solver s(rc.solver);
  s.run(state.range(2) > 0 ? int(state.range(2)) : 2);  // first touch of the arrays (and the wavefield's start)
  s.compute_derived();  // and of phi_p, phi_s (allocated by the first call)
  const int steps = state.range(0) == 0 ? 4 : 40;
  double step_cpu = 0, step_wall = 0, der_cpu = 0, der_wall = 0;
  for (auto _ : state) {
    const double c0 = cpu_seconds(), w0 = omp_get_wtime();
    s.run(steps);
    const double c1 = cpu_seconds(), w1 = omp_get_wtime();
    s.compute_derived();
    step_cpu += c1 - c0;
    step_wall += w1 - w0;
    der_cpu += cpu_seconds() - c1;
    der_wall += omp_get_wtime() - w1;
  }
  const double it = double(state.iterations());
  const double cells = double(rc.solver.grid.nx) * rc.solver.grid.ny * rc.solver.grid.nz;
  state.counters["cpu_s_per_step"] = step_cpu / it / steps;
  state.counters["wall_s_per_step"] = step_wall / it / steps;
  state.counters["derived_cpu_s"] = der_cpu / it;
  state.counters["derived_wall_s"] = der_wall / it;
  state.counters["Mcell_updates_per_cpu_s"] = cells * 1e-6 * steps * it / step_cpu;
  const int every = session.schedule.every_steps;
  state.counters["sim_cpu_s_per_snapshot"] = every * step_cpu / it / steps + der_cpu / it;
  state.counters["sim_wall_s_per_snapshot"] = every * step_wall / it / steps + der_wall / it;
  state.SetLabel(std::string(name) + ".toml, " + std::to_string(threads) + " OpenMP thread(s), timed from step " +
                 std::to_string(s.steps_done() - int(it) * steps));
}

}  // namespace

BENCHMARK(BM_Run)->Args({0, 2, 0})->Args({0, 1, 0})->Args({1, 2, 0})->Args({1, 1, 0})->Args({0, 2, 200})->Iterations(3)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_Step)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_MAIN();
