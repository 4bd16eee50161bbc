#include "camera/sphere_index.hpp"

#include <string>

#include "camera/angles.hpp"
#include "core/error.hpp"

namespace panoptes::camera {

int SphereIndex::band_of(double colatitude) const {
  return std::clamp(int(colatitude / band_height_), 0, bands_ - 1);
}

int SphereIndex::bin_of(int band, double longitude) const {
  const int n = band_first_cell_[band + 1] - band_first_cell_[band];
  return std::clamp(int(std::floor((longitude + kPi) / (2 * kPi / n))), 0, n - 1);
}

int SphereIndex::cell_of(const Vec3& u) const {
  const int b = band_of(std::atan2(std::hypot(u.x, u.y), u.z));
  return band_first_cell_[b] + bin_of(b, std::atan2(u.y, u.x));
}

SphereIndex::SphereIndex(const std::vector<Vec3>& directions) {
  const int n = int(directions.size());
  if (n == 0) return;
  spacing_ = std::sqrt(4 * kPi / n);
  // About two points per cell: 4·bands²/π cells ≈ n/2.
  bands_ = std::max(1, int(std::sqrt(n * kPi / 8.0)));
  band_height_ = kPi / bands_;
  band_first_cell_.resize(bands_ + 1);
  band_first_cell_[0] = 0;
  for (int b = 0; b < bands_; ++b) {
    // Bins as wide as the band is high at the band's widest colatitude.
    const double t0 = b * band_height_, t1 = (b + 1) * band_height_;
    const double widest = (t0 <= kPi / 2 && t1 >= kPi / 2) ? 1.0 : std::max(std::sin(t0), std::sin(t1));
    const int bins = std::max(1, int(std::ceil(2 * kPi * widest / band_height_)));
    band_first_cell_[b + 1] = band_first_cell_[b] + bins;
  }
  const int cells = band_first_cell_[bands_];
  std::vector<int> cell(n);
  cell_first_.assign(cells + 1, 0);
  for (int k = 0; k < n; ++k) {
    const Vec3& d = directions[k];
    const double len = norm(d);
    if (!(len > 0) || !std::isfinite(len))
      throw Error("sphere index: direction " + std::to_string(k) + " is zero or not finite; expected a direction");
    cell[k] = cell_of(d / len);
    ++cell_first_[cell[k] + 1];
  }
  for (int c = 0; c < cells; ++c) cell_first_[c + 1] += cell_first_[c];
  points_.resize(n);
  ids_.resize(n);
  unit_.resize(n);
  std::vector<int> fill(cell_first_.begin(), cell_first_.end() - 1);
  for (int k = 0; k < n; ++k) {
    const int slot = fill[cell[k]]++;
    points_[slot] = unit_[k] = normalize(directions[k]);
    ids_[slot] = k;
  }
}

int SphereIndex::nearest(const Vec3& direction) const {
  if (ids_.empty()) return -1;
  const Vec3 u = normalize(direction);
  if (norm(u) == 0) return -1;
  // Grow the cap until it holds a point: then every closer point is inside the cap too.
  for (double r = 1.5 * std::max(band_height_, 1e-6);; r *= 2) {
    int best = -1;
    double best_cos = -2;
    for_each_within(u, r, [&](int id, const Vec3&, double c) {
      if (c > best_cos || (c == best_cos && id < best)) {
        best_cos = c;
        best = id;
      }
    });
    if (best >= 0 || r >= kPi) return best;
  }
}

}  // namespace panoptes::camera
