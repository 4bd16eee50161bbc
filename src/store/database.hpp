#pragma once
// The movie database: a directory holding panoptes.json (the manifest) and one movie per
// (camera, task): a file found by the manifest's file-name pattern, or (packed layout, pack.hpp) byte
// ranges of a pack file that a binary index lists.
//
// Writing: DatabaseWriter::create → append(camera, task, frame) ... → checkpoint() after each snapshot
// → finalize(). Reading: Database::open (manifest only, no movie opened, no directory scan) →
// stream(camera, task) opens a MovieReader on demand.
//
// Liveness: while a DatabaseWriter that writes the manifest exists, it holds an exclusive flock() on
// `<dir>/.panoptes.lock` (the file names the writer's host and pid). The kernel drops the lock when
// the process dies, however it dies. Database::open reports a manifest whose status is `running` as
// `interrupted` unless that lock is currently held (a live writer), so a killed run opens as
// interrupted with the frames of its last checkpoint.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "store/manifest.hpp"
#include "store/pack.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::store {

/// Name of the liveness lock file inside the database directory.
inline constexpr const char* kLockFileName = ".panoptes.lock";

/// Which layout a new database gets (WriterOptions::layout, `[output] layout`).
enum class LayoutChoice {
  /// Packed when the database has at least kPackedAutoStreams streams and gop 1 (the packed writer
  /// encodes intra-only movies), else files: small databases stay one playable file per stream.
  automatic,
  files,
  packed,
};
/// Stream count from which LayoutChoice::automatic packs (docs/formats.md, Packed layout).
inline constexpr std::int64_t kPackedAutoStreams = 1024;
/// Parses "auto" / "files" / "packed"; throws Error naming the value otherwise.
LayoutChoice parse_layout_choice(std::string_view text);

/// Options of DatabaseWriter::create.
struct WriterOptions {
  /// Replace an existing database in the directory (its manifest, lock and movie tree). Without it,
  /// a directory that already holds a panoptes.json is refused.
  bool overwrite = false;
  /// Cameras whose movies this writer produces (empty = all). With MPI, each rank writes the cameras
  /// it owns; only the writer with writes_manifest = true (rank 0) writes panoptes.json and the lock.
  std::vector<int> owned_cameras;
  /// False on the non-root ranks of a distributed run: no manifest, no lock, no existence check (the
  /// root created the directory; call create() there only after the root's create() returned).
  bool writes_manifest = true;
  /// How the refusal of an existing database says to replace it: the caller's own option (a
  /// command's "--overwrite"); empty = this struct's field, for C++ callers (issue 44).
  std::string overwrite_option;
  /// The layout of a new database (resume keeps the database's own; non-root writers follow the
  /// manifest the root wrote).
  LayoutChoice layout = LayoutChoice::automatic;
  /// Packed layout: this writer's rank (names its pack) and the number of ranks that write (the root
  /// records it in the manifest; a rank that owns no camera may create no writer).
  int rank = 0;
  int ranks = 1;
};

/// Writes a database. Not thread-safe except append(): appends to *different* streams may run
/// concurrently (each stream has its own encoder); same-stream appends must be serialized.
///
/// Memory: every stream that has been appended to keeps one open MovieWriter (an x264 encoder with
/// its lookahead and reference frames) until finalize(); the in-situ engine appends to every
/// (camera, task) each snapshot, so all writers stay open. Per-writer memory at 920x896, measured by
/// bench/video_bench (docs/formats.md, Movies): about 1 MB with gop 1 (the default: no encoder is
/// kept between frames), about 25 MB with gop > 1 (a live x264 encoder with reference frames). So
/// 10^4 streams of one rank need ~10 GB at gop 1: spread cameras over ranks (MPI), or write offline
/// stream by stream with close_stream(). In the packed layout (WriterOptions::layout) no stream keeps
/// an encoder or muxer: one encoder pool serves all, and a stream holds a 96-byte record plus its
/// compressed frames until the next flush (docs/formats.md, Packed layout).
class DatabaseWriter {
 public:
  /// Creates the directory (and parents) and writes the manifest with status `running`,
  /// frames_written 0, image.padded_* and (when empty) provenance.created / provenance.host filled in. Throws FileError if the directory already holds
  /// a database and !options.overwrite, or cannot be created; Error if the manifest is invalid.
  static DatabaseWriter create(const std::filesystem::path& dir, Manifest manifest,
                               const WriterOptions& options = {});
  /// Continues the database in `dir` after a restart (checkpoint/restart of a simulation): the
  /// manifest (rig, cameras, tasks, axes, grid, image size, video settings, movie pattern) must be
  /// the one it was written with, else FileError names what differs. The frames of its last
  /// checkpoint (`frames` < 0: the manifest's frames_written; non-root writers get the root's count)
  /// stay: each owned movie is rewritten with exactly those frames copied as they are (through a
  /// temporary file renamed over it, so a crash leaves the old movie) and the next append() continues
  /// it; the times of those frames stay. A directory without a database is created as by create().
  /// options.overwrite is ignored.
  static DatabaseWriter resume(const std::filesystem::path& dir, Manifest manifest, const WriterOptions& options = {},
                               int frames = -1);
  /// Shorthand for create(dir, manifest, {.overwrite = overwrite}).
  static DatabaseWriter create(const std::filesystem::path& dir, Manifest manifest, bool overwrite);

  DatabaseWriter(DatabaseWriter&&) noexcept;
  DatabaseWriter& operator=(DatabaseWriter&&) noexcept;
  /// Without finalize() (e.g. unwinding after an exception), flushes what it can and marks the
  /// manifest `interrupted` (best effort; never throws).
  ~DatabaseWriter();

  /// Appends the next frame of stream (camera, task), opening its movie on first use. Throws Error if
  /// camera/task are out of range or not owned, or the frame size differs from the manifest's image
  /// size (nothing is written then; earlier frames stay readable); FileError if writing fails.
  void append(int camera, int task, const Image& frame);

  /// Closes one stream's movie now (for offline writers that produce stream after stream, so memory
  /// does not grow with the number of streams). Its frame count is final: further appends to it
  /// throw. May run concurrently for different streams, like append().
  void close_stream(int camera, int task);

  /// Records the simulation time of a frame (stored in Manifest::times at the next checkpoint).
  void set_time(int frame, double time);

  /// Sets a provenance note (Manifest::provenance.extra[key]), written with the next checkpoint; a
  /// resumed database keeps the notes it had (the in-situ session keeps its running references there).
  void set_note(const std::string& key, const std::string& value);

  /// Records the reference of frame `frame` for Manifest::fields[field] (stored at the next checkpoint):
  /// the value that frame's relative windows are multiples of. Throws Error for an unknown field, a
  /// negative frame or a reference that is not finite and > 0.
  void set_field_reference(int frame, int field, double reference);

  /// Flushes every open movie (after it returns the frames are durable), then rewrites the manifest
  /// atomically with frames_written = complete_frames(). Throws FileError on a write failure; the
  /// manifest on disk then still describes the previous checkpoint.
  void checkpoint();
  /// As checkpoint(), but with frames_written given by the caller (the MPI minimum over ranks of
  /// complete_frames() after every rank flushed). Only meaningful when writes_manifest is true.
  void checkpoint(int frames_written);
  /// Flushes every open movie without writing the manifest (non-root ranks before a checkpoint).
  void flush();

  /// Number of complete snapshots here: the minimum, over this writer's streams, of frames appended.
  int complete_frames() const;

  /// Closes every movie and writes the manifest with status `complete`. Further appends throw.
  void finalize();
  /// Same as finalize(), but checkpoint(frames_written) semantics for the frame count (MPI root).
  void finalize(int frames_written);

  const Manifest& manifest() const;
  const std::filesystem::path& dir() const;

 private:
  struct Impl;
  explicit DatabaseWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A problem found by Database::validate_streams.
struct StreamProblem {
  enum class Kind { missing, unreadable, truncated, unsafe, damaged };
  int camera = 0, task = 0;
  Kind kind = Kind::missing;
  std::string message;  ///< one line, names the file
  std::vector<int> damaged_frames;  ///< Kind::damaged: the frames that did not decode cleanly
};

std::string_view to_string(StreamProblem::Kind kind);

/// Result of Database::validate_streams.
struct StreamReport {
  std::int64_t checked = 0;   ///< streams examined
  std::int64_t bytes = 0;     ///< total size of the movies found
  std::vector<StreamProblem> problems;
};

struct PackCatalog;

/// An opened database (reader side). Cheap to copy; const methods are thread-safe (stream() returns
/// an independent reader each call).
class Database {
 public:
  /// Reads and validates the manifest only: no movie is opened and the directory is not scanned, so
  /// open time does not grow with the number of streams. Throws FileError if dir is not a database
  /// (missing/unreadable/malformed manifest, unknown schema version, unsafe pattern).
  static Database open(const std::filesystem::path& dir);

  /// The manifest, with `status` replaced by the effective status (see status()).
  const Manifest& manifest() const { return manifest_; }
  /// Effective status: `running` only while a live writer holds the lock; a stored `running` without
  /// one is `interrupted`.
  Status status() const { return manifest_.status; }
  /// The status exactly as written in panoptes.json.
  Status stored_status() const { return stored_status_; }
  const std::filesystem::path& dir() const { return dir_; }
  int camera_count() const { return manifest_.camera_count(); }
  int task_count() const { return manifest_.task_count(); }
  std::int64_t stream_count() const { return manifest_.stream_count(); }
  /// Frames readable in every stream (the last checkpoint's count).
  int frame_count() const { return manifest_.frames_written; }

  /// Path of the stream's movie (lexical: dir / pattern expansion). Throws Error when out of range.
  std::filesystem::path stream_path(int camera, int task) const;
  /// Opens the stream's movie with the crop to the manifest's image size. Throws FileError if the
  /// resolved path leaves the database directory (e.g. through a symlink), or the movie is missing,
  /// truncated to nothing or not a movie.
  std::unique_ptr<video::MovieReader> stream(int camera, int task) const;

  /// True for a packed database (Manifest::layout).
  bool packed() const { return manifest_.layout == Layout::packed; }
  /// A stream of a packed database as byte ranges of its packs (init segment, then its fragments with
  /// their frame numbers), for servers and exporters that hand out bytes without decoding: the
  /// concatenation of the pieces is a standard fragmented MP4. Covers every indexed fragment (may be
  /// more than frame_count()). Throws Error for a files database, FileError for a damaged index.
  PackedStream packed_stream(int camera, int task) const;

  /// What readers of the stream's movie demand of every frame: with frame checks recorded in the
  /// manifest (databases written since they are), a good checksum, this stream's identity, the
  /// frame's index and timestamp; without (older databases), checksums when the movie carries them.
  video::FrameChecks frame_checks(int camera, int task) const;
  /// The checkpointed frames of the stream that fail those checks, found without decoding (reads
  /// the movie once): what a reader that does not decode through MovieReader (the web server's
  /// index, a browser) must show as damaged. Throws what stream() throws.
  std::vector<int> damaged_frames(int camera, int task) const;

  /// Deep check: opens every stream's movie (in parallel with `threads` threads, 0 = hardware) and
  /// reports missing, unsafe, unreadable and truncated (fewer than frame_count() frames) ones. With
  /// decode_all, also decodes every checkpointed frame of every movie (in order: one decode per
  /// frame) and reports the movies with damaged frames (Kind::damaged, listing them).
  /// `progress(done, total)` is called from one thread now and then, if given.
  StreamReport validate_streams(int threads = 0, bool decode_all = false,
                                const std::function<void(std::int64_t, std::int64_t)>& progress = {}) const;

 private:
  std::filesystem::path dir_;
  Manifest manifest_;
  Status stored_status_ = Status::running;
  std::unique_ptr<video::MovieReader> packed_reader(int camera, int task) const;
  std::shared_ptr<PackCatalog> packs_;  // packed layout: the index headers, read on first use
};

/// The identity stamped on every frame of stream (camera, task): the manifest's database id (8 bytes),
/// camera and task (4 bytes each, big-endian).
video::MovieIdentity movie_identity(const Manifest& manifest, int camera, int task);

/// True if a live process holds the writer lock of the database in dir.
bool writer_is_alive(const std::filesystem::path& dir);

}  // namespace panoptes::store
