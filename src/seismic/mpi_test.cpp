// Rank independence: the same run on MPI_COMM_SELF (one rank) and on MPI_COMM_WORLD (z slabs)
// must give seismograms that agree to 1e-6 relative (bitwise: each plane's arithmetic is the same).
// Layered viscoelastic medium, free surface, double couple, receivers straddling slab boundaries;
// also the gathered phi_p, phi_s (bitwise).
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "seismic/solver.hpp"

using namespace panoptes::seismic;

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  SolverConfig cfg;
  const double h = 20;
  cfg.grid = {28, 26, 30, h};
  cfg.boundary.pml_cells = 6;
  cfg.medium.layers = {Layer{0, 2000, 1800, 1000, 60, 30}, Layer{200, 2500, 3000, 1700, 100, 50}};
  cfg.sources = {SourceSpec::double_couple({270, 250, 150}, 30, 60, 45, 1e15, SourceTimeFunction::ricker(8.0)),
                 SourceSpec::point_force({200, 300, 0}, {0, 0, 1e7}, SourceTimeFunction::kupper(0.1))};
  int r = 0;
  for (double z : {0.0, 95.0, 150.0, 199.0, 270.0, 330.0})
    for (double x : {130.0, 290.0, 410.0}) cfg.receivers.push_back(ReceiverSpec{"r" + std::to_string(r++), {x, 240, z}});
  cfg.steps = 150;
  std::vector<Seismogram> ref;
  std::vector<float> ref_pp, ref_ps;
  if (rank == 0) {
    Solver serial(cfg, MPI_COMM_SELF);
    serial.run(cfg.steps);
    ref = serial.gather_seismograms();
    ref_pp = serial.gather_field("phi_p");
    ref_ps = serial.gather_field("phi_s");
  }
  Solver par(cfg, MPI_COMM_WORLD);
  par.run(cfg.steps);
  const auto got = par.gather_seismograms();
  // φp, φs: only the rank owning the free-surface planes 0 and 1 evaluates them with the surface strains.
  const auto got_pp = par.gather_field("phi_p"), got_ps = par.gather_field("phi_s");
  int fail = 0;
  if (rank == 0) {
    const bool same = ref_pp == got_pp && ref_ps == got_ps && !ref_pp.empty();
    std::printf("[mpi] %d ranks vs 1: phi_p, phi_s bitwise identical: %s\n", size, same ? "yes" : "no");
    if (!same) fail = 1;
  }
  if (rank == 0) {
    double worst = 0, peak = 0;
    bool bitwise = true;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      const std::vector<double>* a[3] = {&ref[i].vx, &ref[i].vy, &ref[i].vz};
      const std::vector<double>* b[3] = {&got[i].vx, &got[i].vy, &got[i].vz};
      for (int c = 0; c < 3; ++c) {
        double m = 0, d = 0;
        for (std::size_t t = 0; t < a[c]->size(); ++t) {
          m = std::max(m, std::abs((*a[c])[t]));
          d = std::max(d, std::abs((*a[c])[t] - (*b[c])[t]));
          if ((*a[c])[t] != (*b[c])[t]) bitwise = false;
        }
        peak = std::max(peak, m);
        if (m > 0) worst = std::max(worst, d / m);
      }
    }
    std::printf("[mpi] %d ranks vs 1: worst relative difference %.3e (bitwise identical: %s), peak |v| %.3e\n", size,
                worst, bitwise ? "yes" : "no", peak);
    if (!(worst <= 1e-6) || !(peak > 0)) fail = 1;
  }
  MPI_Bcast(&fail, 1, MPI_INT, 0, MPI_COMM_WORLD);
  // Errors are collective: a bad receiver is reported on every rank, before any step.
  SolverConfig bad = cfg;
  bad.receivers.push_back(ReceiverSpec{"outside", {1e6, 0, 0}});
  try {
    Solver s(bad, MPI_COMM_WORLD);
    fail = 1;
  } catch (const panoptes::Error& e) {
    if (rank == 0) std::printf("[mpi] expected error: %s\n", e.what());
  }
  MPI_Finalize();
  return fail;
}
