#pragma once
// The viscoelastic finite-difference solver: velocity–stress staggered grid (Virieux 1986,
// Levander 1988), 4th order in space, 2nd order (leapfrog) in time, CPML on absorbing faces, free
// surface by stress imaging, generalized Zener body attenuation, MPI slabs along z.
//
// Staggering (offsets in cells from node (i, j, k)):
//   σxx, σyy, σzz: (0, 0, 0)      vx: (½, 0, 0)   vy: (0, ½, 0)   vz: (0, 0, ½)
//   σxy: (½, ½, 0)  σxz: (½, 0, ½)  σyz: (0, ½, ½)
// Time: σ at t = n·dt, v at t = (n + ½)·dt. After step() number n (counting from 0), v holds
// t = (n + ½)·dt and σ holds t = (n + 1)·dt.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "seismic/config.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::seismic {

/// A read-only view of one float field on this rank's block (no halos). Element (i, j, k) of the
/// block is data[i + j·stride_y + k·stride_z]; its global node index is (i, j, k + k_offset) and its
/// position is ((i + stagger[0])·h, (j + stagger[1])·h, (k + k_offset + stagger[2])·h) metres.
struct FieldView {
  const float* data = nullptr;
  int nx = 0, ny = 0, nz = 0;          ///< local extents
  std::ptrdiff_t stride_y = 0, stride_z = 0;
  int k_offset = 0;                    ///< global z index of local k = 0
  std::array<int, 3> global_dims{0, 0, 0};
  std::array<double, 3> stagger{0, 0, 0};
  double h = 0;
  float at(int i, int j, int k) const { return data[i + j * stride_y + k * stride_z]; }
};

/// A three-component velocity seismogram at one receiver.
struct Seismogram {
  std::string name;
  std::array<double, 3> position{0, 0, 0};
  std::vector<double> time, vx, vy, vz;
};

/// Largest stable time step of the 4th-order staggered scheme in 3-D: h / (√3·(9/8 + 1/24)·vmax).
double stable_time_step(double h, double vp_max);

/// The solver for one run. Construction validates everything (configuration, medium, CFL) and
/// throws panoptes::Error before any step is taken. Collective over the communicator.
class Solver {
 public:
  /// Single process, or MPI_COMM_WORLD when built with MPI and MPI is initialized.
  explicit Solver(const SolverConfig& config);
#ifdef PANOPTES_HAVE_MPI
  /// Runs on `comm` (slabs along z in rank order).
  Solver(const SolverConfig& config, MPI_Comm comm);
#endif
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  /// Advances one time step (collective).
  void step();
  /// Advances n steps.
  void run(int n);

  int steps_done() const;
  double dt() const;
  /// Time of the velocity fields after the last step: (steps_done − ½)·dt.
  double velocity_time() const;
  const SolverConfig& config() const;

  int rank() const;
  int ranks() const;
  /// This rank's global z planes [k_begin, k_end).
  int k_begin() const;
  int k_end() const;

  /// Views of vx, vy, vz on this rank's block (valid until the next step()).
  FieldView vx() const;
  FieldView vy() const;
  FieldView vz() const;
  /// Computes φp = ∇·v and φs = |∇×v| at the nodes of this rank's block (4th-order differences;
  /// curl components averaged from their edges to the node). On the two planes under a free surface
  /// it uses the stress update's surface strains and σxz = σyz = 0, reading no velocity above the
  /// surface (docs/seismic.md). Uses the velocity halos of the last step, so no communication. Units: 1/s.
  void compute_derived();
  FieldView phi_p() const;  ///< valid after compute_derived()
  FieldView phi_s() const;  ///< valid after compute_derived()

  /// Names of the fields gather_field() knows: vx, vy, vz, sxx, syy, szz, sxy, sxz, syz, phi_p, phi_s.
  static const std::vector<std::string>& field_names();
  /// One field on the whole global grid, nz × ny × nx floats with x fastest (index
  /// i + nx·(j + ny·k)), complete on rank 0 and empty on the other ranks (collective). Each field
  /// is sampled at its own staggered points (element (i, j, k) of vx is at ((i + ½)h, jh, kh)).
  /// phi_p / phi_s are computed from the current velocities (compute_derived()). Throws
  /// panoptes::Error for an unknown name (on every rank).
  std::vector<float> gather_field(const std::string& name);

  /// Total mechanical energy (kinetic + strain) [J] inside the non-absorbing region (collective).
  double energy() const;
  /// Seismograms of all receivers, complete on rank 0 (collective; other ranks get an empty list).
  std::vector<Seismogram> gather_seismograms() const;
  /// Writes <dir>/<receiver>.csv (time,vx,vy,vz) on rank 0 (collective).
  void write_seismograms(const std::string& dir) const;
  /// Bytes of field, material, CPML and memory-variable arrays on this rank.
  std::size_t memory_bytes() const;
  /// True when memory variables (attenuation) are in use.
  bool viscoelastic() const;
  /// Largest unrelaxed P velocity in the model (sets the CFL limit).
  double vp_max() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace panoptes::seismic
