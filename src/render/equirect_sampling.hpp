#pragma once
// Adaptive sampling on the sphere (issue 32): an equirectangular frame spends its pixels unevenly —
// row y at latitude φ spreads its W columns over a circle of circumference cos φ, so away from the
// equator a pixel row samples the sphere 1/cos φ times more densely across than along the meridian.
// Frames from inside the volume march every pixel through the whole domain, so the sampling of the
// sphere is what a frame costs. These are the lattice rules the renderer's pixel loop uses for
// equirectangular cameras: wide tiles (so the coarse lattice is not dominated by tile borders) and a
// coarse lattice whose columns widen with 1/cos φ, refined by AdaptiveTile (adaptive_sampling.hpp)
// wherever its cells' corners disagree, as on a planar image.
namespace panoptes::render {

/// Tile of the equirectangular pixel loop, in pixels (columns × rows). Tiles lie on multiples of
/// these in image coordinates, so bricks of a decomposition share their lattices where they overlap.
inline constexpr int kEquirectTileWidth = 64;
inline constexpr int kEquirectTileHeight = 32;

/// The coarse lattice's row spacing in pixels for a lattice about `degrees` apart on a frame `width`
/// pixels wide (360°): the largest power of two not above degrees·width/360, at least 2. Angular, so a
/// small frame's lattice does not skip more of the sphere than a large one's.
int equirect_row_stride(double degrees, int width);

/// The coarse lattice's column spacing for the rows [y0, y1) of an equirectangular image `height`
/// rows tall whose rows are `stride` apart: `stride` times the largest power of two 2^k with
/// 2^k · cos φ ≤ 1 for the row of the band nearest the equator (pixel centres, φ = (0.5 − (y + 0.5) /
/// height)·π), so no lattice cell is wider on the sphere than `stride` pixels at the equator; at most
/// `max_stride` (a power of two times `stride`, or `stride` when it is smaller). Throws
/// std::invalid_argument when stride < 1, height < 1 or the band is empty or outside the image.
int equirect_column_stride(int stride, int height, int y0, int y1, int max_stride);

}  // namespace panoptes::render
