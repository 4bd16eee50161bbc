#pragma once
// Uniform grids, bricks of them, and read-only views of a float32 scalar field on a brick.
#include <array>
#include <cstddef>
#include <cstdint>

#include "core/vec3.hpp"

namespace panoptes::render {

/// Integer index triple (x, y, z).
using Index3 = std::array<int, 3>;

/// A uniform grid of dims[0] × dims[1] × dims[2] POINTS. Point (i, j, k) sits at
/// origin + (i·spacing.x, j·spacing.y, k·spacing.z); the domain is the box spanned by the
/// points, [origin, origin + (dims − 1)·spacing]. Spacing may differ per axis.
struct GridGeometry {
  Index3 dims{2, 2, 2};
  Vec3 origin{0, 0, 0};
  Vec3 spacing{1, 1, 1};

  /// Lower corner of the domain box in world coordinates.
  Vec3 domain_lo() const { return origin; }
  /// Upper corner of the domain box in world coordinates.
  Vec3 domain_hi() const {
    return {origin.x + (dims[0] - 1) * spacing.x, origin.y + (dims[1] - 1) * spacing.y,
            origin.z + (dims[2] - 1) * spacing.z};
  }
  /// Centre of the domain box.
  Vec3 centre() const { return (domain_lo() + domain_hi()) * 0.5; }
  /// The voxel length: the smallest spacing. Sample distances and extinctions are in this unit.
  double voxel() const;
  /// Throws panoptes::Error unless every dim is ≥ 2 and every spacing is finite and > 0.
  void validate() const;
};

/// A brick of the global grid in CELL index space: cells [lo, hi) per axis, where cell i spans
/// point coordinates [i, i+1]. The whole grid is the brick {0,0,0} – {dims−1}. A brick owns the
/// ray samples whose continuous index coordinate p satisfies lo ≤ p < hi on every axis (half-open;
/// closed, p ≤ hi, where hi is the upper face of the whole grid), so every sample of a ray in the
/// domain belongs to exactly one brick of a partition.
struct Brick {
  Index3 lo{0, 0, 0};
  Index3 hi{1, 1, 1};

  /// The brick covering the whole grid.
  static Brick whole(const GridGeometry& g) { return {{0, 0, 0}, {g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1}}; }
  /// Part `index` of `parts` equal slabs of `whole` along `axis` (sizes differ by at most one cell).
  static Brick slab(const GridGeometry& g, int axis, int parts, int index);
  /// Number of cells.
  std::int64_t cells() const { return std::int64_t(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
  bool operator==(const Brick&) const = default;
};

/// Point range [lo, hi) a brick's field data must cover (the brick's points plus ghost layers).
/// Trilinear interpolation of the samples in cells [blo, bhi) reads points blo … bhi. An isosurface
/// hit lies at most one step Δ outside the brick (a crossing between the brick's first sample and the
/// one before it, or a sliver between its last sample and the next; Δ ≤ 1 voxel), and what is read
/// round a hit reaches at most one voxel farther on every axis: its normal's central differences ±0.5
/// voxel, anti-aliasing's footprint filter the renderer's gradient at points up to half a voxel from
/// the hit (iso_shading.cpp, shade_hit_footprint()). Positions in [blo − 2, bhi + 2) read points
/// blo − 2 … bhi + 2, so the requirement is points [blo − 2, bhi + 3) clipped to [0, dims): TWO ghost
/// layers below the brick and, above it, the point bhi (shared with the next brick) plus TWO more.
/// Volume and slice tasks alone read only points [blo, bhi + 1) plus one margin point on each side
/// for the macro-cells' min/max.
struct PointRange {
  Index3 lo{0, 0, 0};
  Index3 hi{0, 0, 0};
  bool contains(const PointRange& o) const {
    for (int a = 0; a < 3; ++a)
      if (o.lo[a] < lo[a] || o.hi[a] > hi[a]) return false;
    return true;
  }
};
/// The ghosted point range a brick's FieldView must cover (see PointRange).
PointRange required_points(const GridGeometry& g, const Brick& b);

/// A read-only view of a float32 scalar field on the points `points` of the global grid `grid`,
/// used to render brick `brick`. `data` points at the value of point points.lo; `stride` is the
/// element step per axis (x fastest for a C array of shape [nz][ny][nx]: stride {1, nx, nx·ny}).
/// The view does not own the data.
struct FieldView {
  GridGeometry grid;
  Brick brick;
  PointRange points;
  const float* data = nullptr;
  std::array<std::int64_t, 3> stride{1, 1, 1};

  /// A view of a whole field stored contiguously with x fastest (shape [nz][ny][nx] in C).
  static FieldView whole(const GridGeometry& g, const float* data);
  /// A view of a brick's data stored contiguously with x fastest over `points` (its ghosted range).
  static FieldView of_brick(const GridGeometry& g, const Brick& b, const PointRange& points, const float* data);
  /// The same field restricted to brick `b`: the point range shrinks to required_points(b), so a
  /// renderer reading outside the ghost layers is caught by validate() / would read wrong data.
  FieldView subview(const Brick& b) const;

  /// The value at global point (i, j, k), which must lie in `points`.
  float at(int i, int j, int k) const {
    return data[std::int64_t(i - points.lo[0]) * stride[0] + std::int64_t(j - points.lo[1]) * stride[1] +
                std::int64_t(k - points.lo[2]) * stride[2]];
  }
  /// Throws panoptes::Error when the grid is invalid, the brick is empty or outside the grid, the
  /// data pointer is null or `points` does not cover required_points(grid, brick).
  void validate() const;
};

}  // namespace panoptes::render
