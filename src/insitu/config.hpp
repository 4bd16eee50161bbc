#pragma once
// Configuration of an in-situ session (plain data) and its TOML form, shared by the C++ API, the C
// API and `panoptes run`. Every key is documented by config_keys_help().
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/renderer.hpp"
#include "video/video_settings.hpp"

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace panoptes::insitu {

/// Largest image side accepted (pixels); the memory check bounds the product with the rig.
inline constexpr int kMaxImageSide = 16384;
/// Largest configuration file read (bytes).
inline constexpr unsigned long long kMaxConfigBytes = 16ull << 20;

/// A value window: absolute [lo, hi], or relative (lo·ref, hi·ref) where ref is the running maximum
/// of the `percentile` quantile of |field| over the whole grid (this snapshot's, or the running
/// maximum over snapshots, or a fixed value: SessionConfig::reference and field_scales).
struct WindowConfig {
  double lo = 0, hi = 1;
  bool relative = true;
};

/// One task, or a sweep of tasks along one parameter axis (several isovalues, windows or slice
/// positions give several tasks, placed on a manifest axis so the player can step through them).
struct TaskConfig {
  /// The renderer's kind; a volume reading two fields is TOML's type = "volume2" (task_plan.hpp maps
  /// the [[task]] keys of every kind).
  render::TaskKind kind = render::TaskKind::volume;
  std::string name;                  ///< unique; sweeps append " <value>" per task
  std::vector<std::string> fields;   ///< 1 field (a volume of two fields: 2)
  std::string preset = "hot";        ///< transfer function (volume, slice colour map)
  std::string preset2 = "s-wave";    ///< volume2: second field's transfer function
  float extinction_scale = 1;
  std::vector<WindowConfig> windows{WindowConfig{}};  ///< volume/slice; several = a "window" sweep
  WindowConfig window2;                                ///< volume2: second field's window
  std::vector<double> isovalues;     ///< isosurface: values (or fractions of ref if iso_relative)
  bool iso_relative = false;
  std::array<float, 3> colour{0.85f, 0.85f, 0.85f};  ///< isosurface colour
  int slice_axis = 2;
  std::vector<double> slice_positions{0.5};  ///< fractions of the domain along slice_axis
  std::string axis;                  ///< name of the sweep axis (default: "<name> isovalue|window|position")
};

/// When snapshots are taken: every `every_steps` steps, or every `every_time` of simulation time
/// (exactly one of them > 0), at most max_snapshots (0 = unlimited).
struct ScheduleConfig {
  std::int64_t every_steps = 10;
  double every_time = 0;
  int max_snapshots = 0;
};

/// What a session does with a database already in its output directory ([output] mode).
enum class OutputMode {
  create,     ///< refuse it (a new run never destroys an old one by accident)
  overwrite,  ///< replace it
  /// Continue it after a checkpoint restart: the snapshots it holds stay, snapshots the restarted run
  /// repeats (time ≤ the last one written) are skipped, and the movies go on from there. The rig,
  /// tasks, grid, image, video settings and schedule must be the ones it was written with. Only an
  /// interrupted database is continued; a complete one (its run finished) is refused unless
  /// SessionConfig::resume_complete says to append to it.
  resume
};
/// "create" / "overwrite" / "resume".
const char* to_string(OutputMode mode);
/// Parses the names of to_string(); throws Error naming `[output] mode` and the accepted values.
OutputMode parse_output_mode(const std::string& text);

/// What the reference of a field's relative windows and isovalues follows over time (issue 41). The
/// reference is the unit relative windows are multiples of; the manifest records it per frame.
enum class ReferenceMode {
  snapshot,  ///< this snapshot's quantile: each frame fills its window, so brightness says nothing across frames
  running,   ///< the largest quantile so far: never shrinks, so a decaying wave gets darker (the default)
  fixed      ///< a physical value from the configuration: the same colour means the same value in every run
};
/// "snapshot" / "running" / "fixed".
const char* to_string(ReferenceMode mode);
/// Parses the words of to_string() (and "running-max", the older word for "running"); throws Error
/// naming `key`, the text and the accepted words.
ReferenceMode parse_reference_mode(const std::string& text, const std::string& key);

/// How one field's reference is chosen: a mode and, for ReferenceMode::fixed, the physical value.
struct FieldScale {
  ReferenceMode mode = ReferenceMode::running;
  double value = 0;  ///< fixed: the reference in the field's units (> 0)
  bool operator==(const FieldScale&) const = default;
};

/// Whether the fields of one two-field picture (volume2) share one reference (issue 41).
enum class ScaleSharing {
  units,  ///< share when their units agree (or are not given): p+s both in 1/s, a weak field stays dark
  none    ///< each field its own reference: every field fills its window, whatever its strength
};

/// How several ranks share a snapshot's rendering ([resources] parallel).
enum class RenderSplit {
  /// cameras when the whole grid's fields are small (kReplicateBytes per rank) and there are at least
  /// as many cameras as ranks, else bricks
  automatic,
  /// Every rank gathers the whole grid's fields and renders its own cameras through the whole volume:
  /// no partial images, no compositing, no waiting for the other ranks' partials. On the issue-45 setting
  /// (26 cameras x 2 tasks at 320x320, 128x128x64 points, 2 ranks) the sort-last split cost 1.8x the CPU
  /// of one rank rendering everything; the frames equal one rank's exactly.
  cameras,
  /// Every rank renders its own brick for every camera; the partial images are composited at the camera's
  /// owner (sort-last). Each rank holds only its brick: for grids too large to copy to every rank.
  bricks
};
/// "auto" / "cameras" / "bricks".
const char* to_string(RenderSplit split);
/// Parses the words of to_string(); throws Error naming `[resources] parallel` and the accepted words.
RenderSplit parse_render_split(const std::string& text);
/// The float32 copy of the whole grid's fields (with the march's corner copies) that
/// RenderSplit::automatic lets every rank hold: 256 MiB, e.g. two volume fields of 6 M points.
inline constexpr double kReplicateBytes = 256.0 * 1024 * 1024;

/// Everything a session needs besides the grid and the communicator.
struct SessionConfig {
  std::string output_dir = "panoptes_out";
  OutputMode mode = OutputMode::create;
  /// [output] resume_complete: mode = "resume" may continue a database whose run finished (extend a
  /// finished run from its last checkpoint). Off by default: a rerun into the same directory would
  /// otherwise skip every snapshot (their times are all in the database) and keep the old movies.
  bool resume_complete = false;
  /// [output] keep_interrupted: mode = "overwrite" over an INTERRUPTED database keeps it beside, as
  /// DIR.interrupted-N, instead of deleting it (issue 42: a restart meant to resume lost part 1 of its
  /// run without a word). The commands' explicit --overwrite sets it false.
  bool keep_interrupted = true;
  /// [output] layout: "auto" (packed from store::kPackedAutoStreams streams at gop 1, else files),
  /// "files" (one movie file per stream) or "packed" (per rank and run segment one pack + index).
  std::string layout = "auto";
  std::string title = "in-situ visualization";
  std::string program = "panoptes insitu";  ///< recorded in the manifest's provenance
  std::string command_line;
  /// What to do about a database already in output_dir, as the refusal says it (issue 44: a command
  /// reading no TOML was told to set a TOML key). Empty: the [output] mode keys, as a TOML user has.
  std::string existing_database_advice;
  std::string units;                  ///< length unit of the grid, for the manifest
  std::string time_units;             ///< unit of the snapshot times, for the manifest (e.g. "s")
  /// Unit of each field's values by field name, for the manifest's colour legends (e.g. phi_p: "1/s").
  std::map<std::string, std::string> field_units;
  std::string rig = "yinyang";        ///< camera::RigSpec string
  std::array<double, 3> up{0, 0, 0};  ///< requested up vector of the rig's cameras (world); 0 = the sky
  std::string up_axis;                ///< which way is up in the domain: "z_up" / "z_down"; "" = z_up
  std::string source_grid;            ///< set by the grid stage: the simulation's non-uniform grid (manifest domain.grid)
  /// "perspective" or "equirectangular" (360° x 180° frames; the domain outline is drawn as arcs).
  std::string projection = "perspective";
  double playback_fps = 0;            ///< preferred playback rate for players (0 = the video's fps)
  int width = 920, height = 896;
  std::vector<TaskConfig> tasks;
  ScheduleConfig schedule;
  video::VideoSettings video;
  /// The product's defaults: image-space adaptive sampling (issue 45: Panoptes 0.44x -> 0.33x of a code's CPU in
  /// situ, frames >= 55.6 dB of marching every pixel) and anti-aliased isosurfaces (iso_edges.hpp).
  render::RenderOptions render{.adaptive = true, .iso_antialias = true};
  std::array<float, 3> background{0, 0, 0};
  bool outline = true;
  bool compass = true;                ///< 360° frames: horizon, ticks and N/E/S/W (render::OutlineStyle)
  double percentile = 0.999;          ///< quantile of |v| used as reference of relative windows
  /// What every field's reference follows over time ([render] reference); per-field exceptions in
  /// field_scales ([render.field.NAME] reference, value).
  ReferenceMode reference = ReferenceMode::running;
  std::map<std::string, FieldScale> field_scales;
  ScaleSharing share_scale = ScaleSharing::units;  ///< [render] share_scale: two-field pictures
  /// The scale of `field`: its entry in field_scales, else {reference}.
  FieldScale scale_of(const std::string& field) const;
  /// Refuse to start when the estimated memory of a rank exceeds what it has available ([resources]
  /// check_memory; false = `--force`, for people who know better than the estimate).
  bool check_memory = true;
  /// Seconds a rank waits in a session call for the other ranks before it reports them missing
  /// ([resources] mpi_timeout; rank_agreement.hpp). Ranks in step arrive within a step's imbalance;
  /// only a rank that stopped calling Panoptes is waited for this long.
  double mpi_timeout = 120;
  /// How several ranks share the rendering ([resources] parallel).
  RenderSplit parallel = RenderSplit::automatic;

  /// Checks ranges and consistency (not the grid); throws panoptes::Error naming the key.
  void validate() const;
};

/// Reads the in-situ keys from a TOML table (sections [output], [image], [rig], [schedule], [video],
/// [render] and the array [[task]]). Keys of other sections listed in `foreign_sections` are left
/// for the caller (e.g. the seismic solver's); any other unknown key, a wrong type or an impossible
/// value throws panoptes::Error naming `source`, the key and what was expected.
SessionConfig parse_session_config(const toml::table& table, const std::string& source,
                                   const std::vector<std::string>& foreign_sections = {});
/// Parses TOML text (errors name `source`).
SessionConfig parse_session_config_text(const std::string& text, const std::string& source,
                                        const std::vector<std::string>& foreign_sections = {});
/// Reads a TOML file; throws FileError naming the file.
SessionConfig load_session_config(const std::string& path, const std::vector<std::string>& foreign_sections = {});

/// Parses a file that holds the session's sections and another component's (`foreign_sections`, e.g.
/// the seismic solver's): returns the session configuration and, in `foreign_text`, the TOML text of
/// the foreign sections only, for that component's own parser.
SessionConfig parse_combined_config(const std::string& text, const std::string& source,
                                    const std::vector<std::string>& foreign_sections, std::string& foreign_text);

/// Documentation of every key with its default.
const char* config_keys_help();

}  // namespace panoptes::insitu
