#pragma once
// The manifest of a movie database (`panoptes.json`): plain data + versioned JSON (de)serialization.
// Its size grows with cameras + tasks, never cameras × tasks: streams are found by a file-name pattern.
// Since schema 2 the per-camera table (cameras and navigation graph) is written to a binary sidecar
// file (store/camera_table.hpp) that panoptes.json references with its size and checksum.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vec3.hpp"
#include "video/video_settings.hpp"

namespace panoptes::store {

/// Schema version this build writes. It reads kOldestSchemaVersion .. kSchemaVersion and refuses any
/// other version with a clear error.
inline constexpr int kSchemaVersion = 2;
/// Oldest schema version this build still reads (1: cameras and graph inline in the JSON).
inline constexpr int kOldestSchemaVersion = 1;
/// File name of the manifest inside the database directory.
inline constexpr const char* kManifestFileName = "panoptes.json";
/// Largest panoptes.json a reader accepts (a schema-1 manifest with 10^6 inline cameras has 232 MB;
/// schema 2 keeps cameras in the binary table): bounds what a hostile manifest can make a reader load.
inline constexpr std::uint64_t kMaxManifestBytes = std::uint64_t(256) << 20;
/// Largest number of cameras a database may hold (2097152): readers keep ~200 bytes per camera in
/// memory, so a table of shared columns claiming 2*10^7 cameras is refused instead of taking 4 GB.
inline constexpr std::int64_t kMaxCameras = std::int64_t(1) << 21;
/// Largest frame a database may hold: H.264 level 6.2 allows 139264 macroblocks (35.6 Mpixel, e.g.
/// 8192x4352); each side at most kMaxImageSide.
inline constexpr std::int64_t kMaxImagePixels = std::int64_t(139264) * 256;
inline constexpr int kMaxImageSide = 16384;
/// Default movie file-name pattern, relative to the database directory.
inline constexpr const char* kDefaultMoviePattern = "movies/c{camera}/t{task}.mp4";

/// Who made the database, when and how.
struct Provenance {
  std::string program;       ///< e.g. "panoptes synth-db", "seismic demo", "mysim"
  std::string version;       ///< program version
  std::string created;       ///< ISO 8601 UTC time, e.g. "2026-11-21T22:40:00Z"
  std::string host;          ///< host name of the writer (rank 0)
  std::string command_line;  ///< the command that produced it
  std::map<std::string, std::string> extra;  ///< free-form key/value notes
  bool operator==(const Provenance&) const = default;
};

/// The simulation domain the images show (informational; the player shows it in its HUD).
struct Domain {
  std::array<std::int64_t, 3> dims{0, 0, 0};  ///< grid points per axis (0 = unknown)
  Vec3 origin{0, 0, 0};
  Vec3 spacing{1, 1, 1};
  std::string units;  ///< length unit, e.g. "m", "km"; empty = dimensionless
  /// Which way is up (towards the sky): "z_up", "z_down" (z is depth, as in seismology), or empty for
  /// databases written before it was recorded, which the player treats as z_up.
  std::string up_axis;
  /// The simulation's own grid when it is not the uniform one the images were rendered from (issue 33:
  /// resampled by the grid stage), as grid::GridDescription::summary() gives it, e.g.
  /// "spherical 24x64x128, r in [0.35, 1]"; its first word is the kind. Empty = the uniform grid above.
  std::string grid;
  bool operator==(const Domain&) const = default;
  /// Unit vector towards the sky: (0, 0, −1) for "z_down", else (0, 0, 1).
  Vec3 sky() const { return up_axis == "z_down" ? Vec3{0, 0, -1} : Vec3{0, 0, 1}; }
};

/// Size of every frame of every stream. Movies are coded at padded_* (even, for 4:2:0) and
/// readers crop to width x height.
struct ImageSize {
  int width = 0, height = 0;
  int padded_width = 0, padded_height = 0;  ///< 0 = not yet known (set by DatabaseWriter::create)
  bool operator==(const ImageSize&) const = default;
};

/// Labels of a camera, for the HUD and for navigation.
struct CameraLabels {
  std::string patch;     ///< rig patch, e.g. "yin", "yang", "fibonacci"; empty if none
  double lat_deg = 0;    ///< latitude of the viewing direction seen from the look-at point
  double lon_deg = 0;    ///< longitude, degrees
  int shell = 0;         ///< index of the radius shell (0 = outermost or only)
  std::map<std::string, std::string> extra;  ///< free-form labels
  bool operator==(const CameraLabels&) const = default;
};

/// One camera. Its id is its index in Manifest::cameras (0..N-1); stored for readability and checked.
struct CameraEntry {
  int id = 0;
  Vec3 position{0, 0, 1};
  Vec3 look_at{0, 0, 0};
  Vec3 up{0, 1, 0};
  double fov_y_deg = 45;
  CameraLabels labels;
  bool operator==(const CameraEntry&) const = default;
};

/// How the cameras were placed (e.g. kind "yin-yang", parameters {"nlat":5,"nlon":13,"radius":3}).
struct RigDescription {
  std::string kind;
  nlohmann::json parameters = nlohmann::json::object();
  bool operator==(const RigDescription&) const = default;
};

/// A field the tasks read (recorded since issue 34; older manifests have none): its unit and, per
/// frame, the reference value its relative windows and isovalues are multiples of, so a player can
/// label a colour bar with physical values.
struct FieldInfo {
  std::string name;    ///< as in TaskEntry::fields, e.g. "phi_p"
  std::string units;   ///< unit of its values, e.g. "1/s"; empty = unknown or dimensionless
  /// references[i]: the reference of frame i (a percentile of |field|, or its running maximum); may be
  /// shorter than the frames (not recorded), each finite and > 0.
  std::vector<double> references;
  /// What the references follow (issue 41): "snapshot", "running" or "fixed"; empty in older
  /// manifests (their references are per snapshot unless provenance says a running maximum).
  std::string reference_mode;
  bool operator==(const FieldInfo&) const = default;
};

/// Neighbours of one camera in the navigation graph; -1 = none.
struct Neighbours {
  int left = -1, right = -1, up = -1, down = -1;
  int in = -1, out = -1;  ///< closer / farther shell
  bool operator==(const Neighbours&) const = default;
};

/// The navigation graph: empty (no navigation data) or exactly one entry per camera.
struct NavigationGraph {
  std::vector<Neighbours> neighbours;
  bool empty() const { return neighbours.empty(); }
  bool operator==(const NavigationGraph&) const = default;
};

/// A parameter axis, e.g. {"isovalue", {0.1, 0.2, 0.3}}. Tasks sit at an index of some axes.
struct ParameterAxis {
  std::string name;
  std::vector<double> values;
  std::string units;  ///< optional
  bool operator==(const ParameterAxis&) const = default;
};

/// The position of a task on one parameter axis: Manifest::axes[axis].values[index].
struct AxisPosition {
  std::string axis;  ///< name of a ParameterAxis
  int index = 0;
  bool operator==(const AxisPosition&) const = default;
};

/// One visualization task. Its id is its index in Manifest::tasks (0..K-1).
struct TaskEntry {
  int id = 0;
  std::string name;                 ///< unique, e.g. "phi_s iso 0.2"
  std::string method;               ///< "volume", "isosurface", "slice", "synthetic", ...
  std::vector<std::string> fields;  ///< fields it reads
  nlohmann::json parameters = nlohmann::json::object();  ///< method parameters
  std::vector<AxisPosition> axes;   ///< where it sits on the parameter axes (may be empty)
  bool operator==(const TaskEntry&) const = default;
};

/// The camera table sidecar a manifest refers to (schema 2, field `camera_table`): a file in the
/// database directory holding every camera and the navigation graph (see store/camera_table.hpp).
struct CameraTableRef {
  std::string file;          ///< plain file name in the database directory, e.g. "cameras.1a2b3c4d.bin"
  std::uint64_t bytes = 0;   ///< its size
  std::uint32_t crc32 = 0;   ///< CRC-32 of its bytes 16..end (recorded in its header too)
  std::int64_t cameras = 0;  ///< cameras it holds
  bool navigation = false;   ///< it holds a navigation graph
  bool operator==(const CameraTableRef&) const = default;
};

/// How a database's movies prove their frames (field `frame_checks`). Databases written before it
/// was recorded have none: their readers check a movie's checksums when its first packets carry
/// them, as before.
struct FrameCheckRecord {
  /// kFrameCheckScheme: every frame of every movie carries a checksum message with its CRC, the
  /// movie's identity (database_id, camera, task) and its index (video/packet_checksum.hpp, version 2).
  /// Empty: not recorded.
  std::string scheme;
  std::string database_id;  ///< 16 lowercase hex digits, random per database
  bool recorded() const { return !scheme.empty(); }
  /// Scheme 3: the frames' identity also binds the movie's parameter sets (SPS/PPS).
  bool binds_parameter_sets() const;
  bool operator==(const FrameCheckRecord&) const = default;
};

/// The frame check scheme this build writes: version-2 messages whose identity is bound to the movie's
/// parameter sets (video::bind_parameter_sets; issue 44: a flipped bit in the avcC's PPS changed every
/// frame while every frame's own CRC held).
inline constexpr const char* kFrameCheckScheme = "panoptes-frame-3";
/// The scheme before it (no parameter-set binding), still read: its frames are checked, its SPS/PPS not.
inline constexpr const char* kFrameCheckSchemeUnboundHeader = "panoptes-frame-2";
inline bool FrameCheckRecord::binds_parameter_sets() const { return scheme == kFrameCheckScheme; }

/// Where a database keeps its movies (field `layout`): one file per stream named by `movie_pattern`,
/// or packs (store/pack.hpp: per writing rank and output segment one pack file and one index).
enum class Layout { files, packed };
std::string_view to_string(Layout layout);

/// One output segment of a packed database (a run, or a resumed continuation of it): its packs are
/// packs/s<segment>-r<rank>.pack/.idx for rank 0 .. ranks-1 (a rank that owned no camera has none).
struct PackSegment {
  int segment = 0;
  int first_frame = 0;  ///< frames before it come from earlier segments
  int ranks = 1;
  bool operator==(const PackSegment&) const = default;
};

/// Lifecycle of a database. `running` on disk with no live writer is reported as interrupted by
/// Database::open (see database.hpp).
enum class Status { running, complete, interrupted };

std::string_view to_string(Status status);
/// Parses "running" / "complete" / "interrupted"; throws Error otherwise.
Status parse_status(std::string_view text);

/// Everything a reader needs to know about a database.
struct Manifest {
  int schema_version = kSchemaVersion;
  std::string title;
  Provenance provenance;
  Domain domain;
  std::vector<double> times;  ///< simulation time of each frame (may be empty or longer than frames_written)
  ImageSize image;
  video::VideoSettings video;
  std::vector<CameraEntry> cameras;
  RigDescription rig;
  NavigationGraph graph;
  std::vector<TaskEntry> tasks;
  std::vector<ParameterAxis> axes;
  Status status = Status::running;
  int frames_written = 0;  ///< complete snapshots: every stream holds at least this many frames
  std::string movie_pattern = kDefaultMoviePattern;  ///< relative; must contain {camera} and {task}
  /// Preferred playback rate in frames per second (0 = none: players use video.fps). A database of
  /// few snapshots sets it so the whole run lasts several seconds instead of flashing by at 30 fps.
  double playback_fps = 0;
  /// Unit of `times`, e.g. "s"; empty = unknown (older manifests).
  std::string time_units;
  /// The fields the tasks read, with units and per-frame references (empty in older manifests).
  std::vector<FieldInfo> fields;
  /// How its movies prove their frames (empty in older databases; DatabaseWriter::create fills it in).
  FrameCheckRecord frame_checks;
  /// Movies in files (the pattern) or in packs; packs lists the segments of a packed database.
  Layout layout = Layout::files;
  std::vector<PackSegment> packs;

  int camera_count() const { return int(cameras.size()); }
  int task_count() const { return int(tasks.size()); }
  std::int64_t stream_count() const { return std::int64_t(cameras.size()) * std::int64_t(tasks.size()); }

  /// Time of frame i: times[i] if present, else i.
  double frame_time(int frame) const;
  /// The stream's file name relative to the database directory (pattern expanded; not checked on disk).
  /// Throws Error if camera or task is out of range.
  std::string stream_relative_path(int camera, int task) const;

  /// Index of the task with this name, or -1.
  int find_task(std::string_view name) const;
  /// Index of the field with this name in `fields`, or -1.
  int find_field(std::string_view name) const;
  /// Index of the axis with this name, or -1.
  int find_axis(std::string_view name) const;
  /// The task that sits at the same positions as `task` on every axis except `axis`, where its index
  /// is moved by `delta`; -1 if there is none (end of the axis, or task not on that axis).
  int step_task_on_axis(int task, std::string_view axis, int delta) const;

  /// Checks internal consistency (schema_version must be one this build reads) (ids, graph size and targets, axis references, pattern safety, image
  /// size, video settings, frames_written). Throws Error naming the first bad field and its value.
  void validate() const;
  // No operator==: compare to_json() results (VideoSettings has no comparison).
};

/// Checks a movie file-name pattern: relative, no "..", "." or empty components, no backslash or NUL,
/// contains {camera} and {task}, no other {...} placeholders. Throws Error with the reason.
void validate_movie_pattern(const std::string& pattern);

/// Serializes to one self-contained JSON document (current schema_version) with the cameras and the
/// navigation graph inline (`cameras`, `navigation.neighbours`), as schema 1 stored them. Files on disk
/// are written by write_manifest_atomic, which puts those two into the camera table instead.
nlohmann::json to_json(const Manifest& manifest);
/// Parses and validates. `source` names the origin (file path) in error messages. Cameras and graph
/// are either inline or in the camera table `dir / camera_table.file` (then `dir` must be given).
/// Throws Error on an unknown schema version, a missing or mistyped field, or a failed validate();
/// FileError for a missing, corrupt or mismatched camera table.
Manifest manifest_from_json(const nlohmann::json& json, const std::string& source,
                            const std::filesystem::path& dir = {});

/// Reads `path` (a panoptes.json file) and the camera table it refers to. Throws FileError if either is
/// missing/unreadable/malformed/invalid.
Manifest read_manifest(const std::filesystem::path& path);
/// Writes the camera table (write_camera_table) and then the manifest referring to it, each atomically
/// (temp file in the same directory, fsync, rename, fsync of the directory); then removes the table the
/// previous manifest referred to if it differs. On failure (e.g. disk full) the previous manifest and
/// its table are left untouched and FileError is thrown.
void write_manifest_atomic(const std::filesystem::path& path, const Manifest& manifest);
/// Writes only panoptes.json (atomically), referring to an already written camera table `table`,
/// which must hold manifest.cameras and manifest.graph (checkpoints: the cameras never change during
/// a run, so the table is written once). Throws Error if table's camera count differs.
void write_manifest_atomic(const std::filesystem::path& path, const Manifest& manifest, const CameraTableRef& table);

/// The camera table file an existing manifest refers to (parsing the JSON only); empty if it has none
/// or cannot be read.
std::string referenced_camera_table(const std::filesystem::path& manifest_path);

}  // namespace panoptes::store
