#pragma once
// The march plan: a task list compiled for one brick's marches (which fields are read and in which
// slot, each task's LUT rows and windows as the kernels read them, which tasks see anything in
// each macro-cell, which special loops apply). Built once per render_brick() call, read by every ray.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "render/compositing_kernels.hpp"
#include "render/field_access.hpp"
#include "render/renderer.hpp"

namespace panoptes::render::march {

// How the march treats a task: TaskKind, with a volume task split by its number of fields (the
// kernels differ). march_kind() is the one place that maps one to the other.
enum class MarchKind : std::uint8_t { volume1, volume2, iso, slice, mip };

/// The march kind of a task (TaskKind::volume with field2 >= 0 is volume2).
inline MarchKind march_kind(const TaskSpec& t) {
  switch (t.kind) {
    case TaskKind::volume: return t.field2 >= 0 ? MarchKind::volume2 : MarchKind::volume1;
    case TaskKind::isosurface: return MarchKind::iso;
    case TaskKind::slice: return MarchKind::slice;
    case TaskKind::mip: return MarchKind::mip;
  }
  return MarchKind::volume1;
}

// A task prepared for the hot loop: field slots, LUT pointers and windows, isovalue, slice plane.
struct MarchTask {
  MarchKind kind;
  int s1 = 0, s2 = 0;  // slots in the march's field list
  std::uint32_t slots = 0;  // bit mask of the slots the march reads for this task
  const LutEntry* lut1 = nullptr;
  const LutEntry* lut2 = nullptr;
  const VolRow* row1 = nullptr;    // volume1: the rows of lut1 as VolRow
  const MixEntry* mix1 = nullptr;  // volume2: the rows of lut1 and lut2 as MixEntry
  const MixEntry* mix2 = nullptr;
  float lo1 = 0, sc1 = 1, last1 = 0, lo2 = 0, sc2 = 1, last2 = 0;
  bool abs1 = false, abs2 = false;
  float iso = 0;
  float colour[3] = {0, 0, 0};
  int axis = 2;
  double plane = 0;  // slice plane in index coordinates
  float opacity = 1;
};

struct MarchPlan {
  MarchPlan() = default;
  MarchPlan(MarchPlan&&) = default;
  MarchPlan& operator=(MarchPlan&&) = default;
  MarchPlan(const MarchPlan&) = delete;  // rt[] points into luts, mixes and rows
  MarchPlan& operator=(const MarchPlan&) = delete;

  GridGeometry grid;
  Brick brick;
  std::vector<FieldAcc> acc;  // per march slot
  std::vector<const MacroCells*> cells;
  // Slots read from a corner copy, and per slot the other slots of the same corner layout.
  std::uint32_t corner_slots = 0;
  std::array<std::uint32_t, 8> corner_mates{};
  std::vector<MarchTask> rt;
  std::vector<std::uint64_t> active;  // per macro-cell: tasks with something visible in it
  std::uint64_t march_mask = 0, iso_mask = 0, volume1_mask = 0;
  // MIP tasks: the march keeps their running maximum, the pixel loop colours it (renderer.cpp).
  std::uint64_t mip_mask = 0;
  // Tasks whose partials join by Blend::max (blend_of()): their depth is the maximum's order key.
  std::uint64_t max_mask = 0;
  // The paper's mix on one corner layout: volume1 tasks trio[0] (slot trio_a) and trio[1] (slot
  // trio_b) and the volume2 task trio[2] reading (trio_a, trio_b); trio_mask = 0 when absent.
  std::uint64_t trio_mask = 0;
  int trio[3] = {0, 0, 0}, trio_a = 0, trio_b = 0;
  // Per field slot: the single-field volume tasks reading it (march_volumes(): several transfer
  // functions or windows of one field).
  std::array<std::uint64_t, 8> volume1_on_slot{};
  // Dense scenes: (nearly) every macro-cell is visible to every march task. A ray that meets none
  // of the few cells that are not (`exceptions`: their boxes in index space, grown by one voxel) would
  // have its walk merge all its cells into one run, so the march skips the walk and runs [ks, ke].
  bool direct = false;
  std::vector<std::array<double, 6>> exceptions;  // lo xyz, hi xyz
  std::vector<int> slices;
  double dt = 0;
  /// Isosurface anti-aliasing (iso_edges.hpp): the camera's pixel pitch in radians, 0 = off.
  double iso_aa_pitch = 0;
  float termination = 0.998f;
  int mc = 8;
  Index3 mcount{};
  // Macro-cells mi with safe_lo ≤ mi ≤ safe_hi on every axis lie at least one cell inside the data
  // of every field: their samples (even rounded one ulp outside) need no index clamps.
  int safe_lo[3] = {0, 0, 0}, safe_hi[3] = {-1, -1, -1};
  Vec3 spacing;
  // The tables rt[] points into (moving the plan keeps their buffers): per task two LUTs (second
  // field of a two-field task), its rows as MixEntry, and a single-field volume task's VolRows.
  std::vector<TransferLut> luts;
  std::vector<std::vector<MixEntry>> mixes;
  std::vector<std::vector<VolRow>> rows;
};

/// Compiles `tasks` (at most kMaxTasksPerMarch) on `fields` (checked by the caller: one grid, brick and
/// macro-cell size) for marches with `opt`. Throws panoptes::Error naming a bad field index, isovalue,
/// slice axis or opacity, or more than 8 fields read.
MarchPlan compile_march_plan(std::span<const PreparedField> fields, std::span<const TaskSpec> tasks,
                             const RenderOptions& opt);

}  // namespace panoptes::render::march
