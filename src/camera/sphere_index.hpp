#pragma once
// Spatial bucketing of unit directions on the sphere, for nearest-camera and within-angle queries
// that touch only the buckets near the query instead of every camera.
#include <algorithm>
#include <cmath>
#include <vector>

#include "camera/angles.hpp"
#include "core/vec3.hpp"

namespace panoptes::camera {

/// Buckets unit vectors in colatitude bands of equal angular height, each band split into
/// longitude bins about as wide as the band is high (cells of roughly equal size, about two points
/// per cell). Queries visit only the cells that intersect a spherical cap, so nearest() costs
/// O(points near the query) and never allocates. Immutable after construction; safe to share
/// between threads.
class SphereIndex {
 public:
  SphereIndex() = default;
  /// Indexes `directions` (normalized here; zero vectors are rejected with panoptes::Error). Point
  /// k of the input keeps the id k in every query result.
  explicit SphereIndex(const std::vector<Vec3>& directions);

  int size() const { return int(ids_.size()); }
  /// The unit vector of point `id` (input order).
  const Vec3& direction(int id) const { return unit_[id]; }
  /// Mean spacing of the points (radians): sqrt(4π / size).
  double spacing() const { return spacing_; }

  /// Id of the point closest (smallest angle) to `direction` (need not be unit); −1 if empty.
  /// Ties go to the smaller id.
  int nearest(const Vec3& direction) const;

  /// Calls fn(id, unit_point, cos_angle) for every point within `radius` radians of the unit vector
  /// `u` (exactly those: the cell scan is conservative, the final test exact).
  template <class Fn>
  void for_each_within(const Vec3& u, double radius, Fn&& fn) const;

 private:
  int cell_of(const Vec3& u) const;
  int band_of(double colatitude) const;
  int bin_of(int band, double longitude) const;

  int bands_ = 0;
  double band_height_ = 0, spacing_ = 0;
  std::vector<int> band_first_cell_;  // size bands_ + 1
  std::vector<int> cell_first_;       // CSR offsets into points_/ids_, size cells + 1
  std::vector<Vec3> points_;          // unit vectors sorted by cell
  std::vector<int> ids_;              // input index of points_[k]
  std::vector<Vec3> unit_;            // unit vectors in input order
};

template <class Fn>
void SphereIndex::for_each_within(const Vec3& u, double radius, Fn&& fn) const {
  if (ids_.empty()) return;
  const double cos_r = radius >= kPi ? -2.0 : std::cos(radius);
  auto scan_cell = [&](int cell) {
    for (int k = cell_first_[cell], e = cell_first_[cell + 1]; k < e; ++k) {
      const double c = dot(points_[k], u);
      if (c >= cos_r) fn(ids_[k], points_[k], c);
    }
  };
  const double theta = std::atan2(std::hypot(u.x, u.y), u.z);
  const double r = radius + 1e-9;  // cover rounding at cell borders
  const int b0 = band_of(std::max(0.0, theta - r)), b1 = band_of(std::min(kPi, theta + r));
  const bool all_longitudes = theta - r <= 0 || theta + r >= kPi;
  // Longitude half-width of a cap that contains no pole: asin(sin r / sin theta).
  const double half = all_longitudes ? kPi : std::asin(std::min(1.0, std::sin(r) / std::sin(theta)));
  const double phi = std::atan2(u.y, u.x);
  for (int b = b0; b <= b1; ++b) {
    const int first = band_first_cell_[b], n = band_first_cell_[b + 1] - first;
    if (all_longitudes) {
      for (int c = first; c < first + n; ++c) scan_cell(c);
      continue;
    }
    const double w = 2 * kPi / n;
    const int j0 = int(std::floor((phi - half + kPi) / w)), j1 = int(std::floor((phi + half + kPi) / w));
    if (j1 - j0 + 1 >= n) {
      for (int c = first; c < first + n; ++c) scan_cell(c);
      continue;
    }
    for (int j = j0; j <= j1; ++j) scan_cell(first + ((j % n) + n) % n);
  }
}

}  // namespace panoptes::camera
