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
#include "store/database.hpp"
#include "core/version.hpp"

namespace panoptes::insitu {

using render::Index3;

namespace {
// Rigs of this many cameras or more report the stages of their construction (log level info).
constexpr long long kReportRigCameras = 100000;
}  // namespace

LocalBlock LocalBlock::slab(const render::GridGeometry& g, int axis, int parts, int index, int ghosts) {
  if (axis < 0 || axis > 2 || parts < 1 || index < 0 || index >= parts || parts > g.dims[axis])
    throw Error("LocalBlock::slab: axis " + std::to_string(axis) + ", part " + std::to_string(index) + " of " +
                std::to_string(parts) + " does not fit " + std::to_string(g.dims[axis]) + " points");
  LocalBlock b = whole(g);
  const int n = g.dims[axis];
  const int lo = int(std::int64_t(n) * index / parts), hi = int(std::int64_t(n) * (index + 1) / parts);
  b.offset[axis] = lo;
  b.extent[axis] = hi - lo;
  b.ghost_lo[axis] = std::min(ghosts, lo);
  b.ghost_hi[axis] = std::min(ghosts, n - hi);
  return b;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using halo::Box;
using halo::BlockInfo;
using halo::intersect;

std::int64_t peak_rss() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return std::int64_t(u.ru_maxrss) * 1024;
}

}  // namespace

struct Session::Impl {
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
  // Per owned camera: the partials of each task in rank order, and the empty partial of a camera
  // no brick reaches (members, so their capacity is reused from camera to camera).
  std::vector<std::vector<const render::PartialImage*>> parts;  // [task]
  render::PartialImage empty_partial;
  // Finished frames waiting to be encoded: batch[i][task] of camera batch_camera[i].
  static constexpr int kEncodeBatch = 4;
  std::vector<std::vector<Image>> batch;
  std::vector<int> batch_camera;
  int batch_n = 0;
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
  double global_percentile(int field);
  double window_reference(int field);
  void render_snapshot(int frame);
  void encode_batch();
  void checkpoint(double time);
};

// Every rank's call starts here: a session that stopped throws at once (its ranks agreed on that, or
// a late rank learns it at this call's agreement); the caller's refusal and this rank's failure since
// the last call are told to every rank now.
int Session::Impl::agree(Call call, CallRecord record, std::exception_ptr error, Failure severity, int stop) {
  if (!stopped.empty()) throw Error(stopped);
  record.call = call;
  record.snapshots = snapshots;
  if (!error && !deferred_failure.empty()) {
    error = std::make_exception_ptr(Error(deferred_failure));
    severity = Failure::failed;
  } else if (!error && !caller_refusal.empty()) {
    error = std::make_exception_ptr(UsageError(caller_refusal));
    severity = Failure::refused;
  }
  caller_refusal.clear();
  try {
    return agreement.agree(record, error, severity, stop);
  } catch (const AgreementError& e) {
    if (e.stops()) stopped = std::string("the session stopped: ") + e.what();
    throw;
  } catch (const std::exception& e) {
    if (severity == Failure::failed) stopped = std::string("the session stopped: ") + e.what();
    throw;
  }
}

// What every rank must describe alike: the global grid and a digest of the configuration's fields
// that shape the database (a rank reading another file would write other movies into it).
std::array<double, kShapeValues> Session::Impl::shape() const {
  std::array<double, kShapeValues> v{};
  for (int a = 0; a < 3; ++a) {
    v[std::size_t(a)] = grid.dims[a];
    v[std::size_t(3 + a)] = grid.origin[a];
    v[std::size_t(6 + a)] = grid.spacing[a];
  }
  std::string text = cfg.output_dir + '\n' + cfg.rig + '\n' + std::to_string(cfg.width) + 'x' + std::to_string(cfg.height) +
                     '\n' + to_string(cfg.mode) + '\n' + cfg.projection;
  for (const TaskConfig& t : cfg.tasks) {
    text += '\n' + t.name + ':' + render::to_string(t.kind);
    for (const std::string& f : t.fields) text += ':' + f;
  }
  // 48 bits: exact in a double, which the agreement compares.
  v[kShapeValues - 1] = double(std::hash<std::string>{}(text) & ((std::uint64_t(1) << 48) - 1));
  return v;
}

void Session::Impl::init() {
  // The first agreement: a rank whose configuration or grid is refused, or that describes another
  // grid or configuration than the others, stops every rank here instead of leaving them waiting in
  // the block exchange below (issue 42).
  {
    std::exception_ptr local;
    try {
      cfg.validate();
      grid.validate();
    } catch (...) {
      local = std::current_exception();
    }
    CallRecord start;
    if (!local) start.shape = shape();
    agree(Call::start, start, local, Failure::failed);
  }
  // Every rank's block, for ownership, bricks and the ghost exchange.
  const std::array<int, halo::kPackedInts> mine = halo::pack_block(block);
  std::vector<int> all(halo::kPackedInts * std::size_t(size));
#ifdef PANOPTES_HAVE_MPI
  if (size > 1)
    MPI_Allgather(mine.data(), halo::kPackedInts, MPI_INT, all.data(), halo::kPackedInts, MPI_INT, comm);
  else
#endif
    std::copy(mine.begin(), mine.end(), all.begin());
  std::int64_t points = 0;
  for (int r = 0; r < size; ++r) {
    const LocalBlock b = halo::unpack_block(all.data() + halo::kPackedInts * std::size_t(r));
    halo::validate_block(b, r, grid);
    blocks.push_back(halo::block_info(grid, b));
    points += blocks.back().owned.size();
  }
  const std::int64_t total = std::int64_t(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  bool overlap = false;
  for (int r = 0; r < size; ++r)
    for (int s = r + 1; s < size; ++s)
      if (!intersect(blocks[std::size_t(r)].owned, blocks[std::size_t(s)].owned).empty()) overlap = true;
  if (points != total || overlap)
    throw Error("the local blocks of the " + std::to_string(size) + " ranks do not partition the grid's " +
                std::to_string(total) + " points (they own " + std::to_string(points) + (overlap ? ", overlapping" : "") +
                "): each point must be owned by exactly one rank");
  exchange.blocks = &blocks;
  exchange.rank = rank;
  exchange.size = size;
#ifdef PANOPTES_HAVE_MPI
  exchange.comm = comm;
#endif
  for (int r = 0; r < size; ++r)
    for (int s = 0; s < size; ++s) exchange.needed = exchange.needed || halo::fetches(blocks, r, s);

  plan = TaskPlan(cfg.tasks, grid);
  plan.share_scales(cfg.field_units, cfg.share_scale);
  field_names = plan.field_names();
  // A scale given for a field no task reads is a typo that would silently leave the real field on
  // the default scale.
  for (const auto& [name, fs] : cfg.field_scales)
    if (std::find(field_names.begin(), field_names.end(), name) == field_names.end()) {
      std::string read;
      for (const std::string& f : field_names) read += (read.empty() ? "" : ", ") + f;
      throw Error("render.field." + name + ": no task reads a field named \"" + name + "\" (the tasks read " + read + ")");
    }
  check_resources();
  const camera::Domain domain{grid.domain_lo(), grid.domain_hi() - grid.domain_lo()};
  camera::RigSpec spec = camera::RigSpec::parse(cfg.rig);
  spec.up = {cfg.up[0], cfg.up[1], cfg.up[2]};
  spec.up_axis = cfg.up_axis.empty() ? camera::UpAxis::z_up : camera::parse_up_axis(cfg.up_axis);
  // Large rigs take seconds to build (rig, cameras, navigation graph, manifest): say so as it goes.
  const auto t0 = std::chrono::steady_clock::now();
  const bool report = rank == 0 && spec.kind != camera::RigSpec::Kind::file &&
                      spec.cameras_per_shell() * (long long)spec.radii.size() >= kReportRigCameras;
  auto stage = [&](const std::string& what) {
    if (report)
      log::info("session: " + what + " (" + number_text(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()) +
                " s)");
  };
  stage("building the rig " + cfg.rig);
  rig = camera::make_rig(spec, domain);
  cameras.reserve(std::size_t(rig.size()));
  const camera::Projection projection = camera::parse_projection(cfg.projection);
  for (int c = 0; c < rig.size(); ++c) cameras.push_back(rig.camera(c, cfg.width, cfg.height, projection));
  for (int c = rank; c < rig.size(); c += size) owned.push_back(c);
  references.resize(field_names.size());
  stage(std::to_string(rig.size()) + " cameras placed; building the navigation graph and the manifest");

  OutputGroup group{rank, size};
#ifdef PANOPTES_HAVE_MPI
  group.comm = comm;
#endif
  SessionOutput out = open_session_output(cfg, make_manifest(), owned, group);
  writer = std::move(out.writer);
  if (cfg.mode == OutputMode::resume) {
    // Go on where the database ends: its snapshots count (frame numbers, max_snapshots), the next
    // snapshot of an every_time schedule follows the last one, and running references continue.
    resumed = true;
    snapshots = out.frames;
    if (out.frames > 0) {
      last_time = out.last_time;
      if (cfg.schedule.every_time > 0)
        next_time = (std::floor(last_time / cfg.schedule.every_time + 1e-9) + 1) * cfg.schedule.every_time;
    }
    if (out.references.size() == references.size())
      for (std::size_t f = 0; f < references.size(); ++f) references[f].update(out.references[f]);
  }
  stage("database created");
  const int slots = size;
  partials.assign(std::size_t(slots), std::vector<render::PartialImage>(plan.size()));
  send_buf.resize(std::size_t(slots));
  received.assign(std::size_t(size), std::vector<render::PartialImage>(plan.size()));
  composited.resize(plan.size());
  parts.resize(plan.size());
  batch.assign(kEncodeBatch, std::vector<Image>(plan.size()));
  batch_camera.assign(kEncodeBatch, 0);
}

// Refuses, before the rig, the writers and the buffers exist, a session this rank cannot hold.
// Collective: if any rank refuses, every rank throws (the others would wait for it forever).
void Session::Impl::check_resources() {
  std::string refusal;
  try {
    const long long cameras = rig_camera_count(cfg, grid);
    check_open_streams(cameras, int(plan.size()), size);
    if (cfg.check_memory) {
      const double points = me().has_brick ? double(me().required.size()) : 0.0;
      int sharing = 1;
#ifdef PANOPTES_HAVE_MPI
      if (size > 1) {
        MPI_Comm node;
        MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
        MPI_Comm_size(node, &sharing);
        MPI_Comm_free(&node);
      }
#endif
      refusal = memory_refusal(estimate_session_memory(cfg, points, cameras, size, omp_get_max_threads()),
                               available_memory(), sharing, "this in-situ session",
                               "set check_memory = false in [resources]");
    }
  } catch (const std::exception& e) {
    refusal = e.what();
  }
  int refused = refusal.empty() ? 0 : 1;
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, &refused, 1, MPI_INT, MPI_MAX, comm);
#endif
  if (refused) throw Error(refusal.empty() ? "another rank of this session refused to start (see its message)" : refusal);
}

store::Manifest Session::Impl::make_manifest() const {
  store::Manifest man;
  man.title = cfg.title;
  man.provenance.program = cfg.program;
  man.provenance.version = panoptes::kVersion;
  man.provenance.command_line = cfg.command_line;
  man.provenance.extra["mpi_ranks"] = std::to_string(size);
  man.provenance.extra[kScheduleNote] = schedule_text(cfg.schedule);
  man.domain.dims = {grid.dims[0], grid.dims[1], grid.dims[2]};
  man.domain.origin = grid.origin;
  man.domain.spacing = grid.spacing;
  man.domain.units = cfg.units;
  man.domain.up_axis = cfg.up_axis;
  man.domain.grid = cfg.source_grid;
  man.playback_fps = cfg.playback_fps;
  man.image.width = cfg.width;
  man.image.height = cfg.height;
  man.video = cfg.video;
  man.rig.kind = rig.spec;
  man.rig.parameters = {{"spec", rig.spec}, {"shells", rig.shell_count}};
  // Additive (issue 14): players read the projection and the lattice shape from here; older readers ignore them.
  if (cfg.projection != "perspective") man.rig.parameters["projection"] = cfg.projection;
  if (rig.is_lattice()) man.rig.parameters["lattice"] = rig.lattice;
  if (rig.path) man.rig.parameters["path"] = true;
  const camera::NavigationGraph graph = camera::build_navigation_graph(rig);
  for (int c = 0; c < rig.size(); ++c) {
    const camera::RigCamera& rc = rig.cameras[std::size_t(c)];
    store::CameraEntry e;
    e.id = c;
    e.position = rc.position;
    e.look_at = rc.look_at;
    e.up = rc.up;
    e.fov_y_deg = cameras[std::size_t(c)].fov_y_degrees();
    e.labels.patch = rc.patch;
    e.labels.lat_deg = rc.latitude_deg;
    e.labels.lon_deg = rc.longitude_deg;
    e.labels.shell = rc.shell;
    man.cameras.push_back(e);
    const camera::Neighbours& n = graph.neighbours[std::size_t(c)];
    man.graph.neighbours.push_back({n.left, n.right, n.up, n.down, n.in, n.out});
  }
  for (const PlannedTask& t : plan.tasks()) man.tasks.push_back(t.entry);
  man.axes = plan.axes();
  man.time_units = cfg.time_units;
  for (const std::string& f : field_names) {
    const auto unit = cfg.field_units.find(f);
    man.fields.push_back({f, unit == cfg.field_units.end() ? std::string() : unit->second, {}, to_string(cfg.scale_of(f).mode)});
  }
  return man;
}

// Copies (and converts) every field to float32 over this rank's required point range: the points
// its arrays hold valid values for are read there, the others come from their owners (halo.hpp).
// This rank's fields, checked before the snapshot's first collective (the caller agrees on the
// outcome with the other ranks, so a refusal on one rank cannot leave the others waiting): every field
// a task reads is given, and its strides address the ghosted block without overflowing 64-bit offsets
// (FieldInput carries no size; a wrapped offset would read plane 0 for every z, or far outside).
// This rank's snapshot time: finite, and after the previous snapshot's (a resumed run's repeats were
// skipped before). Checked with the fields, before the snapshot's first collective.
std::exception_ptr Session::Impl::time_refusal(double time) const {
  if (!std::isfinite(time))
    return std::make_exception_ptr(UsageError("snapshot: time " + number_text(time) + "; expected a finite simulation time"));
  if (std::isfinite(last_time) && !(time > last_time))
    return std::make_exception_ptr(UsageError(
        "snapshot: time " + number_text(time) + " is not after the previous snapshot's time " + number_text(last_time) +
        "; snapshot times must increase" +
        (resumed && written > 0 ? " (a resumed run skips only the times it repeats before its first new snapshot)" : "")));
  return nullptr;
}

std::exception_ptr Session::Impl::field_refusal(const std::vector<FieldInput>& fields) const {
  for (const std::string& name : field_names) {
    const FieldInput* in = nullptr;
    for (const FieldInput& x : fields)
      if (x.name == name) in = &x;
    if (!in || !in->data)
      return std::make_exception_ptr(Error("snapshot: field \"" + name + "\" (read by a task) was not given or has no data"));
    const LocalBlock& lb = block;
    const std::array<std::int64_t, 3> st = halo::field_strides(lb, in->stride);
    const std::array<std::int64_t, 3> n{std::int64_t(lb.extent[0]) + lb.ghost_lo[0] + lb.ghost_hi[0],
                                        std::int64_t(lb.extent[1]) + lb.ghost_lo[1] + lb.ghost_hi[1],
                                        std::int64_t(lb.extent[2]) + lb.ghost_lo[2] + lb.ghost_hi[2]};
    const std::int64_t elem = in->type == ScalarType::f64 ? 8 : 4;
    if (!strided_reach(n, st, elem, {lb.ghost_lo[0], lb.ghost_lo[1], lb.ghost_lo[2]}))
      return std::make_exception_ptr(UsageError(
          "snapshot: field \"" + name + "\": strides (" + std::to_string(st[0]) + ", " + std::to_string(st[1]) + ", " +
          std::to_string(st[2]) + ") over the ghosted block (" + std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " +
          std::to_string(n[2]) + ") reach further than 64-bit offsets can address; expected the strides of an array in memory"));
  }
  return nullptr;
}

void Session::Impl::load_fields(const std::vector<FieldInput>& fields) {
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  buffers.resize(field_names.size());
  std::vector<const FieldInput*> inputs(field_names.size());
  for (std::size_t f = 0; f < field_names.size(); ++f) {
    for (const FieldInput& in : fields)
      if (in.name == field_names[f]) inputs[f] = &in;
    if (!inputs[f] || !inputs[f]->data)  // refused by field_refusal() before the snapshot's collectives
      throw Error("snapshot: field \"" + field_names[f] + "\" (read by a task) was not given or has no data");
    buffers[f].resize(std::size_t(req.size()));
  }
  exchange.load(inputs, req, buffers);
  prepared.clear();
  if (b.has_brick) {
    render::PointRange pr{req.lo, req.hi};
    std::vector<render::FieldView> views;
    for (std::size_t f = 0; f < field_names.size(); ++f)
      views.push_back(render::FieldView::of_brick(grid, b.brick, pr, buffers[f].data()));
    // Every camera renders every task in one march: the fields the volume tasks read together get
    // one interleaved corner copy (render::prepare_fields()).
    std::vector<render::TaskSpec> uses;
    for (const PlannedTask& t : plan.tasks()) uses.push_back(t.spec);
    prepared = render::prepare_fields(views, uses);
  }
}

// The q-quantile of |v| over a fixed lattice of global points (the same set whatever the
// decomposition, so the reference — and every image — does not depend on the number of ranks).
double Session::Impl::global_percentile(int f) {
  const std::int64_t total = std::int64_t(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  const int s = std::max(1, int(std::ceil(std::cbrt(double(total) / 65536.0))));
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  const Index3 rd{req.hi[0] - req.lo[0], req.hi[1] - req.lo[1], req.hi[2] - req.lo[2]};
  std::vector<float> mine;
  const std::vector<float>& buf = buffers[std::size_t(f)];
  auto first = [&](int lo) { return (lo + s - 1) / s * s; };
  for (int k = first(b.owned.lo[2]); k < b.owned.hi[2]; k += s)
    for (int j = first(b.owned.lo[1]); j < b.owned.hi[1]; j += s)
      for (int i = first(b.owned.lo[0]); i < b.owned.hi[0]; i += s)
      {
        // NaN and infinite values (rendered as empty) are no reference: an all-NaN volume gave a NaN window.
        const float v = std::fabs(buf[std::size_t((std::int64_t(k - req.lo[2]) * rd[1] + (j - req.lo[1])) * rd[0] +
                                                  (i - req.lo[0]))]);
        if (std::isfinite(v)) mine.push_back(v);
      }
  std::vector<float> all;
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) {
    int n = int(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
    int sum = 0;
    for (int r = 0; r < size; ++r) displs[std::size_t(r)] = sum, sum += counts[std::size_t(r)];
    all.resize(std::size_t(sum));
    MPI_Allgatherv(mine.data(), n, MPI_FLOAT, all.data(), counts.data(), displs.data(), MPI_FLOAT, comm);
  } else
#endif
    all = std::move(mine);
  if (all.empty()) return 0;
  const std::size_t idx = std::size_t(std::llround(cfg.percentile * double(all.size() - 1)));
  std::nth_element(all.begin(), all.begin() + std::ptrdiff_t(idx), all.end());
  return all[idx];
}

// The reference relative windows are multiples of: this snapshot's percentile of |v|, but at least
// kReferenceFloor x its maximum |v| (over every owned cell). While the waves fill fewer than 1 - percentile
// of the samples (the demo's first snapshot, t = 0.32 s: the source region is ~0.1 % of the grid), the
// percentile lands in the numerical precursor ahead of them, ~1e-4 x the maximum, and a window relative
// to it lit the whole box (24 % of the pixels against 0.4 % at the next snapshot). The floor was 0.001
// while windows reached up to 1 x the reference; on the running scale (issue 41) the demo's windows end at
// 0.05-0.15 x it, so the precursor at the first snapshot must sit below 0.1 x 0.05 x the floor: at 0.001
// the first p+s frame was lit on 242,564 of 936,000 pixels against 8,493 at the next (cli.demo_first_frame),
// at 0.02 it is clean. The cost: near the source the floor, not the percentile, sets phi_p's running
// maximum (4.6e-4 against 1.5e-4 1/s in the demo; phi_s's, 6.4e-4, and so the shared p+s scale, are
// unchanged), which the demo's p-wave window [0, 0.05] allows for.
double Session::Impl::window_reference(int f) {
  constexpr double kReferenceFloor = 0.02;
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  const Index3 rd{req.hi[0] - req.lo[0], req.hi[1] - req.lo[1], req.hi[2] - req.lo[2]};
  const std::vector<float>& buf = buffers[std::size_t(f)];
  float peak = 0;
  for (int k = b.owned.lo[2]; k < b.owned.hi[2]; ++k)
    for (int j = b.owned.lo[1]; j < b.owned.hi[1]; ++j) {
      const std::size_t row = std::size_t((std::int64_t(k - req.lo[2]) * rd[1] + (j - req.lo[1])) * rd[0]);
      for (int i = b.owned.lo[0]; i < b.owned.hi[0]; ++i)
        if (const float v = std::fabs(buf[row + std::size_t(i - req.lo[0])]); std::isfinite(v)) peak = std::max(peak, v);
    }
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, &peak, 1, MPI_FLOAT, MPI_MAX, comm);
#endif
  return std::max(global_percentile(f), kReferenceFloor * double(peak));
}

namespace {

void pack(const render::PartialImage& p, std::vector<char>& out) {
  const std::int32_t rect[4] = {p.rect.x0, p.rect.y0, p.rect.x1, p.rect.y1};
  const std::size_t n = p.rect.empty() ? 0 : std::size_t(p.rect.width()) * std::size_t(p.rect.height());
  const std::size_t at = out.size();
  out.resize(at + sizeof rect + n * 5 * sizeof(float));
  std::memcpy(out.data() + at, rect, sizeof rect);
  if (n) {
    std::memcpy(out.data() + at + sizeof rect, p.rgba.data(), n * 4 * sizeof(float));
    std::memcpy(out.data() + at + sizeof rect + n * 4 * sizeof(float), p.depth.data(), n * sizeof(float));
  }
}

const char* unpack(const char* in, const char* end, int width, int height, render::PartialImage& p) {
  std::int32_t rect[4];
  if (end - in < std::ptrdiff_t(sizeof rect)) throw Error("in-situ compositing: truncated partial-image message");
  std::memcpy(rect, in, sizeof rect);
  in += sizeof rect;
  p.reset(width, height, {rect[0], rect[1], rect[2], rect[3]});
  const std::size_t n = p.rect.empty() ? 0 : std::size_t(p.rect.width()) * std::size_t(p.rect.height());
  if (end - in < std::ptrdiff_t(n * 5 * sizeof(float))) throw Error("in-situ compositing: truncated partial-image message");
  if (n) {
    std::memcpy(p.rgba.data(), in, n * 4 * sizeof(float));
    std::memcpy(p.depth.data(), in + n * 4 * sizeof(float), n * sizeof(float));
  }
  return in + n * 5 * sizeof(float);
}

}  // namespace

void Session::Impl::render_snapshot(int frame) {
  const int C = rig.size();
  const int K = int(plan.size());
  const bool brick = me().has_brick;
  const render::Rgb bg{cfg.background[0], cfg.background[1], cfg.background[2]};
  render::OutlineStyle outline;
  // In a 360° frame the box edges are arcs, and the horizon and compass show where to turn (issue 32).
  outline.enabled = cfg.outline || (cfg.compass && cfg.projection == "equirectangular");
  outline.box = cfg.outline;
  outline.compass = cfg.compass;
  outline.sky = camera::SkyFrame::of(cfg.up_axis.empty() ? camera::UpAxis::z_up : camera::parse_up_axis(cfg.up_axis));
  for (int r0 = 0; r0 < C; r0 += size) {
    // Render every camera of this round, sending each partial set to its owner at once.
#ifdef PANOPTES_HAVE_MPI
    std::vector<MPI_Request> sends;
#endif
    for (int c = r0; c < std::min(C, r0 + size); ++c) {
      if (!brick) continue;
      const int slot = c - r0;
      auto t0 = Clock::now();
      render::render_brick(cameras[std::size_t(c)], prepared, specs, partials[std::size_t(slot)], cfg.render);
      time.render += since(t0);
      if (owner(c) != rank) {
#ifdef PANOPTES_HAVE_MPI
        t0 = Clock::now();
        std::vector<char>& buf = send_buf[std::size_t(slot)];
        buf.clear();
        for (const auto& p : partials[std::size_t(slot)]) pack(p, buf);
        sends.emplace_back();
        MPI_Isend(buf.data(), int(buf.size()), MPI_BYTE, owner(c), 11, comm, &sends.back());
        time.composite += since(t0);
#endif
      }
    }
    const int mine = r0 + rank;
    if (mine < C) {
      auto t0 = Clock::now();
      // Partials of my camera in rank order (a deterministic order: composite() sorts per pixel).
      for (auto& p : parts) p.clear();
      for (int s = 0; s < size; ++s) {
        if (!blocks[std::size_t(s)].has_brick) continue;
        if (s == rank) {
          for (int t = 0; t < K; ++t) parts[std::size_t(t)].push_back(&partials[std::size_t(rank)][std::size_t(t)]);
          continue;
        }
#ifdef PANOPTES_HAVE_MPI
        MPI_Status st;
        MPI_Probe(s, 11, comm, &st);
        int bytes = 0;
        MPI_Get_count(&st, MPI_BYTE, &bytes);
        recv_buf.resize(std::size_t(bytes));
        MPI_Recv(recv_buf.data(), bytes, MPI_BYTE, s, 11, comm, MPI_STATUS_IGNORE);
        const char* p = recv_buf.data();
        const char* end = p + bytes;
        for (int t = 0; t < K; ++t) {
          p = unpack(p, end, cfg.width, cfg.height, received[std::size_t(s)][std::size_t(t)]);
          parts[std::size_t(t)].push_back(&received[std::size_t(s)][std::size_t(t)]);
        }
#endif
      }
      const camera::Camera& cam = cameras[std::size_t(mine)];
      // One task at a time: composite() and finish_image() are parallel over pixels, which keeps
      // both cores busy for any K (a loop over K = 3 tasks on 2 threads left one idle a third of the time).
      std::vector<Image>& images = batch[std::size_t(batch_n)];
      for (int t = 0; t < K; ++t) {
        const std::vector<const render::PartialImage*>& p = parts[std::size_t(t)];
        Image& out = images[std::size_t(t)];
        if (p.empty()) {
          empty_partial.reset(cfg.width, cfg.height, {0, 0, 0, 0});
          render::finish_image_into(empty_partial, cam, grid, out, bg, outline);
        } else if (p.size() == 1) {
          render::finish_image_into(*p[0], cam, grid, out, bg, outline);
        } else {
          render::composite_into(p, composited[std::size_t(t)]);
          render::finish_image_into(composited[std::size_t(t)], cam, grid, out, bg, outline);
        }
      }
      time.composite += since(t0);
      if (observer)
        for (int t = 0; t < K; ++t) observer(mine, t, frame, images[std::size_t(t)]);
      batch_camera[std::size_t(batch_n)] = mine;
      if (++batch_n == int(batch.size())) encode_batch();
    }
#ifdef PANOPTES_HAVE_MPI
    if (!sends.empty()) {
      auto t0 = Clock::now();
      MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
      time.composite += since(t0);
    }
#endif
  }
  encode_batch();
}

void Session::Impl::encode_batch() {
  // After a failed append this rank encodes no more (its movies are incomplete), but it goes on with
  // the snapshot's exchanges: the other ranks wait for its partial images, and the snapshot's last
  // agreement tells them all of the failure (issue 42: a full disk on one rank hung the others).
  if (!deferred_failure.empty()) batch_n = 0;
  if (batch_n == 0) return;
  const auto t0 = Clock::now();
  const int K = int(plan.size());
  store::DatabaseWriter& w = *writer;
  // Frames of several cameras in one parallel loop: appends to different streams may run
  // concurrently, and batch_n × K frames share the threads evenly where K alone would not.
  // An exception must not leave an OpenMP region (the process would terminate): the first one is
  // kept and rethrown after the loop, e.g. a full disk as the FileError naming the movie.
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic)
  for (int f = 0; f < batch_n * K; ++f) {
    try {
      w.append(batch_camera[std::size_t(f / K)], f % K, batch[std::size_t(f / K)][std::size_t(f % K)]);
    } catch (...) {
#pragma omp critical(panoptes_encode_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) {
    deferred_failure = "encoding on rank " + std::to_string(rank) + " failed: " + exception_message(error);
    batch_n = 0;
    return;
  }
  frames_encoded += std::int64_t(batch_n) * K;
  batch_n = 0;
  time.encode += since(t0);
}

void Session::Impl::checkpoint(double t) {
  auto t0 = Clock::now();
  int frames = INT_MAX;
  std::exception_ptr local;
  try {
    if (writer) {
      writer->flush();
      if (!owned.empty()) frames = writer->complete_frames();
    }
  } catch (...) {
    local = std::current_exception();
  }
  // Every rank's encoding and flushing went well, or every rank learns which failed (this rank's
  // failed appends are in deferred_failure, which agree() reports).
  CallRecord r;
  r.time = t;
  r.compare_time = true;
  agree(Call::frames, r, local, Failure::failed);
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, &frames, 1, MPI_INT, MPI_MIN, comm);
#endif
  if (rank == 0) {
    try {
      writer->set_time(snapshots - 1, t);
      {  // every field's running maximum, so a resumed run continues the scale whatever its mode
        std::vector<double> refs;
        for (const render::RunningMax& ref : references) refs.push_back(ref.value());
        writer->set_note(kRunningMaxNote, format_references(refs));
      }
      for (std::size_t f = 0; f < last_references.size(); ++f)
        writer->set_field_reference(snapshots - 1, int(f), last_references[f]);
      writer->checkpoint(frames == INT_MAX ? snapshots : frames);
    } catch (const std::exception& e) {
      // The other ranks have returned: they learn of it at their next call.
      deferred_failure = std::string("rank 0 could not write the manifest: ") + e.what();
      throw;
    }
  }
  time.checkpoint += since(t0);
}

Session::Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block,
                 std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->grid = grid;
  impl_->block = block;
#ifdef PANOPTES_HAVE_MPI
  int init = 0;
  MPI_Initialized(&init);
  if (init) {
    MPI_Comm_dup(MPI_COMM_SELF, &impl_->comm);
  }
#endif
  impl_->init();
}

#ifdef PANOPTES_HAVE_MPI
Session::Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block, MPI_Comm comm,
                 std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->grid = grid;
  impl_->block = block;
  // The agreements' own communicator first: its duplication waits at most the timeout for every rank,
  // so a rank that never starts its session cannot hang the others in the duplication below.
  impl_->agreement = RankAgreement(comm, config.mpi_timeout);
  MPI_Comm_dup(comm, &impl_->comm);
  MPI_Comm_rank(impl_->comm, &impl_->rank);
  MPI_Comm_size(impl_->comm, &impl_->size);
  impl_->init();
}
#endif

// The grid stage's own checks (the source grid, the resampling, the ranks against the cover) are agreed
// before the adapter's collectives: a rank whose grid is refused stops every rank there.
void Session::Impl::start_grid_stage(const grid::GridDescription& source, const std::vector<GridBlock>& grid_blocks,
                                     const ResampleOptions& resample
#ifdef PANOPTES_HAVE_MPI
                                     ,
                                     MPI_Comm user_comm
#endif
) {
  std::exception_ptr local;
  try {
    const render::GridGeometry cover = GridAdapter::cover(source, resample);
    if (agreement.size() > cover.dims[2] - 1)
      throw Error("grid stage: " + std::to_string(agreement.size()) + " ranks for a uniform cover of " +
                  std::to_string(cover.dims[2]) + " points along z; expected at most one rank per cell layer (raise the "
                  "resample points)");
    cfg.source_grid = source.summary();
  } catch (...) {
    local = std::current_exception();
  }
  agree(Call::start, CallRecord{}, local, Failure::failed);
#ifdef PANOPTES_HAVE_MPI
  if (user_comm != MPI_COMM_NULL)
    adapter = std::make_unique<GridAdapter>(source, grid_blocks, resample, user_comm);
  else
#endif
    adapter = std::make_unique<GridAdapter>(source, grid_blocks, resample);
  grid = adapter->render_grid();
  block = adapter->render_block();
}

// A grid stage's fields: each field a task reads, once per block of this rank, with data (checked before
// the snapshot's agreement, like field_refusal()).
std::exception_ptr Session::Impl::grid_field_refusal(const std::vector<FieldInput>& fields) const {
  for (const std::string& name : field_names) {
    int given = 0;
    for (const FieldInput& x : fields)
      if (x.name == name && x.data) ++given;
    if (given != adapter->block_count())
      return std::make_exception_ptr(Error("snapshot: field \"" + name + "\" (read by a task) was given with data for " +
                                           std::to_string(given) + " of this rank's " + std::to_string(adapter->block_count()) +
                                           " block(s); expected one per block"));
  }
  return nullptr;
}

Session::Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                 const ResampleOptions& resample, std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
#ifdef PANOPTES_HAVE_MPI
  impl_->start_grid_stage(source, blocks, resample, MPI_COMM_NULL);
  int init = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_dup(MPI_COMM_SELF, &impl_->comm);
#else
  impl_->start_grid_stage(source, blocks, resample);
#endif
  impl_->init();
}

#ifdef PANOPTES_HAVE_MPI
Session::Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                 const ResampleOptions& resample, MPI_Comm comm, std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->agreement = RankAgreement(comm, config.mpi_timeout);
  impl_->start_grid_stage(source, blocks, resample, comm);
  MPI_Comm_dup(comm, &impl_->comm);
  MPI_Comm_rank(impl_->comm, &impl_->rank);
  MPI_Comm_size(impl_->comm, &impl_->size);
  impl_->init();
}
#endif

Session::~Session() {
#ifdef PANOPTES_HAVE_MPI
  if (impl_ && impl_->comm != MPI_COMM_NULL) {
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Comm_free(&impl_->comm);
  }
#endif
}

// The schedule's answer on this rank (the agreement before it made every rank's arguments and state alike).
bool Session::Impl::due_here(std::int64_t step, double time) const {
  const ScheduleConfig& s = cfg.schedule;
  if (finalized) return false;
  if (s.max_snapshots > 0 && snapshots >= s.max_snapshots) return false;
  if (repeated(time)) return false;
  if (s.every_steps > 0) return step % s.every_steps == 0;
  return time >= next_time - 1e-9 * s.every_time;
}

namespace {
std::exception_ptr finite_refusal(const char* call, double time) {
  if (std::isfinite(time)) return nullptr;
  return std::make_exception_ptr(UsageError(std::string(call) + ": time " + number_text(time) +
                                            "; expected a finite simulation time"));
}
}  // namespace

bool Session::due(std::int64_t step, double time) const {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);
  // Collective (issue 42): ranks that disagree here (another step or time, a skipped call) would take
  // different snapshots and wait for each other in the next one.
  CallRecord r;
  r.step = step;
  r.time = time;
  r.compare_time = true;
  m.agree(Call::due, r, finite_refusal("due", time), Failure::refused);
  return m.due_here(step, time);
}

void Session::snapshot(double time, const std::vector<FieldInput>& fields) {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);  // also when it throws
  m.take_snapshot(time, fields);
}

void Session::Impl::take_snapshot(double time, const std::vector<FieldInput>& fields) {
  Impl& m = *this;
  if (m.finalized) throw Error("snapshot: the session is finalized");
  // [output] mode = "resume": a restarted run repeats the steps since its checkpoint; what the
  // database already holds is not written twice (the same time on every rank: the same decision).
  // NaN is never a repeat: it is refused below.
  const bool repeat = m.repeated(time);
  // The time and the fields are this rank's own arguments (another rank's may be fine): every rank
  // learns in the snapshot's agreement whether any refused its own, and then all refuse this snapshot
  // instead of waiting for that rank in the snapshot's collectives. SIGINT/SIGTERM (when the program
  // installed core/stop_request.hpp's handlers, as `panoptes run` does) is agreed there too: every
  // rank stops before this snapshot; the writer's destructor marks the database interrupted.
  std::exception_ptr refusal;
  if (!repeat) {
    refusal = m.time_refusal(time);
    if (!refusal) refusal = m.adapter ? m.grid_field_refusal(fields) : m.field_refusal(fields);
  }
  CallRecord r;
  r.time = time;
  r.compare_time = true;
  const int stop = m.agree(Call::snapshot, r, refusal, Failure::refused, stop_requested());
  if (stop)
    throw Interrupted(stop, m.cfg.output_dir + ": stopped by " + signal_name(stop) + " before snapshot " +
                                std::to_string(m.snapshots) + "; the database is marked interrupted");
  if (repeat) {
    if (m.rank == 0)
      log::info(m.cfg.output_dir + ": snapshot at time " + number_text(time) + " skipped: the resumed database already holds "
                "snapshots up to time " + number_text(m.last_time));
    return;
  }
  if (m.cfg.schedule.max_snapshots > 0 && m.snapshots >= m.cfg.schedule.max_snapshots)
    throw Error("snapshot: schedule.max_snapshots = " + std::to_string(m.cfg.schedule.max_snapshots) + " already taken");
  auto t0 = Clock::now();
  // The grid stage (collective: it gathers the source points each slab needs) only for a snapshot.
  m.load_fields(m.adapter ? m.adapter->adapt(fields) : fields);
  std::vector<double> ref(m.field_names.size());
  for (std::size_t f = 0; f < m.field_names.size(); ++f) {
    const FieldScale scale = m.cfg.scale_of(m.field_names[f]);
    if (scale.mode == ReferenceMode::fixed) {
      ref[f] = scale.value;  // the same on every rank: no quantile, no collective
      continue;
    }
    const double q = m.window_reference(int(f));
    const double running = m.references[f].update(q);
    ref[f] = std::max(scale.mode == ReferenceMode::running ? running : q, 1e-30);
  }
  m.last_references = ref;
  m.plan.resolve(ref, m.specs);
  m.time.copy += since(t0);
  m.render_snapshot(m.snapshots);
  ++m.snapshots;
  ++m.written;
  m.last_time = time;
  if (m.cfg.schedule.every_time > 0)
    m.next_time = (std::floor(time / m.cfg.schedule.every_time + 1e-9) + 1) * m.cfg.schedule.every_time;
  m.checkpoint(time);
}

bool Session::process(std::int64_t step, double time, const std::vector<FieldInput>& fields) {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);
  // One agreement every step (a few microseconds): a rank that skips a step's call, or passes another
  // step or time, is named at once instead of leaving the others waiting in the next snapshot (issue
  // 42). A time that is not finite is refused on every rank (due() cannot answer for it).
  CallRecord r;
  r.step = step;
  r.time = time;
  r.compare_time = true;
  m.agree(Call::process, r, finite_refusal("process", time), Failure::refused);
  if (!m.due_here(step, time)) return false;
  m.take_snapshot(time, fields);
  return true;
}

void Session::refuse_next_call(const std::string& message) { impl_->caller_refusal = message; }

void Session::finalize() {
  Impl& m = *impl_;
  if (m.finalized) return;
  {
    OverheadMeter::Scope counted(*m.meter);
    int frames = INT_MAX;
    std::exception_ptr local;
    try {
      if (m.writer && !m.owned.empty()) {
        m.writer->flush();
        frames = m.writer->complete_frames();
      }
    } catch (...) {
      local = std::current_exception();
    }
    m.agree(Call::finalize, CallRecord{}, local, Failure::failed);
    m.finalized = true;
#ifdef PANOPTES_HAVE_MPI
    if (m.size > 1) MPI_Allreduce(MPI_IN_PLACE, &frames, 1, MPI_INT, MPI_MIN, m.comm);
#endif
    if (m.rank != 0 && m.writer) m.writer->finalize();
    m.barrier();
    if (m.rank == 0) m.writer->finalize(frames == INT_MAX ? m.snapshots : frames);
    m.barrier();
  }
  m.meter->stop();  // the run's end for the report
}

void Session::set_frame_observer(FrameObserver observer) { impl_->observer = std::move(observer); }
int Session::rank() const { return impl_->rank; }
int Session::ranks() const { return impl_->size; }
int Session::camera_count() const { return impl_->rig.size(); }
int Session::task_count() const { return int(impl_->plan.size()); }
int Session::snapshots() const { return impl_->snapshots; }
const std::vector<std::string>& Session::field_names() const { return impl_->field_names; }
const std::string& Session::output_dir() const { return impl_->cfg.output_dir; }

SessionStats Session::stats() const {
  const Impl& m = *impl_;
  SessionStats s;
  s.snapshots = m.snapshots;
  s.frames_encoded = m.frames_encoded;
  s.owned_cameras = int(m.owned.size());
  for (const auto& b : m.buffers) s.field_buffer_bytes += std::int64_t(b.capacity() * sizeof(float));
  for (const auto& p : m.prepared) s.field_buffer_bytes += std::int64_t(p.corners.bytes());
  auto add = [&](const render::PartialImage& p) {
    s.partial_buffer_bytes += std::int64_t((p.rgba.capacity() + p.depth.capacity()) * sizeof(float));
  };
  for (const auto& v : m.partials)
    for (const auto& p : v) add(p);
  for (const auto& v : m.received)
    for (const auto& p : v) add(p);
  for (const auto& p : m.composited) add(p);
  for (const auto& b : m.send_buf) s.partial_buffer_bytes += std::int64_t(b.capacity());
  s.partial_buffer_bytes += std::int64_t(m.recv_buf.capacity());
  s.peak_rss_bytes = peak_rss();
  s.time = m.time;
  const RankOverhead o = m.meter->read();
  s.session_seconds = o.visualization_wall_s;
  s.elapsed_seconds = o.elapsed_wall_s;
  s.visualization_cpu_seconds = o.visualization_cpu_s;
  s.simulation_cpu_seconds = o.simulation_cpu_s;
  return s;
}

std::vector<RankOverhead> Session::overhead() const {
  RankOverhead mine = impl_->meter->read();
  mine.rank = impl_->rank;
  constexpr int kValues = 4;
  const double values[kValues] = {mine.visualization_cpu_s, mine.simulation_cpu_s, mine.visualization_wall_s,
                                  mine.elapsed_wall_s};
  std::vector<double> all(values, values + kValues);
#ifdef PANOPTES_HAVE_MPI
  Impl& m = *impl_;
  m.agree(Call::report, CallRecord{});
  if (m.size > 1) {
    all.resize(kValues * std::size_t(m.size));
    MPI_Allgather(values, kValues, MPI_DOUBLE, all.data(), kValues, MPI_DOUBLE, m.comm);
  }
#endif
  std::vector<RankOverhead> out;
  for (std::size_t r = 0; r + kValues <= all.size(); r += kValues)
    out.push_back({int(r / kValues), all[r], all[r + 1], all[r + 2], all[r + 3]});
  return out;
}

SessionStats Session::reduced_stats() const {
  SessionStats s = stats();
#ifdef PANOPTES_HAVE_MPI
  Impl& m = *impl_;
  m.agree(Call::report, CallRecord{});
  if (m.size > 1) {
    double t[5] = {s.time.copy, s.time.render, s.time.composite, s.time.encode, s.time.checkpoint};
    MPI_Allreduce(MPI_IN_PLACE, t, 5, MPI_DOUBLE, MPI_MAX, m.comm);
    s.time = {t[0], t[1], t[2], t[3], t[4]};
    std::int64_t c[2] = {s.frames_encoded, s.owned_cameras};
    MPI_Allreduce(MPI_IN_PLACE, c, 2, MPI_INT64_T, MPI_SUM, m.comm);
    s.frames_encoded = c[0];
    s.owned_cameras = int(c[1]);
    std::int64_t mx[3] = {s.field_buffer_bytes, s.partial_buffer_bytes, s.peak_rss_bytes};
    MPI_Allreduce(MPI_IN_PLACE, mx, 3, MPI_INT64_T, MPI_MAX, m.comm);
    s.field_buffer_bytes = mx[0];
    s.partial_buffer_bytes = mx[1];
    s.peak_rss_bytes = mx[2];
  }
#endif
  return s;
}

}  // namespace panoptes::insitu
