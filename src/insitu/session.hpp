#pragma once
// The in-situ session: a simulation hands it views of its local block at every snapshot; it renders
// every (camera, task) image, composites the partial images of all ranks on the rank that owns the
// camera, and appends them to the movie database (DESIGN.md decisions 4, 5, 6, 9).
//
// Data flow of one snapshot (collective over the communicator):
//   local block (float or double, any strides, ghost layers) → float32 copy covering the brick's
//   ghosted point range (missing ghost points fetched from the ranks that own them) → macro-cells →
//   for each camera: ONE render_brick march for all tasks → partial images (rect + premultiplied
//   RGBA + depth) sent to the owner rank of the camera (camera c ↦ rank c mod P, MPI_Isend) → the
//   owner composites by per-pixel depth, finishes (background + outline) and appends to its movies
//   → every rank flushes → MPI_Allreduce(min) of complete frames → rank 0 checkpoints the manifest.
// Cameras are processed in rounds of P (one per owner), so at most ~2·P·K partial images are in
// flight per rank whatever the number of cameras.
#include <array>
#include <cstdint>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/image.hpp"
#include "insitu/config.hpp"
#include "insitu/overhead.hpp"
#include "render/field_view.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::grid {
struct GridDescription;
}

namespace panoptes::insitu {

struct GridBlock;        // grid_adapter.hpp
struct ResampleOptions;  // grid_adapter.hpp

/// A bad argument of a call (a time that is not finite, or not after the previous snapshot's):
/// refused before anything is written, the database stays as it was. The C API returns it as
/// PANOPTES_ERROR_USAGE.
struct UsageError : Error {
  using Error::Error;
};

/// Element type of a simulation field.
enum class ScalarType { f32, f64 };

/// This rank's part of the global grid: the points it OWNS (a box; the boxes of all ranks partition
/// the grid's points) and the ghost layers its arrays hold around them. The session needs, for its
/// brick, 2 ghost layers below and 3 above the owned box on every split axis (render::required_points).
/// It reads from the arrays only the owned points and the ghosts the caller keeps valid: the valid
/// layers (valid_lo/hi) beside each face, and edge and corner ghosts only when edges_valid. Every other
/// point it needs is fetched from its owner (one extra exchange per snapshot), so any ghost width,
/// including 0, and any halo exchange, including none, gives the same picture.
struct LocalBlock {
  render::Index3 offset{0, 0, 0};    ///< global index of the first owned point
  render::Index3 extent{0, 0, 0};    ///< owned points per axis
  render::Index3 ghost_lo{0, 0, 0};  ///< ghost layers stored below the owned box, per axis
  render::Index3 ghost_hi{0, 0, 0};  ///< ghost layers stored above it
  /// Ghost layers the caller keeps up to date, per axis (≤ the stored layers); -1 = every stored layer.
  render::Index3 valid_lo{-1, -1, -1};
  render::Index3 valid_hi{-1, -1, -1};
  /// True when the caller's halo exchange fills edge and corner ghosts too (a full 26-neighbour
  /// exchange); false (the default) = face-only halos: edge and corner ghosts are fetched from their owners.
  bool edges_valid = false;
  /// The whole grid owned by one process, no ghosts.
  static LocalBlock whole(const render::GridGeometry& g) { return {{0, 0, 0}, g.dims, {0, 0, 0}, {0, 0, 0}}; }
  /// Slab `index` of `parts` along `axis` (the usual 1-D decomposition), with `ghosts` layers on
  /// both sides of the split axis where a neighbour exists.
  static LocalBlock slab(const render::GridGeometry& g, int axis, int parts, int index, int ghosts = 0);
};

/// One field of the local block for one snapshot. `data` points at the FIRST OWNED point
/// (global index LocalBlock::offset); ghost points are at negative offsets. `stride` is in elements
/// per axis; {0,0,0} means contiguous x-fastest over the ghosted box (C [nz][ny][nx], Fortran (nx,ny,nz)).
struct FieldInput {
  std::string name;
  const void* data = nullptr;
  ScalarType type = ScalarType::f32;
  std::array<std::int64_t, 3> stride{0, 0, 0};
};

/// Seconds spent in each phase (this rank), summed over snapshots.
struct Timings {
  double copy = 0;       ///< field conversion, ghost exchange, macro-cells, reference values
  double render = 0;     ///< render_brick marches
  double composite = 0;  ///< sending partials, waiting for them, compositing, finishing images
  double encode = 0;     ///< DatabaseWriter::append (H.264 encoding)
  double checkpoint = 0; ///< flush + reduction + manifest
  double total() const { return copy + render + composite + encode + checkpoint; }
};

/// What a rank holds and did, for reports.
struct SessionStats {
  int snapshots = 0;              ///< snapshots processed
  std::int64_t frames_encoded = 0;  ///< (camera, task) frames appended on this rank
  int owned_cameras = 0;          ///< cameras (hence encoders ×tasks) on this rank
  std::int64_t field_buffer_bytes = 0;   ///< float32 copies of the brick's fields and their 16-bit corner copies
  std::int64_t partial_buffer_bytes = 0; ///< partial images and message buffers (capacity)
  std::int64_t peak_rss_bytes = 0;       ///< process peak resident set (getrusage), includes encoders
  Timings time;
  double session_seconds = 0;  ///< wall time inside the session's calls (construction, snapshots, finalize)
  double elapsed_seconds = 0;  ///< wall time from construction to finalize (or to now)
  double visualization_cpu_seconds = 0;  ///< process CPU (all threads) spent by Panoptes (overhead.hpp)
  double simulation_cpu_seconds = 0;     ///< the rest of the process CPU since the process started
};

/// A running in-situ visualization. Not copyable; all public calls except the accessors are
/// collective over the communicator and must be made by every rank in the same order.
class Session {
 public:
  /// Validates the configuration against the grid (throws panoptes::Error naming the bad key), builds
  /// the rig, the navigation graph and the task list, and creates, replaces or resumes the database as
  /// [output] mode says (rank 0 first, then the other ranks for the movies of the cameras they own;
  /// resume: snapshots() starts at the number the database holds). Single process.
  /// `meter`: the overhead meter to count the session's calls on; a caller that does Panoptes' work
  /// around them (the C API: grid adapters, field bindings) passes its own and brackets its calls with it.
  Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block,
          std::shared_ptr<OverheadMeter> meter = nullptr);
#ifdef PANOPTES_HAVE_MPI
  /// On communicator `comm` (duplicated internally). Every rank passes the same config and grid.
  Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block, MPI_Comm comm,
          std::shared_ptr<OverheadMeter> meter = nullptr);
#endif
  /// A grid that is not a uniform box (rectilinear, spherical, Yin-Yang: grid/grid_description.hpp):
  /// the session owns the grid stage (grid_adapter.hpp), which resamples this rank's `blocks` onto the
  /// uniform cover it renders, at each snapshot (not at steps that take none). Fields are then given
  /// once per block, in the blocks' order. Single process.
  Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
          const ResampleOptions& resample, std::shared_ptr<OverheadMeter> meter = nullptr);
#ifdef PANOPTES_HAVE_MPI
  /// The same on communicator `comm`: the blocks of all ranks partition every patch.
  Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
          const ResampleOptions& resample, MPI_Comm comm, std::shared_ptr<OverheadMeter> meter = nullptr);
#endif
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// True when the schedule asks for a snapshot at this step / simulation time (collective: the ranks
  /// agree on the step and time first, rank_agreement.hpp). Steps count from 0; with
  /// schedule.every_steps = N, steps 0, N, 2N… are due; with every_time = Δt, the first step whose time
  /// reaches 0, Δt, 2Δt… (each once). Throws UsageError for a time that is not finite.
  ///
  /// Every collective call starts with that agreement: when one rank's call fails, or the ranks are out
  /// of step (another call, step, time or grid), every rank's call throws, naming the rank and its
  /// message; a rank waits at most [resources] mpi_timeout seconds for the others. A refused argument
  /// refuses the call on every rank; anything else stops the session (every later call throws).
  bool due(std::int64_t step, double time) const;
  /// Renders and stores one snapshot of `fields` (must include every field a task reads) at
  /// simulation time `time`. Collective. Throws Error on missing fields or exhausted max_snapshots.
  /// After [output] mode = "resume", a snapshot at or before the last time written (a step the
  /// restarted run repeats) is skipped (due() is false for it): the database keeps the first one.
  /// Throws UsageError, writing nothing, for a time that is not finite or not after the previous
  /// snapshot's (other than such a repeat): the manifest would hold null or times out of order.
  void snapshot(double time, const std::vector<FieldInput>& fields);
  /// due() then snapshot(); returns whether a snapshot was taken.
  bool process(std::int64_t step, double time, const std::vector<FieldInput>& fields);
  /// Closes every movie and marks the database complete (collective). Idempotent.
  void finalize();
  /// The caller failed on this rank (a field it could not bind, ...): its next collective call is
  /// refused on every rank with `message`, naming this rank, instead of using what it holds.
  void refuse_next_call(const std::string& message);

  /// Called on the owner rank with every finished frame before it is encoded (tests, previews).
  using FrameObserver = std::function<void(int camera, int task, int frame, const Image& image)>;
  void set_frame_observer(FrameObserver observer);

  int rank() const;
  int ranks() const;
  int camera_count() const;
  int task_count() const;
  int snapshots() const;
  /// Names of the fields the tasks read, in first-use order.
  const std::vector<std::string>& field_names() const;
  const std::string& output_dir() const;
  /// This rank's statistics (peak_rss_bytes refreshed on each call).
  SessionStats stats() const;
  /// The element-wise maximum over ranks of the per-rank times, and sums of the counters (collective).
  SessionStats reduced_stats() const;
  /// Every rank's in-situ overhead (CPU time as the OS counts it, overhead.hpp), in rank order
  /// (collective; call after finalize() for the whole run).
  std::vector<RankOverhead> overhead() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace panoptes::insitu
