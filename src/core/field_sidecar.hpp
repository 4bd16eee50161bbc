#pragma once
// The sidecar of a field file (issue 41): a small JSON file beside a raw array (`<name>.npy` ->
// `<name>.json`) that says what the array cannot — its grid (dims, origin, spacing), units, which way
// is up, and when it was taken — so a reader shows it the right way up without being told.
// `panoptes seismic` writes one per snapshot, `panoptes render` reads it. Format: docs/formats.md,
// "Field sidecars".
#include <array>
#include <optional>
#include <string>

#include "core/vec3.hpp"

namespace panoptes {

/// What a field sidecar records. Only `dims`, `spacing` and `up_axis` are required in the file.
struct FieldSidecar {
  std::string data;                   ///< file name of the array it describes (no directory), "" = not recorded
  std::string field;                  ///< name of the field, e.g. "phi_p"; "" = not recorded
  std::string field_units;            ///< unit of the values, e.g. "1/s"; "" = unknown
  std::array<int, 3> dims{0, 0, 0};   ///< points along x, y, z (x fastest: a C-order .npy has shape (nz, ny, nx))
  std::optional<Vec3> origin;         ///< position of point (0, 0, 0); nullopt = not recorded (readers take 0, 0, 0)
  Vec3 spacing{1, 1, 1};              ///< distance between points along x, y, z (> 0)
  std::string length_units;           ///< unit of origin and spacing, e.g. "m"; "" = unknown
  std::string up_axis = "z_up";       ///< which way is the sky: "z_up", or "z_down" (z is depth)
  std::optional<double> time;         ///< simulation time of the values
  std::string time_units;             ///< unit of `time`, e.g. "s"; "" = unknown
  std::optional<long long> step;      ///< solver steps done when the values were taken
};

/// Format name and version written in every sidecar ("format", "version").
inline constexpr const char* kFieldSidecarFormat = "panoptes field sidecar";
inline constexpr int kFieldSidecarVersion = 1;

/// The sidecar's path for a data file: its extension replaced by ".json" (`snap/phi_p_000020.npy` ->
/// `snap/phi_p_000020.json`).
std::string field_sidecar_path(const std::string& data_path);

/// The sidecar as JSON text (one key per line, numbers as their shortest exact decimals).
std::string field_sidecar_json(const FieldSidecar& sidecar);

/// Parses sidecar text; `path` names the file in errors. Throws FileError naming the file, the key
/// and what was expected (`X.json: spacing: expected an array of 3 numbers > 0, got [1,0,1]`),
/// for malformed JSON, a missing required key, a wrong type or value, or another format/version.
/// Unknown keys are ignored (a later version may add some).
FieldSidecar parse_field_sidecar(const std::string& text, const std::string& path);

/// Reads and parses the sidecar at `path` (a regular file of at most 1 MiB).
FieldSidecar read_field_sidecar(const std::string& path);

/// Writes the sidecar to `path` (temp file + rename, so a reader never sees half of it). Throws FileError.
void write_field_sidecar(const std::string& path, const FieldSidecar& sidecar);

/// The sidecar beside `data_path` (field_sidecar_path), checked against it: nullopt when there is
/// none; otherwise its `data` must name this file (a sidecar copied beside another array would describe
/// the wrong grid and time). Throws FileError naming the sidecar.
std::optional<FieldSidecar> find_field_sidecar(const std::string& data_path);

}  // namespace panoptes
