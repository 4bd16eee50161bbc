#pragma once
// Material properties sampled on the grid nodes of a range of z planes (one rank's slab plus the
// planes its material averages need), with the physical checks every seismologist expects.
#include <string>
#include <vector>

#include "seismic/config.hpp"

namespace panoptes::seismic {

/// ρ, Vp, Vs, Qp, Qs on nodes (i, j, k) for k in [k0, k0 + nk), all i, j; x fastest.
struct MediumBlock {
  int nx = 0, ny = 0, k0 = 0, nk = 0;
  std::vector<float> rho, vp, vs, qp, qs;
  std::size_t index(int i, int j, int k) const {
    return std::size_t(i) + std::size_t(nx) * (std::size_t(j) + std::size_t(ny) * std::size_t(k - k0));
  }
  /// True when some Qp or Qs is finite (the solver then allocates memory variables).
  bool attenuating() const;
};

/// Samples the medium on planes [k_begin, k_end) of the grid. Throws panoptes::Error (FileError for
/// files) naming the node and value for a non-positive ρ/Vp/Vs, Vs > Vp/√2, a non-positive Q, a
/// malformed or mis-shaped .npy file, or an invalid layer list.
MediumBlock sample_medium(const MediumSpec& spec, const GridSpec& grid, int k_begin, int k_end);

/// Reads planes [k_begin, k_end) of a float32 .npy array of shape (nz, ny, nx) and checks the
/// shape. Throws FileError when the file is missing, not .npy v1/v2/v3, not '<f4', Fortran-ordered
/// or of another shape.
std::vector<float> read_npy_planes(const std::string& path, int nx, int ny, int nz, int k_begin, int k_end);

/// Writes a float32 .npy array of shape (nz, ny, nx) (used by tests and tools).
void write_npy(const std::string& path, const std::vector<float>& data, int nx, int ny, int nz);

}  // namespace panoptes::seismic
