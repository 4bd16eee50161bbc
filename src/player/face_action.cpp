#include "player/face_action.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace panoptes::player {

std::optional<Vec3> strongest_signal_direction(const video::YuvFrame& f, const ViewBasis& cam) {
  const int W = f.width, H = f.height;
  if (W < 2 || H < 2 || f.y.size() < std::size_t(W) * std::size_t(H)) return std::nullopt;
  // Median and 98th percentile of the luma, solid-angle weighted (rows near the poles cover little).
  std::array<double, 256> hist{};
  double total = 0;
  for (int y = 0; y < H; ++y) {
    const double w = std::cos((0.5 - (y + 0.5) / H) * std::numbers::pi);
    const std::uint8_t* row = f.y.data() + std::size_t(y) * W;
    for (int x = 0; x < W; ++x) hist[row[x]] += w;
    total += w * W;
  }
  int median = 0, top = 255;
  double acc = 0;
  for (int v = 0; v < 256; ++v) {
    acc += hist[std::size_t(v)];
    if (acc < 0.5 * total) median = v + 1;
    if (acc < 0.98 * total) top = v + 1;
  }
  const int threshold = std::max(top, median + 16);
  if (threshold > 255) return std::nullopt;
  Vec3 sum{0, 0, 0};
  double weight = 0;
  for (int y = 0; y < H; ++y) {
    const double lat = (0.5 - (y + 0.5) / H) * std::numbers::pi;
    const double cl = std::cos(lat), sl = std::sin(lat);
    const std::uint8_t* row = f.y.data() + std::size_t(y) * W;
    for (int x = 0; x < W; ++x) {
      if (row[x] < threshold) continue;
      const double lon = (2.0 * (x + 0.5) / W - 1.0) * std::numbers::pi;
      const double w = double(row[x] - median) * cl;
      sum = sum + (cam.forward * (cl * std::cos(lon)) + cam.right * (cl * std::sin(lon)) + cam.up * sl) * w;
      weight += w;
    }
  }
  if (!(weight > 0) || norm(sum) < 0.2 * weight) return std::nullopt;
  return normalize(sum);
}

}  // namespace panoptes::player
