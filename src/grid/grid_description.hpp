#pragma once
// Descriptions of the grids a simulation hands us: uniform boxes, rectilinear (stretched) boxes,
// spherical shells and the Yin-Yang grid, each validated with messages that name the bad value.
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec3.hpp"
#include "render/field_view.hpp"

namespace panoptes::grid {

/// The kinds of grid a field may live on.
enum class GridKind {
  uniform,      ///< origin + spacing (render::GridGeometry): what the renderer marches
  rectilinear,  ///< per-axis monotonic coordinates x[i], y[j], z[k]
  spherical,    ///< a spherical shell (or sector): radius r[i], colatitude θ[j], longitude φ[k]
  yinyang,      ///< two congruent low-latitude lat-lon patches (Yin, Yang) covering a spherical shell
};
/// "uniform" / "rectilinear" / "spherical" / "yinyang".
std::string_view to_string(GridKind kind);
/// Parses a to_string() name; throws panoptes::Error listing the valid names otherwise.
GridKind parse_grid_kind(std::string_view text);

/// A grid in its own index space: points (i, j, k), i fastest in memory (a C array [n2][n1][n0]).
/// Rectilinear: point (i, j, k) is (x[i], y[j], z[k]). Spherical and Yin-Yang: point (i, j, k) has
/// radius r[i], colatitude θ[j] ∈ [0, π] from +z and longitude φ[k] (radians, from +x towards +y),
/// i.e. (r sinθ cosφ, r sinθ sinφ, r cosθ) in the patch's frame. Yin-Yang has two patches with the
/// same coordinates: Yin's frame is the world's; Yang's is Yin's rotated by (x, y, z) → (−x, z, y)
/// (an involution: the same map takes world points to Yang's frame). A spherical grid whose φ
/// coordinates close the circle (the gap φ[0] + 2π − φ[last] is no larger than 1.5 neighbour
/// spacings) is periodic in φ; one whose θ reaches to within 1.5 spacings of a pole covers the cap
/// around that pole with the value of its nearest ring.
struct GridDescription {
  GridKind kind = GridKind::uniform;
  render::GridGeometry uniform;               ///< kind == uniform only
  std::array<std::vector<double>, 3> coords;  ///< rectilinear: x, y, z; spherical, yinyang: r, θ, φ

  static GridDescription make_uniform(const render::GridGeometry& g);
  static GridDescription rectilinear(std::vector<double> x, std::vector<double> y, std::vector<double> z);
  static GridDescription spherical(std::vector<double> r, std::vector<double> theta, std::vector<double> phi);
  static GridDescription yinyang(std::vector<double> r, std::vector<double> theta, std::vector<double> phi);
  /// The one door from a kind and three coordinate arrays (the C API, Python and `render --grid` all
  /// come through here; a new kind is one case in this switch, and the compiler names a missing one).
  /// Throws panoptes::Error for `uniform`, which has an origin and spacing, not coordinates.
  static GridDescription of_kind(GridKind kind, std::vector<double> a, std::vector<double> b, std::vector<double> c);
  /// The usual Yin-Yang patch: `n_theta` colatitudes over [π/4 − m, 3π/4 + m] and `n_phi`
  /// longitudes over [−3π/4 − m', 3π/4 + m'], where the margins m, m' are `margin_cells` of the
  /// patch's own spacing (an overlap beyond the minimal covering, as codes use for interpolation).
  static GridDescription yinyang_standard(std::vector<double> r, int n_theta, int n_phi, double margin_cells = 2);

  /// Points per axis.
  render::Index3 dims() const;
  /// 2 for Yin-Yang, 1 otherwise.
  int patches() const { return kind == GridKind::yinyang ? 2 : 1; }
  /// Points of one patch.
  std::int64_t points_per_patch() const;
  /// Throws panoptes::Error unless the description is usable: at least 2 points per axis, finite
  /// strictly increasing coordinates, radii ≥ 0, colatitudes in [0, π], longitudes spanning at most
  /// 2π, at most 65535 points per axis; Yin-Yang patches that cover θ ∈ [π/4, 3π/4] and
  /// φ ∈ [−3π/4, 3π/4] within (0, π) × (−π, π) (otherwise the two patches leave a gap or a patch is
  /// not a low-latitude one).
  void validate() const;
  /// Whether φ wraps around (spherical and Yin-Yang only; see the type's comment).
  bool phi_periodic() const;
  /// The colatitudes the grid covers (spherical, Yin-Yang): [θ[0], θ[last]], widened to a pole
  /// when the grid stops within 1.5 spacings of it (the cap takes its nearest ring's values).
  std::array<double, 2> theta_cover() const;
  /// The world box holding every point of the domain (for shells: of the sphere sectors between
  /// the grid's coordinate lines, not just the grid points).
  Vec3 bounds_lo() const;
  Vec3 bounds_hi() const;
  /// The world position of point (i, j, k) of patch `patch`.
  Vec3 point(int patch, int i, int j, int k) const;
  /// A one-line summary ("spherical 32x64x128, r in [0.35, 1]").
  std::string summary() const;
};

/// The uniform grid over the description's bounding box whose longest axis has `longest_axis_points`
/// points and whose spacing is the same on every axis (≥ 2 points per axis). What the adapter
/// resamples a non-uniform grid onto.
render::GridGeometry uniform_cover(const GridDescription& grid, int longest_axis_points);

/// Yang's frame from the world's and back (the same map): (x, y, z) → (−x, z, y).
constexpr Vec3 yinyang_swap(const Vec3& p) { return {-p.x, p.z, p.y}; }

}  // namespace panoptes::grid
