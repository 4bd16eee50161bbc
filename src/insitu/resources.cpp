#include "insitu/resources.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "camera/volume_rigs.hpp"
#include "core/error.hpp"
#include "insitu/task_plan.hpp"
#include "render/renderer.hpp"
#include "store/database.hpp"
#include "video/writer_memory.hpp"

namespace panoptes::insitu {

namespace {
// Rig camera, render camera, manifest entry, navigation graph row and its build, camera table row:
// measured as the resident growth of `panoptes rig fibonacci:N` and Session construction (see
// docs/insitu.md, "Resources"), rounded up.
constexpr double kBytesPerCamera = 1500;
}  // namespace

MemoryEstimate estimate_session_memory(const SessionConfig& cfg, double block_points, long long cameras, int ranks,
                                       int encode_threads) {
  ranks = std::max(ranks, 1);
  std::vector<std::string> fields;
  for (const TaskConfig& t : cfg.tasks)
    for (const auto& f : t.fields)
      if (std::find(fields.begin(), fields.end(), f) == fields.end()) fields.push_back(f);
  double tasks = 0;  // sweeps expand to one task per value
  for (const TaskConfig& t : cfg.tasks)
    tasks += double(std::max<std::size_t>(1, planned_task_count(t)));
  const double px = double(cfg.width) * cfg.height;
  const double owned = std::ceil(double(cameras) / ranks);
  MemoryEstimate e;
  // float32 copy of each field over the brick, its macro-cell min/max and the ghost exchange.
  e.add("field copies", double(fields.size()) * block_points * (4 + 1));
  // The march's 16-bit corner copy (render/corner_field.hpp: 16 B per cell) of every field a
  // volume-rendering task reads; isosurfaces and slices read the float copy. It was missing from the
  // estimate: an 8x200x400 shell rendered on a 400^3 cover peaked at 2.5 GB against an estimated 1.7 GB.
  std::vector<std::string> marched;
  for (const TaskConfig& t : cfg.tasks)
    if (t.kind != render::TaskKind::isosurface && t.kind != render::TaskKind::slice)
      for (const auto& f : t.fields)
        if (std::find(marched.begin(), marched.end(), f) == marched.end()) marched.push_back(f);
  if (!marched.empty()) e.add("corner copies", double(marched.size()) * block_points * 16);
  if (sweep_rendering(cfg, ranks)) {
    // render_sweep(): one camera's frames (4 bytes per pixel and task, isosurfaces 2; a pixel's tasks
    // padded to 64 bytes), and per encoding thread one partial image (20 B/px), one frame (4 B/px) and an
    // encoder; an isosurface sweep also keeps the field's staggered differences (12 B per point).
    const bool iso = cfg.tasks[0].kind == render::TaskKind::isosurface;
    e.add("sweep frames", px * std::ceil((iso ? 2.0 : 4.0) * tasks / 64) * 64);
    e.add("finished frames", std::max(encode_threads, 1) * (px * 24 + video::live_encoder_bytes(px)));
    if (iso) e.add("sweep gradients", block_points * 12);
  } else {
    // Partial images (premultiplied RGBA + depth floats) of one camera round: rendered ones, their
    // send buffers and the received ones, plus the composite; full frames at worst.
    e.add("partial images", (3.0 * ranks + 1) * tasks * px * 20);
    e.add("finished frames", tasks * px * 3 + std::max(encode_threads, 1) * video::live_encoder_bytes(px));
  }
  if (packed_layout(cfg, (long long)(double(cameras) * tasks))) {
    // docs/formats.md, "Packed layout": a 96-byte record and ~13 bytes of heap per idle stream, and the
    // compressed frames of the snapshot until its flush (23 kB per 920x896 frame at crf 23, ~0.03 B per
    // pixel: counted twice over for sharper pictures).
    e.add("packed stream records and pending frames", owned * tasks * (110.0 + 0.06 * px));
  } else {
    e.add("open movie writers", owned * tasks * video::open_writer_bytes(px, cfg.video.gop));
  }
  e.add("rig and manifest", double(cameras) * kBytesPerCamera);
  return e;
}

MemoryEstimate estimate_grid_stage_memory(double source_points, double cover_points, int ranks, int fields) {
  ranks = std::max(ranks, 1);
  const double slab = cover_points / ranks;
  // A slab reads the source points around it: its share, plus the interpolation's neighbours.
  const double source_share = std::min(source_points, source_points / ranks * 1.25 + 4096);
  MemoryEstimate e;
  e.add("grid stage: resampling plan", slab * 14);
  e.add("grid stage: resampled fields", slab * 4 * std::max(fields, 1));
  e.add("grid stage: gathered source points", source_share * 4 * 3);
  return e;
}

bool sweep_rendering(const SessionConfig& cfg, int ranks) {
  if (ranks != 1 || cfg.tasks.size() != 1) return false;
  const TaskConfig& t = cfg.tasks[0];
  const std::size_t K = planned_task_count(t);
  if (K < 2) return false;
  if (t.kind == render::TaskKind::isosurface)
    return !cfg.render.iso_antialias || K > std::size_t(render::kMaxTasksPerMarch);
  return t.kind == render::TaskKind::volume && t.fields.size() == 1;
}

RenderSplit choose_render_split(const SessionConfig& cfg, const render::GridGeometry& grid, long long cameras,
                                int ranks) {
  if (ranks <= 1) return RenderSplit::bricks;
  if (cfg.parallel != RenderSplit::automatic) return cfg.parallel;
  // Fewer cameras than ranks would leave ranks idle while the others march whole rays.
  if (cameras < ranks) return RenderSplit::bricks;
  const double points = double(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  // The same per-point bytes as estimate_session_memory(): 4 + 1 per field, 16 per marched field.
  std::vector<std::string> fields, marched;
  for (const TaskConfig& t : cfg.tasks)
    for (const auto& f : t.fields) {
      if (std::find(fields.begin(), fields.end(), f) == fields.end()) fields.push_back(f);
      if (t.kind != render::TaskKind::isosurface && t.kind != render::TaskKind::slice &&
          std::find(marched.begin(), marched.end(), f) == marched.end())
        marched.push_back(f);
    }
  const double bytes = points * (5.0 * double(fields.size()) + 16.0 * double(marched.size()));
  return bytes <= kReplicateBytes ? RenderSplit::cameras : RenderSplit::bricks;
}

long long rig_camera_count(const SessionConfig& cfg, const render::GridGeometry& grid) {
  const camera::RigSpec spec = camera::RigSpec::parse(cfg.rig);
  if (spec.kind == camera::RigSpec::Kind::lattice) return spec.cameras_per_shell();
  if (spec.kind != camera::RigSpec::Kind::file && spec.kind != camera::RigSpec::Kind::path)
    return spec.cameras_per_shell() * (long long)spec.radii.size();
  const camera::Domain domain{grid.domain_lo(), grid.domain_hi() - grid.domain_lo()};
  if (spec.kind == camera::RigSpec::Kind::path) return camera::read_path_rig(spec.path, domain).size();
  return camera::read_rig_file(spec.path, domain).size();
}

bool packed_layout(const SessionConfig& cfg, long long streams) {
  const store::LayoutChoice choice = store::parse_layout_choice(cfg.layout);
  return choice == store::LayoutChoice::packed ||
         (choice == store::LayoutChoice::automatic && cfg.video.gop == 1 && streams >= store::kPackedAutoStreams);
}

long long check_open_streams(long long cameras, int tasks, int ranks, bool packed) {
  const long long streams = checked_product(cameras, tasks, "cameras x tasks (movies)", INT_MAX);
  if (packed) return 2;
  const long long per_rank = (streams + std::max(ranks, 1) - 1) / std::max(ranks, 1);
  const long long limit = open_file_limit();
  // Keep room for the manifest, the lock, MPI and the C library.
  if (limit >= 0 && per_rank > limit - 64)
    throw Error(std::to_string(cameras) + " cameras x " + std::to_string(tasks) + " tasks = " + std::to_string(streams) +
                " movies, " + std::to_string(per_rank) + " open at once on each of " + std::to_string(ranks) +
                " rank(s), but the open-file limit (ulimit -n) is " + std::to_string(limit) +
                "; use fewer cameras or tasks, more ranks, or raise the limit");
  return per_rank;
}

}  // namespace panoptes::insitu
