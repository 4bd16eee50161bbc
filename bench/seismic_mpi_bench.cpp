// Seismic solver throughput on the paper's FULL grid (256 × 512 × 160 nodes, h = 100 m, layered
// crust, 10-node CPML, free surface, double couple) under MPI: scripts/bench runs it with
// `mpirun -np 1` and `-np 2` (OMP_NUM_THREADS=1). A plain program, not Google Benchmark (which is
// one process): per case it warms up, times `reps` runs of `steps` steps and prints one Markdown
// table row with the medians.
//
//   mpirun -np N seismic_mpi_bench [steps] [reps]     (defaults 4 and 3)
//
// A cell update is one time step of one cell for all its fields (CPML and memory variables
// included). "per core" divides by ranks × wall time (the slowest rank's, after a barrier); "per
// CPU second" divides by the process CPU time summed over the ranks, which is what to compare on a
// shared machine (wall-clock rates there mostly measure the other users).
#include <mpi.h>
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "seismic/solver.hpp"

using namespace panoptes::seismic;

namespace {

SolverConfig paper_grid(bool visco) {
  SolverConfig cfg;
  cfg.grid = {256, 512, 160, 100.0};
  cfg.boundary.pml_cells = 10;
  const double q = visco ? 50.0 : std::numeric_limits<double>::infinity();
  cfg.medium.layers = {Layer{0, 2300, 3000, 1700, q, q}, Layer{1000, 2700, 5500, 3200, q, q},
                       Layer{8000, 3100, 7000, 4000, q, q}};
  cfg.sources = {SourceSpec::double_couple({12800, 25600, 6000}, 30, 60, 90, 1e16, SourceTimeFunction::ricker(1.0))};
  cfg.receivers = {ReceiverSpec{"surface", {14000, 27000, 0}}};
  cfg.steps = 1000;
  return cfg;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Resident set size now, bytes (Linux /proc/self/statm).
double rss_now() {
  std::ifstream in("/proc/self/statm");
  long pages = 0, resident = 0;
  in >> pages >> resident;
  return double(resident) * double(sysconf(_SC_PAGESIZE));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double l = 0;
  in >> l;
  return l;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 4;
  const int reps = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  int rc = 0;
  try {
    if (rank == 0) {
      std::printf("Full paper grid 256 x 512 x 160 (20.97 M cells), %d rank(s) x %d OpenMP thread(s), %d steps per "
                  "repetition, median of %d; load average at start %.1f\n\n",
                  size, omp_get_max_threads(), steps, reps, load_average());
      std::printf("| case | ranks | M cell-updates/s/core (wall) | M cell-updates per CPU second | s/step | "
                  "bytes/cell | RSS/rank after setup MB | peak RSS/rank MB |\n");
      std::printf("|---|---|---|---|---|---|---|---|\n");
      std::fflush(stdout);
    }
    for (const bool visco : {false, true}) {
      const SolverConfig cfg = paper_grid(visco);
      const double cells = double(cfg.grid.nx) * cfg.grid.ny * cfg.grid.nz;
      Solver s(cfg, MPI_COMM_WORLD);
      const double rss_setup = rss_now();
      s.run(2);  // warm-up: first touch of every page, caches
      std::vector<double> wall, cpu;
      for (int r = 0; r < reps; ++r) {
        MPI_Barrier(MPI_COMM_WORLD);
        const double w0 = MPI_Wtime(), c0 = cpu_seconds();
        s.run(steps);
        double c = cpu_seconds() - c0;
        MPI_Barrier(MPI_COMM_WORLD);
        double w = MPI_Wtime() - w0;
        MPI_Allreduce(MPI_IN_PLACE, &c, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        wall.push_back(w);
        cpu.push_back(c);
      }
      double bytes = double(s.memory_bytes());
      MPI_Allreduce(MPI_IN_PLACE, &bytes, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      rusage ru{};
      getrusage(RUSAGE_SELF, &ru);
      double peak = double(ru.ru_maxrss) * 1024.0, setup = rss_setup;
      MPI_Allreduce(MPI_IN_PLACE, &peak, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      MPI_Allreduce(MPI_IN_PLACE, &setup, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      if (rank == 0) {
        const double w = median(wall), c = median(cpu);
        std::printf("| %s | %d | %.1f | %.1f | %.3f | %.1f | %.0f | %.0f |\n",
                    visco ? "viscoelastic (Q = 50, 3 mechanisms)" : "elastic", size, cells * steps / (w * size) * 1e-6,
                    cells * steps / c * 1e-6, w / steps, bytes / cells, setup / 1e6, peak / 1e6);
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seismic_mpi_bench (rank %d): %s\n", rank, e.what());
    rc = 1;
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return rc;
}
