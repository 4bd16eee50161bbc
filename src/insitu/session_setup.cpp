#include "insitu/session_impl.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>

namespace panoptes::insitu {

namespace {
// Rigs of this many cameras or more report the stages of their construction (log level info).
constexpr long long kReportRigCameras = 100000;
}  // namespace

// What every rank must describe alike: the global grid and a digest of the configuration's fields
// that shape the database (a rank reading another file would write other movies into it).
std::array<double, kShapeValues> Session::Impl::shape() const {
  std::array<double, kShapeValues> v{};
  for (int a = 0; a < 3; ++a) {
    v[std::size_t(a)] = grid.dims[a];
    v[std::size_t(3 + a)] = grid.origin[a];
    v[std::size_t(6 + a)] = grid.spacing[a];
  }
  // [resources] parallel too: ranks that split the rendering differently would wait for each other.
  std::string text = cfg.output_dir + '\n' + to_string(cfg.parallel) + '\n' + cfg.rig + '\n' + std::to_string(cfg.width) + 'x' + std::to_string(cfg.height) +
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
  // Cameras split: every rank's brick becomes the whole grid, so the exchange below fetches every
  // point each rank does not own and render_snapshot() renders whole rays with nothing to composite.
  // (A rig that cannot be read counts no cameras here; check_resources() refuses it on every rank.)
  long long rig_cameras = 0;
  try {
    rig_cameras = rig_camera_count(cfg, grid);
  } catch (const std::exception&) {
  }
  split = choose_render_split(cfg, grid, rig_cameras, size);
  if (split == RenderSplit::cameras) {
    const BlockInfo whole = halo::block_info(grid, LocalBlock::whole(grid));
    for (BlockInfo& b : blocks) {
      b.brick = whole.brick;
      b.has_brick = whole.has_brick;
      b.required = whole.required;
    }
  }
  if (rank == 0 && size > 1)
    log::info("session: " + std::to_string(size) + " ranks split the rendering by " +
              (split == RenderSplit::cameras ? "cameras (each gathers the whole grid's fields)" : "bricks (sort-last)"));
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
  const int slots = split == RenderSplit::cameras ? 1 : size;
  partials.assign(std::size_t(slots), std::vector<render::PartialImage>(plan.size()));
  send_buf.resize(std::size_t(slots));
  received.assign(std::size_t(size), std::vector<render::PartialImage>(plan.size()));
  composited.resize(plan.size());
  parts.resize(plan.size());
  batch_camera.assign(kEncodeBatch, 0);
  // A whole-domain brick on one rank rendering one sweep: render_sweep(), frames task by task.
  sweep = sweep_rendering(cfg, size) && me().has_brick && me().brick == render::Brick::whole(grid);
  if (!sweep) {
    batch.assign(kEncodeBatch, std::vector<Image>(plan.size()));
  } else {
    partials.clear(), received.clear(), composited.clear(), parts.clear();
  }
}

// Refuses, before the rig, the writers and the buffers exist, a session this rank cannot hold.
// Collective: if any rank refuses, every rank throws (the others would wait for it forever).
void Session::Impl::check_resources() {
  std::string refusal;
  try {
    const long long cameras = rig_camera_count(cfg, grid);
    check_open_streams(cameras, int(plan.size()), size, packed_layout(cfg, cameras * (long long)plan.size()));
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
  if (size > 1) man.provenance.extra["mpi_split"] = to_string(split);
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
    // The grid stage and the session it feeds, before either is built (a cover of 1024^3 points ended in
    // a bare "out of memory"); check_resources() below repeats the session's part for every grid.
    if (cfg.check_memory) {
      const double cover_points = double(cover.dims[0]) * cover.dims[1] * cover.dims[2];
      const double source_points = double(source.points_per_patch()) * source.patches();
      const int ranks = agreement.size();
      int fields = 0;
      {
        std::vector<std::string> names;
        for (const TaskConfig& t : cfg.tasks)
          for (const std::string& f : t.fields)
            if (std::find(names.begin(), names.end(), f) == names.end()) names.push_back(f);
        fields = int(names.size());
      }
      MemoryEstimate e = estimate_session_memory(cfg, cover_points / ranks * 1.1, rig_camera_count(cfg, cover), ranks,
                                                 omp_get_max_threads());
      e.add(estimate_grid_stage_memory(source_points, cover_points, ranks, fields));
      const std::string refusal = memory_refusal(e, available_memory(), 1, "this in-situ session with its grid stage",
                                                 "set check_memory = false in [resources]");
      if (!refusal.empty()) throw Error(refusal);
    }
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

}  // namespace panoptes::insitu
