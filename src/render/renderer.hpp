#pragma once
// The brick ray caster: one march per camera serves K tasks (volume, isosurface, slice).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "render/macro_cells.hpp"
#include "render/partial_image.hpp"
#include "render/task_spec.hpp"
#include "render/transfer_function.hpp"

namespace panoptes::render {

/// Ray-casting parameters shared by all tasks of a march.
struct RenderOptions {
  /// Distance between samples along a ray, in voxels (GridGeometry::voxel()). Opacity is corrected
  /// for it exactly (α = 1 − exp(−σ·Δ)). Volume and slice tasks are compositable across bricks for
  /// any value; isosurfaces for values ≤ 1 (a hit up to one step outside the brick reads up to a
  /// voxel round it — its normal, anti-aliasing's footprint filter — which the ghost layers of
  /// required_points() cover for steps ≤ 1; beyond, hit pixels are shaded from clamped positions).
  double sample_distance = 0.5;
  bool skip_empty = true;            ///< empty-space skipping with macro-cells
  float termination_alpha = 0.998f;  ///< early ray termination (the rest adds < 1/255)
  int tile = 16;                     ///< tile edge in pixels (OpenMP dynamic schedule over tiles)
  /// Image-space adaptive sampling (render/adaptive_sampling.hpp): march a lattice of every
  /// `adaptive_stride`-th pixel, interpolate the pixels of cells whose corners agree within
  /// `adaptive_tolerance` (premultiplied RGBA, per task and channel), refine the others down to
  /// single pixels. Off by default: the library's images stay one march per pixel; the product's
  /// configurations switch it on (docs/rendering.md, Round 4, for its measured cost and quality).
  bool adaptive = false;
  int adaptive_stride = 4;               ///< coarse lattice spacing in pixels (>= 2), refined by halves
  float adaptive_tolerance = 4.0f / 255;  ///< largest corner range interpolated (4/255: Round 4 of docs/rendering.md)
  /// Tile edge of adaptive perspective frames (`tile` is for frames marched pixel by pixel). Each
  /// tile marches its own lattice's borders, so 16-pixel tiles marched 56 % more lattice rays than
  /// the stride asks for; 64 marches 13 % more and cut the ParaView anchor's rays from 22.3 to 20.4 %
  /// of its pixels (−9 % CPU, docs/rendering.md, Round 23). Larger tiles share a frame's work among
  /// the threads more coarsely.
  int adaptive_tile = 64;
  /// A cell split at its midpoints whose new lattice points all lie within this of the bilinear
  /// interpolation of its four corners (every premultiplied channel) is filled without splitting
  /// further; not where isosurfaces, slices or maxima are split with the cell (their refinement, and
  /// so every image of such a march, stays as without it); 0: off. 2/255 (Round 13
  /// of docs/rendering.md): the dense anchor marches 22 % of its rays instead of 32 % (−17 % CPU) at
  /// 59.8 instead of 60.7 dB of the full march, max error 8/255 instead of 7. A 4x4 cell that fails it
  /// is filled from the biquadratic through its 3x3 points where its four sub-cell centres lie within
  /// this of it (Round 23: the anchor's rays 20.4 → 17.1 % of the pixels). Perspective frames only.
  float adaptive_linear_tolerance = 2.0f / 255;
  /// Equirectangular cameras: adaptive sampling on the sphere (render/equirect_sampling.hpp) whatever
  /// `adaptive` says — 64×32-pixel tiles (`tile` does not apply), a coarse lattice of rows about
  /// `equirect_lattice_deg` apart whose columns widen by 1/cos(latitude) toward the poles, refined where
  /// corners differ by more than `equirect_tolerance`. A 360° frame from inside the volume marches
  /// every pixel through the domain; this cuts its cost ~8× within 45 dB of the full march (issue 32,
  /// docs/rendering-journal.md). Like any adaptive sampling it can miss a feature smaller than the
  /// lattice that lies between its rays. Bricks of a decomposition then composite as adaptive images
  /// do (not within 1/255). false: equirectangular frames follow `adaptive` as perspective ones.
  bool equirect_adaptive = true;
  /// Row spacing of the equirectangular coarse lattice in degrees (the columns' at the equator): the
  /// largest power of two of pixels not above it, at least 2 (1920 px wide: 8 px; 768: 2 px).
  double equirect_lattice_deg = 1.5;
  /// Largest corner range interpolated in equirectangular frames (what `adaptive_tolerance` is for
  /// perspective ones). 11/255, not 4/255: from inside a dense field (issue 45, inside_bench's
  /// BM_DenseInside) 4/255 refined a third of the pixels down to single ones and kept the frame at
  /// 59 dB of the full march; 10/255 marched 15 % at 50.6 dB, ~2.3x cheaper (docs/rendering.md, Round
  /// 12); 11/255 14 % at 49.4 dB, 8 % cheaper again, once anti-aliased isosurfaces made each ray dearer
  /// (Round 20).
  float equirect_tolerance = 11.0f / 255;
  /// Isosurface anti-aliasing (render/iso_edges.hpp): rays that graze or nearly miss a surface
  /// give it partial coverage (box filter of one pixel), so silhouettes are not stair-stepped.
  /// Off in the library (images stay those of the reference renderer); the product's
  /// configurations switch it on ([render] iso_antialias, default true).
  bool iso_antialias = false;
};

/// Counters of one render_brick() call.
struct RenderStats {
  std::uint64_t rays = 0;              ///< rays marched that meet the brick (adaptive: not the interpolated pixels)
  std::uint64_t samples = 0;           ///< effective samples: inside the brick along those rays, marched or skipped
  std::uint64_t marched_samples = 0;   ///< samples actually interpolated and classified
  double seconds = 0;
  std::uint64_t interpolated_pixels = 0;  ///< adaptive sampling: pixels filled from their cell's corners, not marched
};

/// Maximum tasks served by one march; longer task lists are processed in groups of this size.
inline constexpr int kMaxTasksPerMarch = 64;

/// Renders the brick shared by `fields` (all on the same grid and brick) for every task in one ray
/// march per group of kMaxTasksPerMarch tasks: each sample is interpolated once per field and
/// classified by every task still live. `out[i]` receives task i's premultiplied partial image
/// (resized; capacity reused). Sample k of a ray lies at t0 + k·Δ, where t0 is where the ray enters
/// the GLOBAL domain box (or 0 if the camera is inside), and a brick takes the samples inside its
/// half-open cell range — so partial images of a brick decomposition composite (composite()) to the
/// single-brick image. Throws panoptes::Error on inconsistent fields, bad task parameters or
/// out.size() != tasks.size().
RenderStats render_brick(const camera::Camera& cam, std::span<const PreparedField> fields,
                         std::span<const TaskSpec> tasks, std::span<PartialImage> out, const RenderOptions& options = {});

/// The fields of one brick prepared for marches of `tasks` (what a caller that renders the same
/// task list from many cameras should build once per snapshot): a corner copy for every field a
/// volume task reads, none for the others (isosurfaces and slices read the float field), and the
/// copies of two such fields with the same point range interleaved (CornerField::joint()) — first
/// the two fields of each two-field volume task, then the rest in order — since every march of
/// the task list reads them sample by sample together. Each copy is clamped to the values its tasks
/// tell apart (quantization_ranges()), so `tasks` must be the tasks as they will be rendered, their
/// references resolved. Images are those of fields prepared separately with the same ranges, bit
/// for bit. Throws panoptes::Error when a task names a field outside `views`.
std::vector<PreparedField> prepare_fields(std::span<const FieldView> views, std::span<const TaskSpec> tasks,
                                          int macro_cell_size = MacroCells::kDefaultSize);

/// Per field of `n_fields`, the values the tasks that read its corner copy tell apart: the union over
/// its volume and MIP tasks of their resolved windows (of ±|v| for an absolute-value map) widened by
/// 64 window widths on each side, and its isovalues; the whole range for a field no such task reads.
/// Throws panoptes::Error when a window cannot be resolved (ValueWindow::resolve()).
std::vector<QuantizationRange> quantization_ranges(int n_fields, std::span<const TaskSpec> tasks);

}  // namespace panoptes::render
