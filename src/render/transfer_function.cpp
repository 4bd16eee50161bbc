#include "render/transfer_function.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace panoptes::render {

ValueWindow ValueWindow::resolve(double reference) const {
  ValueWindow w{lo, hi, false};
  if (relative) {
    w.lo = lo * reference;
    w.hi = hi * reference;
  }
  if (!(std::isfinite(w.lo) && std::isfinite(w.hi) && w.hi > w.lo))
    throw Error("value window [" + std::to_string(w.lo) + ", " + std::to_string(w.hi) + "]" +
                (relative ? " (relative, reference " + std::to_string(reference) + ")" : std::string()) +
                "; expected finite lo < hi");
  return w;
}

namespace {
template <class P, class F>
auto piecewise(const std::vector<P>& pts, float u, F value) {
  if (u <= pts.front().x) return value(pts.front());
  if (u >= pts.back().x) return value(pts.back());
  auto it = std::upper_bound(pts.begin(), pts.end(), u, [](float x, const P& p) { return x < p.x; });
  const P& b = *it;
  const P& a = *(it - 1);
  const float w = b.x > a.x ? (u - a.x) / (b.x - a.x) : 1.0f;
  const auto va = value(a), vb = value(b);
  return va + (vb - va) * w;
}
struct V3 {
  float r, g, b;
  V3 operator+(V3 o) const { return {r + o.r, g + o.g, b + o.b}; }
  V3 operator-(V3 o) const { return {r - o.r, g - o.g, b - o.b}; }
  V3 operator*(float s) const { return {r * s, g * s, b * s}; }
};
}  // namespace

Rgb TransferFunction::colour_at(float u) const {
  const V3 c = piecewise(colour, u, [](const ColourPoint& p) { return V3{p.colour.r, p.colour.g, p.colour.b}; });
  return {c.r, c.g, c.b};
}

float TransferFunction::extinction_at(float u) const {
  return piecewise(opacity, u, [](const OpacityPoint& p) { return p.extinction; });
}

void TransferFunction::validate() const {
  if (colour.empty() || opacity.empty()) throw Error("transfer function: needs at least one colour and one opacity point");
  float prev = 0;
  for (const auto& p : colour) {
    if (!(p.x >= prev && p.x <= 1)) throw Error("transfer function: colour point x = " + std::to_string(p.x) +
                                                "; expected non-decreasing positions in [0, 1]");
    for (float c : {p.colour.r, p.colour.g, p.colour.b})
      if (!(c >= 0 && c <= 1)) throw Error("transfer function: colour component " + std::to_string(c) + "; expected [0, 1]");
    prev = p.x;
  }
  prev = 0;
  for (const auto& p : opacity) {
    if (!(p.x >= prev && p.x <= 1)) throw Error("transfer function: opacity point x = " + std::to_string(p.x) +
                                                "; expected non-decreasing positions in [0, 1]");
    if (!(std::isfinite(p.extinction) && p.extinction >= 0))
      throw Error("transfer function: extinction " + std::to_string(p.extinction) + "; expected finite and >= 0");
    prev = p.x;
  }
}

TransferFunction TransferFunction::constant(Rgb c, float extinction) {
  TransferFunction tf;
  tf.colour = {{0, c}, {1, c}};
  tf.opacity = {{0, extinction}, {1, extinction}};
  return tf;
}

std::vector<std::string> TransferFunction::preset_names() {
  return {"p-wave", "s-wave", "diverging", "grayscale", "hot", "rainbow"};
}

TransferFunction TransferFunction::preset(std::string_view name, float s) {
  TransferFunction tf;
  // Wave fronts: transparent below 10 % of the window so the quiet background stays empty (and
  // skippable), then a ramp; the colour brightens towards the strongest amplitudes.
  const std::vector<OpacityPoint> ramp{{0, 0}, {0.1f, 0}, {1, 0.5f * s}};
  if (name == "p-wave") {
    tf.colour = {{0, {0.9f, 0.35f, 0.05f}}, {1, {1.0f, 0.8f, 0.4f}}};
    tf.opacity = ramp;
    tf.absolute_value = true;
  } else if (name == "s-wave") {
    tf.colour = {{0, {0.1f, 0.7f, 0.2f}}, {1, {0.6f, 1.0f, 0.5f}}};
    tf.opacity = ramp;
    tf.absolute_value = true;
  } else if (name == "diverging") {
    tf.colour = {{0, {0.23f, 0.30f, 0.75f}}, {0.5f, {0.87f, 0.87f, 0.87f}}, {1, {0.71f, 0.02f, 0.15f}}};
    tf.opacity = {{0, 0.5f * s}, {0.45f, 0}, {0.55f, 0}, {1, 0.5f * s}};
  } else if (name == "grayscale") {
    tf.colour = {{0, {0, 0, 0}}, {1, {1, 1, 1}}};
    tf.opacity = {{0, 0}, {1, 0.5f * s}};
  } else if (name == "hot") {
    tf.colour = {{0, {0, 0, 0}}, {0.4f, {0.9f, 0.1f, 0}}, {0.8f, {1, 0.9f, 0}}, {1, {1, 1, 1}}};
    tf.opacity = ramp;
  } else if (name == "rainbow") {
    tf.colour = {{0, {0.2f, 0.1f, 0.6f}}, {0.25f, {0.1f, 0.5f, 1}}, {0.5f, {0.2f, 0.85f, 0.3f}},
                 {0.75f, {1, 0.85f, 0.1f}}, {1, {0.85f, 0.1f, 0.1f}}};
    tf.opacity = ramp;
  } else {
    std::string names;
    for (const auto& n : preset_names()) names += (names.empty() ? "" : ", ") + n;
    throw Error("transfer function preset '" + std::string(name) + "'; expected one of: " + names);
  }
  return tf;
}

TransferLut::TransferLut(const TransferFunction& tf, const ValueWindow& window, double step_voxels, int bins) {
  tf.validate();
  if (window.relative) throw Error("transfer LUT: window is relative; resolve it against a reference first");
  const ValueWindow w = window.resolve(0);
  if (!(step_voxels > 0 && std::isfinite(step_voxels)))
    throw Error("transfer LUT: sample distance " + std::to_string(step_voxels) + " voxels; expected > 0");
  if (bins < 2) throw Error("transfer LUT: " + std::to_string(bins) + " bins; expected >= 2");
  lo_ = float(w.lo);
  scale_ = float(bins / (w.hi - w.lo));
  last_ = float(bins - 1);
  abs_ = tf.absolute_value;
  entries_.resize(bins);
  visible_prefix_.assign(bins + 1, 0);
  for (int i = 0; i < bins; ++i) {
    const float u = (i + 0.5f) / bins;
    const Rgb c = tf.colour_at(u);
    const double tau = double(tf.extinction_at(u)) * step_voxels;
    const float a = float(-std::expm1(-tau));  // 1 − exp(−σΔt): exact opacity of one step
    entries_[i] = {c.r * a, c.g * a, c.b * a, a, c.r, c.g, c.b, float(tau)};
    visible_prefix_[i + 1] = visible_prefix_[i] + (a > 0 ? 1 : 0);
  }
}

bool TransferLut::visible(float vmin, float vmax) const {
  if (entries_.empty()) return false;
  if (abs_) {
    const float a = std::abs(vmin), b = std::abs(vmax);
    const float hi = std::max(a, b);
    const float lo = (vmin <= 0 && vmax >= 0) ? 0.0f : std::min(a, b);
    vmin = lo;
    vmax = hi;
  }
  const int b0 = bin(vmin), b1 = bin(vmax);
  return visible_prefix_[b1 + 1] - visible_prefix_[b0] > 0;
}

double abs_percentile(const FieldView& f, double q, std::size_t max_samples) {
  f.validate();
  if (!(q >= 0 && q <= 1)) throw Error("percentile: q = " + std::to_string(q) + "; expected 0 <= q <= 1");
  const Brick& b = f.brick;
  const std::int64_t n = std::int64_t(b.hi[0] - b.lo[0] + 1) * (b.hi[1] - b.lo[1] + 1) * (b.hi[2] - b.lo[2] + 1);
  const std::int64_t step = std::max<std::int64_t>(1, n / std::int64_t(std::max<std::size_t>(1, max_samples)));
  std::vector<float> v;
  v.reserve(std::size_t(n / step + 1));
  const int nx = b.hi[0] - b.lo[0] + 1, ny = b.hi[1] - b.lo[1] + 1;
  for (std::int64_t idx = 0; idx < n; idx += step) {
    const int i = int(idx % nx), j = int((idx / nx) % ny), k = int(idx / (std::int64_t(nx) * ny));
    v.push_back(std::abs(f.at(b.lo[0] + i, b.lo[1] + j, b.lo[2] + k)));
  }
  const std::size_t r = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(r), v.end());
  return v[r];
}

double abs_max(const FieldView& f) {
  f.validate();
  const Brick& b = f.brick;
  float m = 0;
  for (int k = b.lo[2]; k <= b.hi[2]; ++k)
    for (int j = b.lo[1]; j <= b.hi[1]; ++j)
      for (int i = b.lo[0]; i <= b.hi[0]; ++i) m = std::max(m, std::abs(f.at(i, j, k)));
  return m;
}

double RunningMax::update(double v) {
  if (std::isfinite(v)) value_ = std::max(value_, v);
  return value_;
}

}  // namespace panoptes::render
