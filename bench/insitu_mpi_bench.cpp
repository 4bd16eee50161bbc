// In-situ benchmark under MPI (run by scripts/bench with mpirun -np 1 and -np 2): the same workload
// as insitu_bench (the seismic solver driven with in-situ visualization like `panoptes run`, see
// bench/insitu_bench.hpp) on all ranks of MPI_COMM_WORLD, so the per-snapshot split shows what the
// ranks share (simulation and rendering of slabs) and what they add (compositing: partial images
// sent to each camera's owner). Prints one table row per setting; times are the slowest rank's.
#include <mpi.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <string>

#include "bench/insitu_bench.hpp"

using namespace panoptes;

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int rc = 0;
  try {
    struct Named {
      const char* name;
      bench::InsituSetting setting;
    };
    const Named settings[] = {
        {"demo", {"examples/demo.toml", "", 150, 3}},
        {"paper_quarter", {"examples/paper_quarter.toml", "yinyang:2x2", 200, 2}},
    };
    int pid = ::getpid();
    MPI_Bcast(&pid, 1, MPI_INT, 0, MPI_COMM_WORLD);
    const std::string out = (std::filesystem::temp_directory_path() / ("insitu_mpi_bench_" + std::to_string(pid))).string();
    if (rank == 0) {
      std::printf("| setting | ranks | threads/rank | streams | streams/rank | simulation s | copy s | render s | composite s | "
                  "encode s | checkpoint s | snapshot s | vis/sim | camera-frames/core-s | db/raw %% | RSS/rank MB | MB/open stream |\n");
      std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
      std::fflush(stdout);
    }
    for (const Named& n : settings) {
      bench::InsituSetting s = n.setting;
      s.config = std::string(PANOPTES_SOURCE_DIR) + "/" + s.config;
      const bench::InsituResult r = bench::run_insitu_setting(s, out, true);
      if (rank == 0) {
        int threads = 1;
#ifdef _OPENMP
        threads = omp_get_max_threads();
#endif
        std::printf("| %s | %d | %d | %d | %d | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.1f | %.1f | %.0f | %.2f |\n",
                    n.name, r.ranks, threads, r.streams, r.owned_streams_max, r.simulation_s, r.copy_s, r.render_s,
                    r.composite_s, r.encode_s, r.checkpoint_s, r.wall_s,
                    r.simulation_s > 0 ? (r.wall_s - r.simulation_s) / r.simulation_s : 0.0, r.frames_per_core_s(),
                    100 * r.db_bytes / r.raw_bytes, r.rss_bytes_max / 1e6, r.stream_bytes_max / 1e6);
        std::fflush(stdout);
        std::filesystem::remove_all(out);
      }
      MPI_Barrier(MPI_COMM_WORLD);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "insitu_mpi_bench (rank %d): %s\n", rank, e.what());
    rc = 1;
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return rc;
}
