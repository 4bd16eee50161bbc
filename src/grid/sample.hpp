#pragma once
// Fields sampled from a function of position on any grid, and the analytic shell field the tests,
// the spherical-shell example and the adapter benchmark use.
#include <functional>
#include <vector>

#include "grid/grid_description.hpp"

namespace panoptes::grid {

/// f at every point of patch `patch`, i fastest (OpenMP-parallel; f must be thread-safe).
std::vector<float> sample(const GridDescription& grid, int patch, const std::function<double(const Vec3&)>& f);
/// f at every point of a uniform grid, x fastest.
std::vector<float> sample(const render::GridGeometry& grid, const std::function<double(const Vec3&)>& f);

/// A dynamo-like field in a spherical shell r_in ≤ r ≤ r_out: a radial profile sin(π·(r − r_in) /
/// (r_out − r_in)) times a few low-degree spherical harmonics (an axial l = 2 part, a drifting
/// l = 2, m = 2 pattern and an l = 3, m = 1 pattern drifting the other way), at time t (one drift
/// period = 2π). Values lie within about [−2, 2]; 0 outside the shell. Written in Cartesian terms,
/// so it is smooth everywhere in the shell, the poles included.
struct ShellField {
  double r_in = 0.35;
  double r_out = 1.0;
  double t = 0;
  double operator()(const Vec3& p) const;
};

}  // namespace panoptes::grid
