#pragma once
// Transfer functions (piecewise-linear colour and extinction), value windows, and the lookup
// tables the ray caster's hot loop reads.
#include <string>
#include <string_view>
#include <vector>

#include "render/field_view.hpp"

namespace panoptes::render {

/// Linear RGB colour with components in [0, 1].
struct Rgb {
  float r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

/// A colour control point at normalized window position x ∈ [0, 1].
struct ColourPoint {
  float x;
  Rgb colour;
};

/// An extinction control point at normalized window position x ∈ [0, 1]. `extinction` is the
/// absorption coefficient σ per VOXEL LENGTH (GridGeometry::voxel()): a homogeneous layer of
/// thickness L voxels has opacity 1 − exp(−σ·L), whatever the sample distance.
struct OpacityPoint {
  float x;
  float extinction;
};

/// How field values map to the normalized coordinate u ∈ [0, 1] of a transfer function:
/// u = (v − lo) / (hi − lo), clamped. `relative` windows give lo and hi as multiples of a reference
/// value (a percentile of |field|, or a running maximum over time) that is supplied at render
/// time — the right absolute range of a simulation field is unknown beforehand.
struct ValueWindow {
  double lo = 0;
  double hi = 1;
  bool relative = false;

  /// An absolute window [lo, hi].
  static ValueWindow absolute(double lo, double hi) { return {lo, hi, false}; }
  /// A window [lo·ref, hi·ref] for a reference value ref given later.
  static ValueWindow relative_to(double lo_fraction, double hi_fraction) { return {lo_fraction, hi_fraction, true}; }
  /// The absolute window for `reference` (ignored when absolute). Throws panoptes::Error when the
  /// result is empty or not finite (e.g. a relative window with reference 0 — use a tiny floor).
  ValueWindow resolve(double reference) const;
};

/// A piecewise-linear transfer function over the normalized window coordinate u ∈ [0, 1]:
/// colour(u) and extinction(u), constant beyond the first/last control point. With
/// `absolute_value` the field value v is replaced by |v| before windowing (one colour for both
/// signs of a signed field such as φp = ∇·v).
struct TransferFunction {
  std::vector<ColourPoint> colour{{0, {1, 1, 1}}, {1, {1, 1, 1}}};
  std::vector<OpacityPoint> opacity{{0, 0}, {1, 1}};
  bool absolute_value = false;

  Rgb colour_at(float u) const;
  float extinction_at(float u) const;
  /// Throws panoptes::Error unless both lists are non-empty, x is non-decreasing in [0, 1],
  /// colours are in [0, 1] and extinctions are finite and ≥ 0.
  void validate() const;

  /// A constant colour and extinction (exactly σ everywhere: the slab test uses it).
  static TransferFunction constant(Rgb colour, float extinction);
  /// Named presets: "p-wave" (orange, opacity rising with |v|), "s-wave" (green, same ramp),
  /// "diverging" (blue–white–red over a symmetric window, opacity rising with |v| away from the
  /// centre), "grayscale" (black→white, linear ramp), "hot" (black–red–yellow–white), "rainbow"
  /// (for slices). `extinction_scale` multiplies the preset's extinctions. Unknown names throw
  /// panoptes::Error listing the valid ones.
  static TransferFunction preset(std::string_view name, float extinction_scale = 1.0f);
  /// The preset names accepted by preset().
  static std::vector<std::string> preset_names();
};

/// One LUT entry: premultiplied colour (r·α, g·α, b·α), the sample opacity α, the unpremultiplied
/// colour and the sample's optical depth τ = σ·Δt (needed when two fields mix at a sample).
struct LutEntry {
  float pr, pg, pb, alpha;
  float r, g, b, tau;
};

/// A transfer function baked for one window and one sample distance: the hot loop computes
/// bin = clamp(int((v − lo)·scale), 0, n − 1) and reads one entry. Also answers, for any value
/// range, whether every value in it has zero opacity (empty-space skipping).
class TransferLut {
 public:
  static constexpr int kDefaultBins = 1024;
  TransferLut() = default;
  /// Bakes `tf` over the absolute window `window` for a sample distance of `step_voxels` voxels.
  TransferLut(const TransferFunction& tf, const ValueWindow& window, double step_voxels, int bins = kDefaultBins);

  int bin(float v) const {
    if (abs_) v = v < 0 ? -v : v;
    float u = (v - lo_) * scale_;
    u = u > 0 ? u : 0.0f;  // also maps NaN to bin 0
    u = u < last_ ? u : last_;
    return int(u);
  }
  const LutEntry& entry(int bin) const { return entries_[bin]; }
  const LutEntry& operator()(float v) const { return entries_[bin(v)]; }
  /// True when some value in [vmin, vmax] has non-zero opacity.
  bool visible(float vmin, float vmax) const;
  int bins() const { return int(entries_.size()); }
  float lo() const { return lo_; }
  float scale() const { return scale_; }
  bool absolute_value() const { return abs_; }

 private:
  std::vector<LutEntry> entries_;
  std::vector<int> visible_prefix_;  // visible_prefix_[i] = number of bins < i with alpha > 0
  float lo_ = 0, scale_ = 1, last_ = 0;
  bool abs_ = false;
};

/// The q-quantile (q ∈ [0, 1]) of |v| over the points of a view's brick (cells [lo, hi] points),
/// estimated from at most `max_samples` evenly strided points. A reference value for relative
/// windows; in a distributed run reduce it over ranks (e.g. take the maximum).
double abs_percentile(const FieldView& f, double q, std::size_t max_samples = 1u << 20);
/// max |v| over the brick's points.
double abs_max(const FieldView& f);

/// A running maximum of per-snapshot references (the paper's "range unknown beforehand" case):
/// the window only ever widens, so colours stay comparable across frames of a movie.
class RunningMax {
 public:
  /// Folds in this snapshot's value and returns the running maximum.
  double update(double snapshot_value);
  double value() const { return value_; }

 private:
  double value_ = 0;
};

}  // namespace panoptes::render
