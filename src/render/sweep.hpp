#pragma once
// A parameter sweep (hundreds to thousands of isovalues or volume windows of one field) rendered in
// ONE march per ray, into compact 8-bit frames (issue 45, point 2). render_brick() serves at most
// kMaxTasksPerMarch tasks per march and keeps 20 bytes per pixel per task; a 1,000-value sweep there
// is 16 marches and 4 GB of partial images per 460x448 camera. Here the cost of a ray grows with the
// surfaces it hits, not with the number of isovalues, and a frame takes 4 bytes per pixel.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "camera/camera.hpp"
#include "render/partial_image.hpp"
#include "render/renderer.hpp"

namespace panoptes::render {

/// The frames of one camera for every task of a sweep, stored pixel-major (a pixel's `stride` bytes
/// hold its tasks' values, slot after slot) because a ray writes all its tasks' values at once; task t
/// is stored in slot[t] (isosurfaces in the order of their isovalues). A volume task's value is its
/// premultiplied RGBA8 (4 bytes); an isosurface's is 2 bytes: 0 where the ray misses it, else
/// 1 + |n·l|·65534 (its colour, in `colour`, and |n·l| give the headlight shading, so half the bytes of
/// RGBA8). The stride is a multiple of 64 bytes and pixels start on 64-byte boundaries, so a ray's
/// pixel is written by streaming stores that bypass the caches.
struct SweepFrames {
  int width = 0, height = 0, count = 0;
  int task_bytes = 4;      ///< bytes per task and pixel: 4 (volume, RGBA8) or 2 (isosurface)
  std::size_t stride = 0;  ///< bytes per pixel (task_bytes·count rounded up to 64)
  std::vector<int> slot;
  std::vector<std::array<float, 3>> colour;  ///< isosurfaces: each task's surface colour

  /// Whether task t shows something at pixel (x, y).
  bool shows(int x, int y, int t) const {
    const std::uint8_t* v = pixel(x, y) + std::size_t(task_bytes) * std::size_t(slot[std::size_t(t)]);
    return task_bytes == 2 ? (v[0] | v[1]) != 0 : v[3] != 0;
  }
  const std::uint8_t* pixel(int x, int y) const { return data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * stride; }
  std::uint8_t* pixel(int x, int y) { return data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * stride; }
  /// Resizes for a w×h image of `tasks` tasks of `bytes` bytes each (capacity reused; contents unspecified).
  void resize(int w, int h, int tasks, int bytes);
  /// Bytes held (what a session keeps per camera being rendered).
  std::size_t bytes() const { return storage_.capacity(); }
  /// Task t's frame as a full-image partial (what finish_image() takes): colour and alpha as floats
  /// (k/255, or the isosurface's shading), depth 0 where the task shows something, +∞ elsewhere.
  /// Reuses `out`'s buffers.
  void to_partial(int t, PartialImage& out) const;

 private:
  const std::uint8_t* data() const { return storage_.data() + base_; }
  std::uint8_t* data() { return storage_.data() + base_; }
  std::vector<std::uint8_t> storage_;
  std::size_t base_ = 0;  // first 64-byte boundary in storage_
};

/// Whether render_sweep() can render `tasks`: at least two, all isosurfaces of one field, or all
/// single-field volume tasks of one field (windows or transfer functions).
bool is_sweep(std::span<const TaskSpec> tasks);

/// Renders every task of the sweep `tasks` (is_sweep()) on their field `fields[tasks[0].field]` from `cam` into `out` (resized;
/// capacity reused) in one march per pixel: samples are interpolated once for all tasks.
///   - Isosurfaces: per segment between consecutive samples, the isovalues crossed are found by a
///     binary search in the sorted isovalues ((min, max] of the segment's two values) and only those
///     not hit yet are refined and shaded, as render_brick() refines and shades one hit. The ray goes
///     on until every isovalue is hit or it leaves the domain.
///   - Volume tasks: per block of 8 samples every window still transparent enough composites them
///     (render_brick()'s operations, four windows' chains interleaved); a window whose visible value
///     range misses the block's values is skipped (its samples would be exact no-ops), an opaque one
///     leaves the ray.
/// Every pixel is marched (no adaptive sampling; `options.adaptive` and `equirect_adaptive` do not
/// apply) and isosurfaces are not anti-aliased. The field must cover the whole domain (one brick: the
/// frames hold no depth to composite bricks by). Throws panoptes::Error naming what is not a sweep,
/// a field that is not the whole domain, or a bad sample distance.
RenderStats render_sweep(const camera::Camera& cam, std::span<const PreparedField> fields, std::span<const TaskSpec> tasks,
                         SweepFrames& out, const RenderOptions& options = {});

}  // namespace panoptes::render
