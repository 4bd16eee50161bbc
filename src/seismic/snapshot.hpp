#pragma once
// What a field snapshot of `panoptes seismic` is (issue 41): the grid its values sit on (each field at
// its own staggered points), its unit, its time, and which way is up (z is depth: the sky is -z). Written
// as the snapshot's sidecar (core/field_sidecar.hpp) beside <field>_<step>.npy, so `panoptes render`
// shows the free surface on top without being told.
#include <array>
#include <string>

#include "core/field_sidecar.hpp"
#include "seismic/config.hpp"

namespace panoptes::seismic {

/// Offset of a field's sample points from the nodes, in cells: vx (1/2, 0, 0), sxz (1/2, 0, 1/2), ...;
/// (0, 0, 0) for sxx, syy, szz, phi_p and phi_s. Throws Error for a name outside Solver::field_names().
std::array<double, 3> field_stagger(const std::string& field);

/// SI unit of a field's values: "m/s" (vx, vy, vz), "Pa" (stresses), "1/s" (phi_p, phi_s).
std::string field_units(const std::string& field);

/// The sidecar of `field` after `step` steps of dt on `grid`: dims (nx, ny, nz), origin = the stagger
/// times h, spacing h, metres, up axis z_down, time in s — the velocity time (step − 1/2)·dt for
/// velocities and the fields derived from them, step·dt for stresses — and `data` = `data_file`.
FieldSidecar snapshot_sidecar(const std::string& field, const GridSpec& grid, int step, double dt,
                              const std::string& data_file);

}  // namespace panoptes::seismic
