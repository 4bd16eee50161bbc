#pragma once
// Premultiplied partial images of bricks, the front-to-back compositing operator, the visibility
// order of bricks, and the final RGBA8 image with the domain's outline box.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "camera/camera.hpp"
#include "camera/orientation.hpp"
#include "core/image.hpp"
#include "render/field_view.hpp"
#include "render/task_spec.hpp"
#include "render/transfer_function.hpp"

namespace panoptes::render {

/// Pixel rectangle [x0, x1) × [y0, y1).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  bool operator==(const PixelRect&) const = default;
};

/// An isosurface task's grazing-sliver state (anti-aliasing, iso_edges.hpp) where a ray leaves a
/// brick, as a function of the state where it enters: `pass` keeps the front's state (the ray met
/// no entry, exit or hit of a sliver in the brick), `closed` and `open` set it (the last such event
/// was an exit or hit, or an entry whose exit is still to come).
enum class SliverEnd : std::uint8_t { pass = 0, closed = 1, open = 2 };

/// What one brick contributes to one (camera, task) image: premultiplied RGBA floats for the pixels
/// of `rect` (the brick's screen footprint; pixels outside it are transparent), and per pixel the
/// depth — the ray parameter (world distance from the camera) where the ray ENTERS the brick, +∞
/// when it misses. Bricks are convex and disjoint, so sorting a pixel's partials by this depth is
/// their exact front-to-back order. For a kind whose blend is Blend::max the depth is instead the
/// order key max_key_depth() of the ray's maximum in the brick (+∞: no sample), so that in both
/// blends the partial with the smaller depth comes first.
///
/// Alpha convention: `rgba[3]` is the OPACITY α, and colour is premultiplied by it. The march's
/// accumulators (ray_march.cpp, compositing_kernels.hpp) hold the TRANSMITTANCE T = 1 − α in lane 3
/// instead while a ray is marched (the loop-carried chain is then one multiply per sample:
/// C ← C + T·α_s·c_s, T ← T·(1 − α_s)); march_ray() turns T back into α before a pixel is written.
/// A new kind's kernel that composites along the ray follows the same convention.
struct PartialImage {
  static constexpr float kNoDepth = std::numeric_limits<float>::infinity();
  int width = 0, height = 0;  ///< full image size
  PixelRect rect;
  std::vector<float> rgba;   ///< 4 floats per pixel of rect, row-major, premultiplied by alpha
  std::vector<float> depth;  ///< 1 float per pixel of rect
  /// Isosurface tasks with anti-aliasing from a brick that is not the whole domain (`slivers`): a
  /// grazing ray's exit adds nothing only when its entry came before it on the ray, maybe in a brick
  /// in front. `rgba` is then the colour if no sliver is open where the ray enters the brick (the
  /// state at the ray's start), `rgba_open` (4 floats per pixel) the colour if one is, and
  /// `sliver_end` (1 per pixel) the state where the ray leaves the brick. composite() chains them
  /// front to back, so the composite's `rgba` is the single brick's; empty when `slivers` is false.
  bool slivers = false;
  std::vector<float> rgba_open;
  std::vector<SliverEnd> sliver_end;

  /// Resizes to a w×h image holding `r` (clipped to the image), all transparent, depth +∞ (and, with
  /// `slivers`, rgba_open transparent, sliver_end pass).
  /// Reuses the buffers' capacity (no allocation once warm).
  void reset(int w, int h, PixelRect r);
  /// As reset() but leaves the pixels unspecified (old contents or zeros), for writers that set every
  /// pixel of the rect: render_brick() does, and so saves clearing (K × 20 bytes per pixel) that it
  /// would overwrite anyway.
  void resize(int w, int h, PixelRect r);
  float* rgba_at(int x, int y) { return rgba.data() + 4 * (std::size_t(y - rect.y0) * rect.width() + (x - rect.x0)); }
  const float* rgba_at(int x, int y) const {
    return rgba.data() + 4 * (std::size_t(y - rect.y0) * rect.width() + (x - rect.x0));
  }
  std::size_t index(int x, int y) const { return std::size_t(y - rect.y0) * rect.width() + (x - rect.x0); }
  float depth_at(int x, int y) const {
    return rect.contains(x, y) ? depth[std::size_t(y - rect.y0) * rect.width() + (x - rect.x0)] : kNoDepth;
  }
};

/// The compositing operator, front-to-back "over" on premultiplied colour:
/// acc ← acc + (1 − acc.α)·back. Associative, so partials may be merged pairwise in any grouping
/// as long as their front-to-back order is kept.
inline void over(float* acc, const float* back) {
  const float w = 1.0f - acc[3];
  acc[0] += w * back[0];
  acc[1] += w * back[1];
  acc[2] += w * back[2];
  acc[3] += w * back[3];
}

/// The depth a Blend::max partial stores for its maximum `key` (≥ 0, the window coordinate the
/// colour map is read at): −key, so the largest maximum sorts first, and +∞ (no sample) last.
inline float max_key_depth(float key) { return -key; }

/// Merges partial images of disjoint bricks of the same (camera, task) into one as the task's kind
/// blends (blend_of()): over, ordering them per pixel by depth, or max, keeping per pixel the partial
/// with the smallest depth (largest maximum) — exact for any brick decomposition. The result covers
/// the union of the rects; its depth is the smallest. Throws panoptes::Error if the image sizes differ.
PartialImage composite(TaskKind kind, std::span<const PartialImage* const> parts);
/// composite() into `out`, reusing its buffers (no allocation once warm: the in-situ session's path).
void composite_into(TaskKind kind, std::span<const PartialImage* const> parts, PartialImage& out);
/// The same by blend (what composite_into(kind, …) dispatches to).
void composite_into(Blend blend, std::span<const PartialImage* const> parts, PartialImage& out);
/// Merges partial images already in front-to-back order (e.g. from visibility_order()); a max
/// blend does not depend on their order.
PartialImage composite_ordered(TaskKind kind, std::span<const PartialImage* const> front_to_back);

/// A front-to-back order of bricks for a camera: indices into `bricks` sorted by the sum over axes
/// of the world distance from the camera to the brick's extent along that axis (0 when the camera
/// lies within it; a camera on a shared face: the brick that owns the eye by the march's half-open
/// rule first). Valid for bricks cut on common planes (slabs, rectilinear block
/// decompositions, as MPI codes use); for arbitrary boxes use composite() (per-pixel depth).
std::vector<int> visibility_order(const camera::Camera& cam, const GridGeometry& grid, std::span<const Brick> bricks);

/// The domain's outline box in final images.
struct OutlineStyle {
  bool enabled = true;
  Rgb colour{0.75f, 0.75f, 0.75f};
  float width = 1.5f;  ///< line width in pixels (anti-aliased)
  bool box = true;     ///< the domain box's edges (false: the compass alone)
  /// 360° (equirectangular) frames only: the horizon of `sky` (the great circle normal to its sky), a
  /// tick every 45° of azimuth on it and N/E/S/W letters above the cardinal ones, faint and behind
  /// the data like the box edges seen from inside (where a camera inside the domain sees them all).
  bool compass = true;
  camera::SkyFrame sky{};  ///< whose north, east and sky the marks follow (default: z up, north = +y)
};

/// The final RGBA8 image (alpha 255): `composited` over the background colour, with the outline of
/// `grid`'s domain box drawn depth-correctly. The box is convex and its edges lie on the domain
/// surface, so an edge is either where rays ENTER the volume (an edge of a face turned towards the
/// camera: drawn over the volume) or where they LEAVE it (both adjacent faces turned away: drawn
/// behind the volume and attenuated by its full opacity). `composited` may cover only part of the
/// image (its rect). In an equirectangular frame the edges are the arcs they project to (wrapping at
/// the frame's left/right seam), with the compass marks of `outline` if it asks for them.
/// Throws panoptes::Error when its size differs from the camera's.
Image finish_image(const PartialImage& composited, const camera::Camera& cam, const GridGeometry& grid,
                   Rgb background = {0, 0, 0}, const OutlineStyle& outline = {});
/// finish_image() into `out`, reusing its pixels when it already has the camera's size and 4
/// channels (the in-situ session finishes hundreds of images per snapshot into the same buffers).
void finish_image_into(const PartialImage& composited, const camera::Camera& cam, const GridGeometry& grid, Image& out,
                       Rgb background = {0, 0, 0}, const OutlineStyle& outline = {});

}  // namespace panoptes::render
