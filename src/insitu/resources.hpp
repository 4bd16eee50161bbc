#pragma once
// What an in-situ session will hold in memory and open files, per rank, before it builds anything.
#include <string>

#include "core/memory.hpp"
#include "insitu/config.hpp"
#include "render/field_view.hpp"

namespace panoptes::insitu {

/// Peak resident bytes of one rank of a Session: float32 copies of the fields over its brick
/// (`block_points` points, ghosts included), partial images in flight (camera rounds of `ranks`,
/// every task, full frames at worst), finished frames, the open writers of the streams it owns and
/// the rig / manifest / navigation graph of `cameras` cameras. `encode_threads` frames encode at once.
/// Open writers: a muxer per stream in the files layout, a ~110-byte record plus the stream's
/// compressed frames of one snapshot in the packed layout (packed_layout()).
MemoryEstimate estimate_session_memory(const SessionConfig& config, double block_points, long long cameras,
                                       int ranks, int encode_threads);

/// What one rank's grid stage (grid_adapter.hpp) holds for a source grid of `source_points` points
/// (every patch) resampled onto a cover of `cover_points`, over `ranks` ranks and `fields` fields: its
/// resampling plan (14 B per slab point), the resampled fields (4 B per slab point and field), and the
/// gathered, sent and received source points of one field (the grid stage was outside the estimate:
/// an 8x200x400 shell peaked at 2.5 GB against an estimate of 348 MB, issue 44).
MemoryEstimate estimate_grid_stage_memory(double source_points, double cover_points, int ranks, int fields);

/// Whether a session of `config` on `ranks` ranks renders its tasks as one sweep (render::render_sweep():
/// one march per ray for every value, 8-bit frames, finished and encoded task by task): one rank, and
/// the tasks are one [[task]] with several isovalues, or one single-field volume [[task]] with several
/// windows. An isosurface sweep of at most render::kMaxTasksPerMarch values with [render]
/// iso_antialias keeps the general path (render_sweep() does not anti-alias); a longer one takes the
/// sweep path without anti-aliasing (the general path needed 20 bytes per pixel and value per camera:
/// 1,000 values at 460x448 refused 16.5 GB, issue 45).
bool sweep_rendering(const SessionConfig& config, int ranks);
/// The split config.parallel asks for on `ranks` ranks, RenderSplit::automatic decided: cameras when
/// there are several ranks, at least as many cameras as ranks and the whole grid's fields (float32
/// copy, macro-cells, and the march's corner copy of each volume-rendered field) take at most
/// kReplicateBytes per rank; else bricks. One rank always renders the whole grid (bricks = cameras).
/// Depends only on what every rank agrees on, so every rank decides alike.
RenderSplit choose_render_split(const SessionConfig& config, const render::GridGeometry& grid, long long cameras,
                                int ranks);

/// The number of cameras config.rig gives: computed for built-in rigs, read for file rigs (bounded).
long long rig_camera_count(const SessionConfig& config, const render::GridGeometry& grid);

/// Whether a new database of `streams` streams gets the packed layout under `config` ([output] layout
/// = "packed", or "auto" with gop 1 and at least store::kPackedAutoStreams streams: what
/// store::DatabaseWriter decides).
bool packed_layout(const SessionConfig& config, long long streams);

/// Files one rank holds open for its movies: with `packed`, its pack and index (2); else one per movie
/// of its share of cameras × tasks, and then throws Error naming the count and the open-file limit
/// (ulimit -n) when they cannot all be open. Refuses a cameras × tasks count beyond an int.
long long check_open_streams(long long cameras, int tasks, int ranks, bool packed = false);

}  // namespace panoptes::insitu
