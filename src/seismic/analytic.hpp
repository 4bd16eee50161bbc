#pragma once
// Exact velocity seismograms in a homogeneous, isotropic, elastic whole space (Aki & Richards 2002,
// eq. 4.23 for a point force and eq. 4.29 / the moment-tensor Green's-function derivative for a
// point moment tensor): near-, intermediate- and far-field terms, with the time function applied
// analytically (S, dS/dt, d²S/dt²) and the near-field time integral done by Simpson's rule.
#include <array>

#include "seismic/config.hpp"

namespace panoptes::seismic {

/// Particle velocity (vx, vy, vz) [m/s] at `receiver` and time t of `source` in a whole space of
/// density rho and velocities alpha (P), beta (S).
std::array<double, 3> whole_space_velocity(const SourceSpec& source, const std::array<double, 3>& receiver,
                                           double t, double rho, double alpha, double beta);

}  // namespace panoptes::seismic
