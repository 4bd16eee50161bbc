#pragma once
// Shared helpers of the seismic tests: whole-space runs compared with the exact solution.
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "seismic/analytic.hpp"
#include "seismic/solver.hpp"

namespace panoptes::seismic::test_util {

/// Uses one OpenMP thread unless OMP_NUM_THREADS is set.
inline bool default_single_thread() {
  if (!std::getenv("OMP_NUM_THREADS")) omp_set_num_threads(1);
  return true;
}

/// Relative L2 misfit sqrt(Σ|num − exact|² / Σ|exact|²) over the three components of one trace.
inline double misfit(const Seismogram& g, const SourceSpec& src, double rho, double vp, double vs) {
  double num = 0, den = 0;
  for (std::size_t t = 0; t < g.time.size(); ++t) {
    const auto e = whole_space_velocity(src, g.position, g.time[t], rho, vp, vs);
    const double n[3] = {g.vx[t], g.vy[t], g.vz[t]};
    for (int c = 0; c < 3; ++c) {
      num += (n[c] - e[c]) * (n[c] - e[c]);
      den += e[c] * e[c];
    }
  }
  return std::sqrt(num / den);
}

}  // namespace panoptes::seismic::test_util
