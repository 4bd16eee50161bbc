#include "seismic/snapshot.hpp"

#include "core/error.hpp"

namespace panoptes::seismic {

namespace {

bool is_stress(const std::string& f) {
  return f == "sxx" || f == "syy" || f == "szz" || f == "sxy" || f == "sxz" || f == "syz";
}

}  // namespace

std::array<double, 3> field_stagger(const std::string& f) {
  // The staggered grid (docs/seismic.md, Discretization).
  if (f == "vx") return {0.5, 0, 0};
  if (f == "vy") return {0, 0.5, 0};
  if (f == "vz") return {0, 0, 0.5};
  if (f == "sxy") return {0.5, 0.5, 0};
  if (f == "sxz") return {0.5, 0, 0.5};
  if (f == "syz") return {0, 0.5, 0.5};
  if (f == "sxx" || f == "syy" || f == "szz" || f == "phi_p" || f == "phi_s") return {0, 0, 0};
  throw Error("unknown seismic field \"" + f + "\"; expected vx, vy, vz, sxx, syy, szz, sxy, sxz, syz, phi_p or phi_s");
}

std::string field_units(const std::string& f) {
  (void)field_stagger(f);  // refuses unknown names
  if (is_stress(f)) return "Pa";
  if (f == "phi_p" || f == "phi_s") return "1/s";
  return "m/s";
}

FieldSidecar snapshot_sidecar(const std::string& field, const GridSpec& grid, int step, double dt,
                              const std::string& data_file) {
  const std::array<double, 3> stagger = field_stagger(field);
  FieldSidecar s;
  s.data = data_file;
  s.field = field;
  s.field_units = field_units(field);
  s.dims = {grid.nx, grid.ny, grid.nz};
  s.origin = Vec3(stagger[0] * grid.h, stagger[1] * grid.h, stagger[2] * grid.h);
  s.spacing = {grid.h, grid.h, grid.h};
  s.length_units = "m";
  s.up_axis = "z_down";  // x north, y east, z depth: the free surface z = 0 is the top
  // Leapfrog: stresses at n·dt, velocities (and phi_p, phi_s computed from them) at (n − 1/2)·dt.
  s.time = is_stress(field) ? step * dt : (step - 0.5) * dt;
  s.time_units = "s";
  s.step = step;
  return s;
}

}  // namespace panoptes::seismic
