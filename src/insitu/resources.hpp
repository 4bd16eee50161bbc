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
MemoryEstimate estimate_session_memory(const SessionConfig& config, double block_points, long long cameras,
                                       int ranks, int encode_threads);

/// What one rank's grid stage (grid_adapter.hpp) holds for a source grid of `source_points` points
/// (every patch) resampled onto a cover of `cover_points`, over `ranks` ranks and `fields` fields: its
/// resampling plan (14 B per slab point), the resampled fields (4 B per slab point and field), and the
/// gathered, sent and received source points of one field (the grid stage was outside the estimate:
/// an 8x200x400 shell peaked at 2.5 GB against an estimate of 348 MB, issue 44).
MemoryEstimate estimate_grid_stage_memory(double source_points, double cover_points, int ranks, int fields);

/// The split config.parallel asks for on `ranks` ranks, RenderSplit::automatic decided: cameras when
/// there are several ranks, at least as many cameras as ranks and the whole grid's fields (float32
/// copy, macro-cells, and the march's corner copy of each volume-rendered field) take at most
/// kReplicateBytes per rank; else bricks. One rank always renders the whole grid (bricks = cameras).
/// Depends only on what every rank agrees on, so every rank decides alike.
RenderSplit choose_render_split(const SessionConfig& config, const render::GridGeometry& grid, long long cameras,
                                int ranks);

/// The number of cameras config.rig gives: computed for built-in rigs, read for file rigs (bounded).
long long rig_camera_count(const SessionConfig& config, const render::GridGeometry& grid);

/// Movies open at once on one rank (its share of cameras × tasks), or throws Error naming the count
/// and the open-file limit (ulimit -n) when they cannot all be open; also refuses a cameras × tasks
/// count beyond an int.
long long check_open_streams(long long cameras, int tasks, int ranks);

}  // namespace panoptes::insitu
