#pragma once
// Session's private state, shared by the three files that implement it:
//   session.cpp         the public calls, each opening with the ranks' agreement (rank_agreement.hpp)
//   session_setup.cpp   the start: the grid stage, the rig, the task plan, resources, the database
//   session_frames.cpp  one snapshot: fields in, references, images rendered, composited, encoded,
//                       and the checkpoint
//   session_bands.cpp   compositing in bands of rows when ranks outnumber cameras

#include "insitu/session.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <ctime>
#include <exception>
#include <map>
#include <optional>
#include <sstream>

#include <omp.h>

#include "camera/navigation.hpp"
#include "camera/orientation.hpp"
#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/log.hpp"
#include "core/number_text.hpp"
#include "core/strided.hpp"
#include "grid/grid_description.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/halo.hpp"
#include "insitu/output.hpp"
#include "insitu/rank_agreement.hpp"
#include "insitu/resources.hpp"
#include "insitu/task_plan.hpp"
#include "render/renderer.hpp"
#include "render/sweep.hpp"
#include "store/database.hpp"
#include "core/version.hpp"

namespace panoptes::insitu {

/// The outline and compass of the session's frames, as the configuration asks.
render::OutlineStyle outline_style(const SessionConfig& config);

struct Session::Impl {
  using Clock = std::chrono::steady_clock;
  using Box = halo::Box;
  using BlockInfo = halo::BlockInfo;
  using Index3 = render::Index3;
  static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
  static std::int64_t peak_rss() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return std::int64_t(u.ru_maxrss) * 1024;
  }

  SessionConfig cfg;
  render::GridGeometry grid;
  LocalBlock block;
  int rank = 0, size = 1;
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm = MPI_COMM_NULL;
#endif
  // Every collective call starts with an agreement of the ranks (rank_agreement.hpp).
  RankAgreement agreement;
  std::string stopped;          // why the session cannot go on (every later call throws it)
  std::string caller_refusal;   // the caller's own failure, refused on every rank at the next call
  std::string deferred_failure; // this rank's failure after an agreement, reported at the next one
  // A grid that is not a uniform box: the grid stage resamples the caller's blocks at each snapshot.
  std::unique_ptr<GridAdapter> adapter;
  std::vector<BlockInfo> blocks;  // per rank
  halo::Exchange exchange;        // reads the trusted points, fetches the others
  std::vector<std::string> field_names;
  TaskPlan plan;  // the tasks, their windows' references, axes and manifest entries
  std::vector<render::TaskSpec> specs;  // per snapshot, references resolved
  camera::Rig rig;
  std::vector<camera::Camera> cameras;
  std::optional<store::DatabaseWriter> writer;
  std::vector<int> owned;
  RenderSplit split = RenderSplit::bricks;  // how the ranks share the rendering (choose_render_split())
  int snapshots = 0;
  double next_time = 0;
  // The time of the last snapshot written (this run's or, after a resume, the database's): snapshot
  // times must increase. Resume: until the restarted run writes its first snapshot, its times at or
  // before the database's last one are the steps it repeats since its checkpoint and are skipped;
  // once it has written one, a time that goes back is a mistake like in any run.
  bool resumed = false;
  int written = 0;  // snapshots written by this run
  double last_time = -INFINITY;
  bool finalized = false;
  FrameObserver observer;

  std::vector<std::vector<float>> buffers;  // per field, over blocks[rank].required
  std::vector<render::PreparedField> prepared;
  std::vector<render::RunningMax> references;
  std::vector<double> last_references;  // per field, this snapshot's (recorded in the manifest)
  std::vector<std::vector<render::PartialImage>> partials;  // [slot][task]
  std::vector<std::vector<char>> send_buf;                  // [slot]
  std::vector<char> recv_buf;
  std::vector<std::vector<render::PartialImage>> received;  // [rank][task]
  std::vector<render::PartialImage> composited;
  // [task][frame]: 1 once some camera of this rank showed something of the task in the frame (a pixel
  // more than 2/255 opaque); reduced over ranks at finalize for the "nothing visible" warning.
  std::vector<std::vector<char>> shown;
  void note_shown(int task, int frame, const render::PartialImage& p);
  // Rank 0 warns of tasks that showed nothing in many frames (collective).
  void warn_invisible_tasks();
  // Per owned camera: the partials of each task in rank order, and the empty partial of a camera
  // no brick reaches (members, so their capacity is reused from camera to camera).
  std::vector<std::vector<const render::PartialImage*>> parts;  // [task]
  render::PartialImage empty_partial;
  // Band compositing (more ranks than cameras, render_snapshot_banded): messages out and in, the
  // partials of one band by sender, and one finished task image of a band.
  std::vector<std::vector<char>> band_send, band_recv;
  std::vector<std::vector<render::PartialImage>> band_parts;  // [sender][task]
  Image band_image;
  // Finished frames waiting to be encoded: batch[i][task] of camera batch_camera[i].
  static constexpr int kEncodeBatch = 4;
  std::vector<std::vector<Image>> batch;
  std::vector<int> batch_camera;
  int batch_n = 0;
  // One rank, one sweep (sweep_rendering()): each camera's frames come from render::render_sweep()
  // in 8 bits, and are finished and encoded task by task from there, so the session holds one
  // camera's sweep frames and a partial and a frame per thread instead of K of each per camera.
  bool sweep = false;
  render::SweepFrames sweep_frames;
  std::int64_t frames_encoded = 0;
  Timings time;
  // The in-situ overhead: CPU time of the process (all threads) inside the session's calls on this
  // rank (construction, snapshots, finalize) and of Panoptes' own threads between them, against the
  // rest of the process's CPU time (overhead.hpp says how threads are attributed).
  std::shared_ptr<OverheadMeter> meter;

  int owner(int camera) const { return camera % size; }
  const BlockInfo& me() const { return blocks[std::size_t(rank)]; }

  void barrier() {
#ifdef PANOPTES_HAVE_MPI
    if (size > 1) MPI_Barrier(comm);
#endif
  }

  void init();
  void start_grid_stage(const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                        const ResampleOptions& resample
#ifdef PANOPTES_HAVE_MPI
                        ,
                        MPI_Comm comm  // MPI_COMM_NULL: one process
#endif
  );
  std::exception_ptr grid_field_refusal(const std::vector<FieldInput>& fields) const;
  int agree(Call call, CallRecord record, std::exception_ptr error = nullptr, Failure severity = Failure::none,
            int stop = 0);
  std::array<double, kShapeValues> shape() const;
  bool due_here(std::int64_t step, double time) const;
  void take_snapshot(double time, const std::vector<FieldInput>& fields);
  bool repeated(double time) const {
    return resumed && written == 0 && std::isfinite(last_time) && time <= last_time + 1e-9 * std::fabs(last_time);
  }
  // NaN or ±inf would be stored as null in the manifest, which then no reader accepts.
  static void check_finite(const char* call, double time) {
    if (!std::isfinite(time))
      throw UsageError(std::string(call) + ": time " + number_text(time) + "; expected a finite simulation time");
  }
  void check_resources();
  store::Manifest make_manifest() const;
  std::exception_ptr time_refusal(double time) const;
  std::exception_ptr field_refusal(const std::vector<FieldInput>& fields) const;
  void load_fields(const std::vector<FieldInput>& fields);
  // The render's prepared fields (corner copies) of the loaded buffers, for `specs` as resolved.
  void prepare_fields();
  double global_percentile(int field);
  double window_reference(int field);
  void render_snapshot(int frame);
#ifdef PANOPTES_HAVE_MPI
  void render_snapshot_banded(int frame);
#endif
  void render_own_cameras(int frame);  // RenderSplit::cameras
  // Finishes camera `camera`'s images from parts[] (each task's partials), hands them to the observer
  // and queues them for encoding (the caller encodes a full batch).
  void finish_camera(int camera, int frame);
  void encode_batch();
  void render_sweep_snapshot(int frame);
  void checkpoint(double time);
};

}  // namespace panoptes::insitu
