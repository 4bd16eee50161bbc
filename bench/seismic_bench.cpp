// Seismic solver throughput: million cell-updates per second (one cell update = one time step of
// one cell for all its fields, CPML and memory variables included) on a 256×512×32 slab of the
// paper's 256×512×160 grid, one process, 1 or 2 OpenMP threads. The full grid under MPI (1 and 2
// ranks) is bench/seismic_mpi_bench.cpp.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <ctime>

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

}  // namespace

BENCHMARK(BM_Step)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_MAIN();
