#pragma once
// Everything that defines a seismic run: grid, medium, boundaries, attenuation band, sources,
// receivers, time stepping. Plain data; SolverConfig::validate() and the Solver constructor check it.
//
// Coordinates (docs/seismic.md): right-handed x = north, y = east, z = depth, positive DOWN
// (Aki & Richards' convention). Grid node (i, j, k) sits at (i·h, j·h, k·h) [m]; the free surface,
// when enabled, is the plane z = 0. SI units throughout: m, s, kg/m³, m/s, Pa, N, N·m.
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "seismic/stf.hpp"

namespace panoptes::seismic {

/// Largest grid accepted per axis and per x-y plane (the solver indexes a plane with int).
inline constexpr int kMaxAxisNodes = 1 << 20;
inline constexpr long long kMaxPlaneNodes = (1LL << 31) - 1;

/// A uniform grid of nx × ny × nz nodes with spacing h, INCLUDING the absorbing layers.
struct GridSpec {
  int nx = 0, ny = 0, nz = 0;
  double h = 0;  ///< grid spacing [m]
};

/// One horizontal layer of a layered medium; it extends from `top` down to the next layer's top.
struct Layer {
  double top = 0;  ///< depth of the layer's top [m]
  double rho = 0, vp = 0, vs = 0;  ///< density [kg/m³], P and S velocities [m/s] at the reference frequency
  double qp = std::numeric_limits<double>::infinity();  ///< P quality factor (∞: elastic)
  double qs = std::numeric_limits<double>::infinity();  ///< S quality factor (∞: elastic)
};

/// The medium: homogeneous (one layer), layered (layers sorted by top, first top = 0), or files.
struct MediumSpec {
  enum class Kind { layered, file };
  Kind kind = Kind::layered;
  std::vector<Layer> layers;  ///< kind == layered (a homogeneous medium is one layer with top 0)
  /// kind == file: .npy float32 arrays of shape (nz, ny, nx) (x fastest), C order, little endian.
  std::string rho_file, vp_file, vs_file;
  std::string qp_file, qs_file;  ///< optional; if empty, qp / qs below apply everywhere
  double qp = std::numeric_limits<double>::infinity();
  double qs = std::numeric_limits<double>::infinity();

  /// A homogeneous medium.
  static MediumSpec homogeneous(double rho, double vp, double vs,
                                double qp = std::numeric_limits<double>::infinity(),
                                double qs = std::numeric_limits<double>::infinity());
};

/// Which boundary conditions the faces get. x/y faces and the bottom are always absorbing.
struct BoundarySpec {
  bool free_surface = true;  ///< top (z = 0): free surface, or absorbing when false (whole space)
  int pml_cells = 10;        ///< CPML thickness in nodes on every absorbing face
  double pml_reflection = 1e-4;  ///< target reflection coefficient R of the CPML damping profile
  double pml_frequency = 0;  ///< CFS-PML α_max = π·f; 0 → the dominant source frequency
};

/// Constant-Q band of the generalized Zener body (used only when some Q is finite).
struct AttenuationSpec {
  double fmin = 0, fmax = 0;  ///< band [Hz]; 0 → [f_dom/10, 10·f_dom]
  double fref = 0;            ///< frequency at which vp, vs are the phase velocities; 0 → f_dom
  int mechanisms = 3;         ///< relaxation mechanisms (≥ 3)
};

/// A point source at an arbitrary position.
struct SourceSpec {
  enum class Kind { moment, force };
  Kind kind = Kind::moment;
  std::array<double, 3> position{0, 0, 0};  ///< [m]
  /// Moment tensor [N·m]: Mxx, Myy, Mzz, Mxy, Mxz, Myz (kind == moment). M(t) = M·S(t).
  std::array<double, 6> moment{0, 0, 0, 0, 0, 0};
  /// Force [N]: Fx, Fy, Fz (kind == force). F(t) = F·S(t).
  std::array<double, 3> force{0, 0, 0};
  SourceTimeFunction stf;

  /// An explosion (isotropic) of scalar moment M0.
  static SourceSpec explosion(std::array<double, 3> pos, double m0, SourceTimeFunction stf);
  /// A double couple from strike, dip, rake [degrees] and M0 (Aki & Richards box 4.4, x = north,
  /// y = east, z = down).
  static SourceSpec double_couple(std::array<double, 3> pos, double strike, double dip, double rake,
                                  double m0, SourceTimeFunction stf);
  /// A point force.
  static SourceSpec point_force(std::array<double, 3> pos, std::array<double, 3> f, SourceTimeFunction stf);
};

/// A three-component velocity receiver.
struct ReceiverSpec {
  std::string name;
  std::array<double, 3> position{0, 0, 0};  ///< [m]
};

/// A complete run.
struct SolverConfig {
  GridSpec grid;
  MediumSpec medium;
  BoundarySpec boundary;
  AttenuationSpec attenuation;
  std::vector<SourceSpec> sources;
  std::vector<ReceiverSpec> receivers;
  double dt = 0;          ///< time step [s]; 0 → courant × the largest stable step
  double courant = 0.9;   ///< fraction of the stability limit used when dt == 0
  int steps = 0;          ///< number of time steps of a run
  int record_every = 1;   ///< receivers sample every n-th step

  /// Checks everything that does not need the medium values (grid, sources and receivers inside
  /// the non-absorbing part, parameters in range). Throws panoptes::Error naming the bad value.
  void validate() const;
  /// The dominant source frequency (largest Ricker f0, or 1/T): used for CPML and Q band defaults.
  double dominant_frequency() const;
};

}  // namespace panoptes::seismic
