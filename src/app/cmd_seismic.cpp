// `panoptes seismic CONFIG.toml`: runs the seismic solver alone (also under mpirun), writes one CSV
// seismogram per receiver, a run report and optional field snapshots (.npy, each with a .json sidecar
// of its grid, units, time and up axis: core/field_sidecar.hpp).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/command.hpp"
#include "app/mpi_scope.hpp"
#include "core/error.hpp"
#include "core/field_sidecar.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/medium.hpp"
#include "seismic/snapshot.hpp"
#include "seismic/solver.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif
#include <omp.h>

namespace cmd_seismic {  // named, not anonymous: the unity build joins the command units

using MpiScope = panoptes::app::MpiScope;

/// Throws on every rank the error that rank 0 met (empty: none), so no rank is left in a collective.
void agree_with_root(std::string err, int rank) {
#ifdef PANOPTES_HAVE_MPI
  int len = int(err.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, MPI_COMM_WORLD);
  err.resize(std::size_t(len));
  MPI_Bcast(err.data(), len, MPI_CHAR, 0, MPI_COMM_WORLD);
#endif
  (void)rank;
  if (!err.empty()) throw panoptes::Error(err);
}

/// Writes the configured snapshot fields after `step` steps (collective; rank 0 writes).
double write_snapshots(panoptes::seismic::Solver& solver, const panoptes::seismic::RunConfig& rc, int step) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& g = rc.solver.grid;
  for (const auto& name : rc.snapshot_fields) {
    const std::vector<float> data = solver.gather_field(name);
    std::string err;
    if (solver.rank() == 0) {
      char stem[64];
      std::snprintf(stem, sizeof stem, "%s_%06d", name.c_str(), step);
      const std::string base = rc.output_dir + "/snapshots/" + stem;
      try {
        panoptes::seismic::write_npy(base + ".npy", data, g.nx, g.ny, g.nz);
        // Its grid, units, time and up axis (z is depth), so `panoptes render` shows it right side up.
        panoptes::write_field_sidecar(base + ".json", panoptes::seismic::snapshot_sidecar(name, g, step, solver.dt(),
                                                                                           std::string(stem) + ".npy"));
      } catch (const std::exception& e) {
        err = e.what();
      }
    }
    agree_with_root(err, solver.rank());
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

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
  const bool snapshots = !rc.snapshot_fields.empty();
  if (snapshots) {
    std::string err;
    if (root) {
      std::error_code ec;
      std::filesystem::create_directories(rc.output_dir + "/snapshots", ec);
      if (ec) err = panoptes::FileError(rc.output_dir + "/snapshots", "cannot create directory: " + ec.message()).what();
    }
    agree_with_root(err, solver.rank());
  }
  const auto t1 = std::chrono::steady_clock::now();
  const int report_every = std::max(1, rc.solver.steps / 10);
  double snapshot_seconds = 0;
  int snapshot_count = 0;
  for (int s = 0; s < rc.solver.steps; ++s) {
    solver.step();
    const int done = s + 1;
    if (snapshots && (rc.snapshot_every > 0 ? done % rc.snapshot_every == 0 : done == rc.solver.steps)) {
      snapshot_seconds += write_snapshots(solver, rc, done);
      ++snapshot_count;
    }
    if (root && !quiet && done % report_every == 0) {
      std::printf("  step %d / %d\n", done, rc.solver.steps);
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
  const double wall = std::chrono::duration<double>(t2 - t1).count() - snapshot_seconds;
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
  if (snapshots) {
    r << "snapshots: " << snapshot_count << " x {";
    for (std::size_t i = 0; i < rc.snapshot_fields.size(); ++i) r << (i ? ", " : "") << rc.snapshot_fields[i];
    r << "} -> " << rc.output_dir << "/snapshots/<field>_<step>.npy + .json sidecar (" << snapshot_seconds
      << " s, not in the wall time above)\n";
  }
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
      "writes one CSV seismogram (time,vx,vy,vz) per receiver, report.txt and optional field snapshots (.npy)");
  auto config = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  sub->add_option("config", *config, "TOML configuration file (keys below)")->required();
  sub->add_option("--out", *output, "Output directory (overrides [output] directory), as --out of every other command");
  sub->add_flag("-q,--quiet", *quiet, "print nothing but errors");
  sub->footer(panoptes::seismic::config_keys_help());
  sub->callback([=] { run(*config, *output, *quiet); });
});

}  // namespace
