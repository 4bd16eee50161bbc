#pragma once
// `panoptes render`'s use of field sidecars (issue 41; core/field_sidecar.hpp): the volumes of a series
// are described by all their sidecars or by none, and the sidecars of one series agree on the grid,
// the units, the up axis and the field. Header-only (app compiles cmd_*.cpp only).
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "app/volume_file.hpp"
#include "core/error.hpp"
#include "core/field_sidecar.hpp"
#include "core/number_text.hpp"

namespace panoptes::app {

/// The sidecars of a series of volume files (empty `sidecars` when the volumes have none).
struct SeriesSidecars {
  std::vector<FieldSidecar> sidecars;  ///< one per file, in order; empty = no sidecars
  std::vector<std::string> paths;      ///< the sidecars' paths
  bool present() const { return !sidecars.empty(); }
  const FieldSidecar& first() const { return sidecars.front(); }
  /// Snapshot times from the sidecars when every one records its time, else nullopt.
  std::optional<std::vector<double>> times() const {
    std::vector<double> t;
    for (const auto& s : sidecars) {
      if (!s.time) return std::nullopt;
      t.push_back(*s.time);
    }
    return t;
  }
};

namespace series_detail {

inline bool is_npy(const std::string& path) {
  return path.size() >= 4 && volume_detail::lower(path.substr(path.size() - 4)) == ".npy";
}

inline std::string vec_text(const Vec3& v) {
  return "[" + number_text(v.x) + ", " + number_text(v.y) + ", " + number_text(v.z) + "]";
}

inline bool same(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)); }
inline bool same(const Vec3& a, const Vec3& b) { return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z); }

}  // namespace series_detail

/// Finds and checks the sidecars of `files` (only .npy files have them). Throws FileError naming the
/// sidecar and the key when one is malformed, when some volumes have one and others not, when two
/// disagree on dims, origin, spacing, units, up axis or field, or when their times go backwards.
inline SeriesSidecars read_series_sidecars(const std::vector<std::string>& files) {
  using namespace series_detail;
  SeriesSidecars out;
  std::string without;  // the first volume without a sidecar
  for (const std::string& f : files) {
    std::optional<FieldSidecar> s = is_npy(f) ? find_field_sidecar(f) : std::nullopt;
    if (!s) {
      if (without.empty()) without = f;
      continue;
    }
    out.sidecars.push_back(std::move(*s));
    out.paths.push_back(field_sidecar_path(f));
  }
  if (out.sidecars.empty()) return out;
  if (!without.empty())
    throw FileError(without, "has no sidecar (" + field_sidecar_path(without) + "), but " + out.paths.front() +
                                 " describes its volume; a series is described by the sidecars of all its volumes or of none");
  const FieldSidecar& a = out.sidecars.front();
  for (std::size_t i = 1; i < out.sidecars.size(); ++i) {
    const FieldSidecar& b = out.sidecars[i];
    auto differ = [&](const std::string& key, const std::string& va, const std::string& vb) {
      throw FileError(out.paths[i], key + ": " + vb + ", but " + out.paths.front() + " has " + va +
                                        "; the volumes of one series must share it");
    };
    if (b.dims != a.dims)
      differ("dims", "[" + std::to_string(a.dims[0]) + ", " + std::to_string(a.dims[1]) + ", " + std::to_string(a.dims[2]) + "]",
             "[" + std::to_string(b.dims[0]) + ", " + std::to_string(b.dims[1]) + ", " + std::to_string(b.dims[2]) + "]");
    if (a.origin.has_value() != b.origin.has_value() || (a.origin && !same(*a.origin, *b.origin)))
      differ("origin", a.origin ? vec_text(*a.origin) : "none", b.origin ? vec_text(*b.origin) : "none");
    if (!same(a.spacing, b.spacing)) differ("spacing", vec_text(a.spacing), vec_text(b.spacing));
    if (a.up_axis != b.up_axis) differ("up_axis", "\"" + a.up_axis + "\"", "\"" + b.up_axis + "\"");
    if (a.length_units != b.length_units) differ("length_units", "\"" + a.length_units + "\"", "\"" + b.length_units + "\"");
    if (a.field != b.field) differ("field", "\"" + a.field + "\"", "\"" + b.field + "\"");
    if (a.field_units != b.field_units) differ("field_units", "\"" + a.field_units + "\"", "\"" + b.field_units + "\"");
    if (a.time_units != b.time_units) differ("time_units", "\"" + a.time_units + "\"", "\"" + b.time_units + "\"");
    const FieldSidecar& prev = out.sidecars[i - 1];
    if (prev.time && b.time && *b.time < *prev.time)
      throw FileError(out.paths[i], "time: " + number_text(*b.time) + " comes after " + out.paths[i - 1] + " at time " +
                                        number_text(*prev.time) + "; give the volumes in time order");
  }
  return out;
}

/// Checks a volume read from `file` against its sidecar at `sidecar_path`: the array's points per axis
/// must be the sidecar's dims. Throws FileError naming the sidecar.
inline void check_volume_against_sidecar(const std::string& file, const Volume& v, const FieldSidecar& s,
                                         const std::string& sidecar_path) {
  if (v.dims == s.dims) return;
  auto d = [](const std::array<int, 3>& x) {
    return "[" + std::to_string(x[0]) + ", " + std::to_string(x[1]) + ", " + std::to_string(x[2]) + "]";
  };
  throw FileError(sidecar_path, "dims: " + d(s.dims) + " (points along x, y, z), but " + file + " holds " +
                                    std::to_string(v.dims[0]) + "x" + std::to_string(v.dims[1]) + "x" + std::to_string(v.dims[2]) +
                                    " points (a C-order .npy of shape (" + std::to_string(v.dims[2]) + ", " +
                                    std::to_string(v.dims[1]) + ", " + std::to_string(v.dims[0]) +
                                    ")); expected the sidecar of this array");
}

}  // namespace panoptes::app
