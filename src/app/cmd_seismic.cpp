// `panoptes seismic CONFIG.toml`: runs the seismic solver alone (also under mpirun), writes one CSV
// seismogram per receiver and a run report.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/command.hpp"
#include "app/mpi_scope.hpp"
#include "core/error.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/solver.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif
#include <omp.h>

namespace {

using MpiScope = panoptes::app::MpiScope;

void run(const std::string& config_path, const std::string& output_override, bool quiet) {
  using namespace panoptes::seismic;
  MpiScope mpi;
  RunConfig rc = load_run_config(config_path);
  if (!output_override.empty()) rc.output_dir = output_override;
  const auto t0 = std::chrono::steady_clock::now();
  Solver solver(rc.solver);
  const bool root = solver.rank() == 0;
  const auto& g = rc.solver.grid;
  const double cells = double(g.nx) * g.ny * g.nz;
  if (root && !quiet)
    std::printf("seismic: grid %dx%dx%d, h = %g m, dt = %.6g s, %d steps (%.4g s), %d rank(s) x %d thread(s), %s\n",
                g.nx, g.ny, g.nz, g.h, solver.dt(), rc.solver.steps, rc.solver.steps * solver.dt(), solver.ranks(),
                omp_get_max_threads(), solver.viscoelastic() ? "viscoelastic" : "elastic");
  const auto t1 = std::chrono::steady_clock::now();
  const int report_every = std::max(1, rc.solver.steps / 10);
  for (int s = 0; s < rc.solver.steps; ++s) {
    solver.step();
    if (root && !quiet && (s + 1) % report_every == 0) {
      std::printf("  step %d / %d\n", s + 1, rc.solver.steps);
      std::fflush(stdout);
    }
  }
  const auto t2 = std::chrono::steady_clock::now();
  solver.write_seismograms(rc.output_dir);
  double mem = double(solver.memory_bytes());
#ifdef PANOPTES_HAVE_MPI
  MPI_Allreduce(MPI_IN_PLACE, &mem, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
#endif
  if (!root) return;
  const double setup = std::chrono::duration<double>(t1 - t0).count();
  const double wall = std::chrono::duration<double>(t2 - t1).count();
  const double rate = wall > 0 ? cells * rc.solver.steps / wall : 0;
  std::ostringstream r;
  r << "config: " << config_path << "\n"
    << "grid: " << g.nx << " x " << g.ny << " x " << g.nz << " nodes, h = " << g.h << " m\n"
    << "medium: " << (solver.viscoelastic() ? "viscoelastic" : "elastic") << ", max unrelaxed Vp = " << solver.vp_max()
    << " m/s\n"
    << "dt: " << solver.dt() << " s (stable limit " << stable_time_step(g.h, solver.vp_max()) << " s)\n"
    << "steps: " << rc.solver.steps << " (simulated " << rc.solver.steps * solver.dt() << " s)\n"
    << "ranks: " << solver.ranks() << ", threads per rank: " << omp_get_max_threads() << "\n"
    << "setup time: " << setup << " s\n"
    << "wall time (time loop): " << wall << " s\n"
    << "cell updates per second: " << rate << " (" << rate / 1e6 / (solver.ranks() * omp_get_max_threads())
    << " M per core)\n"
    << "memory (all ranks): " << mem / (1 << 20) << " MiB (" << mem / cells << " bytes per cell)\n"
    << "receivers: " << rc.solver.receivers.size() << " -> " << rc.output_dir << "/<name>.csv\n";
  const std::string report = rc.output_dir + "/report.txt";
  std::filesystem::create_directories(rc.output_dir);
  std::ofstream out(report);
  if (!(out << r.str())) throw panoptes::FileError(report, "cannot write the run report");
  if (!quiet) std::printf("%s", r.str().c_str());
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "seismic",
      "Run the 3-D viscoelastic finite-difference seismic wave solver alone (works under mpirun -np N): "
      "writes one CSV seismogram (time,vx,vy,vz) per receiver and report.txt");
  auto config = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  sub->add_option("config", *config, "TOML configuration file (keys below)")->required();
  sub->add_option("-o,--output", *output, "output directory (overrides [output] directory)");
  sub->add_flag("-q,--quiet", *quiet, "print nothing but errors");
  sub->footer(panoptes::seismic::config_keys_help());
  sub->callback([=] { run(*config, *output, *quiet); });
});

}  // namespace
