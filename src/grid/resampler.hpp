#pragma once
// The grid adapter: resamples a field on any GridDescription onto points of a uniform grid (what the
// renderer marches), trilinearly in the source's index space, with a fill value where the uniform
// grid leaves the source's domain (the empty core and the outside of a spherical shell).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "grid/grid_description.hpp"
#include "render/field_view.hpp"

namespace panoptes::grid {

/// A block of a field on one patch of a source grid: the points `points` of patch `patch`'s index
/// space, `data` at point points.lo, `stride` elements per step along each axis.
struct SourceBlock {
  int patch = 0;
  render::PointRange points;
  const float* data = nullptr;
  std::array<std::int64_t, 3> stride{1, 1, 1};

  /// A whole patch stored contiguously, i fastest.
  static SourceBlock whole(const GridDescription& grid, int patch, const float* data);
  /// The points `points` of patch `patch` stored contiguously, i fastest.
  static SourceBlock of(int patch, const render::PointRange& points, const float* data);
};

/// A resampling plan from a source grid onto the points `points` of a uniform `target` grid, built
/// once (the geometry does not change between snapshots) and applied to every snapshot.
///
/// Each target point inside the source's domain takes the trilinear interpolation, in the source's
/// index space (i.e. along r, θ, φ on a shell), of the 8 source points around it; points outside
/// (beyond the radii, angles or box of the source) take `outside_value`, which the caller picks so
/// that its transfer functions map it to zero opacity (0 for the absolute-value presets). On a
/// Yin-Yang grid a point of the overlap reads the patch it lies farther inside (the larger of its
/// angular distances to the patch's edges; Yin on ties): every point has one rule whatever the
/// decomposition, and both patches interpolate the same field there, so the switch costs no more
/// than the interpolation error (no seam). Weights are stored in 16 bits (error ≤ 8e-6 of the
/// local value range); the plan takes 14 bytes per target point.
class Resampler {
 public:
  Resampler(const GridDescription& source, const render::GridGeometry& target, const render::PointRange& points,
            float outside_value = 0);

  const GridDescription& source() const { return source_; }
  const render::GridGeometry& target() const { return target_; }
  const render::PointRange& points() const { return points_; }
  float outside_value() const { return outside_value_; }
  /// Number of target points (the length resample() writes).
  std::int64_t size() const { return std::int64_t(plan_.size()); }
  /// Target points that lie outside the source's domain.
  std::int64_t outside_points() const { return outside_; }
  /// Per patch, the source points the plan reads (lo == hi when it reads none of that patch): what
  /// a rank must hold or fetch to resample its brick.
  const std::vector<render::PointRange>& needed() const { return needed_; }
  /// The patch target point `index` (x fastest over points()) reads, or −1 when it lies outside.
  int patch_at(std::int64_t index) const {
    const Stencil& s = plan_[std::size_t(index)];
    return (s.flags & kOutside) ? -1 : s.patch;
  }
  /// Bytes the plan holds.
  std::size_t plan_bytes() const { return plan_.size() * sizeof(Stencil); }

  /// Writes the resampled field, x fastest over points(), to `out` (size() values). `blocks` holds
  /// at least one block per patch the plan reads, each covering needed() for that patch. Throws
  /// panoptes::Error naming the patch and ranges otherwise, or when out is too short.
  void resample(std::span<const SourceBlock> blocks, std::span<float> out) const;

 private:
  struct Stencil {
    std::uint16_t i, j, k;     // lower corner in the patch's index space
    std::uint16_t wi, wj, wk;  // weights of the upper corner, ·65535
    std::uint8_t patch;
    std::uint8_t flags;        // kOutside, kWrap
  };
  static_assert(sizeof(Stencil) == 14);
  static constexpr std::uint8_t kOutside = 1, kWrap = 2;

  GridDescription source_;
  render::GridGeometry target_;
  render::PointRange points_;
  float outside_value_ = 0;
  std::vector<Stencil> plan_;
  std::vector<render::PointRange> needed_;
  std::int64_t outside_ = 0;
};

}  // namespace panoptes::grid
