#pragma once
// Colour legends (issue 34): what a task's colours stand for, in physical values and units, at one
// frame. Built from the manifest alone (the transfer function's control points, the window and, for
// relative windows, the field's per-frame reference), so every front end shows the same numbers.
#include <array>
#include <string>
#include <vector>

#include "store/manifest.hpp"

namespace panoptes::player {

/// Optical depth (in voxels) a volume's legend colours are drawn at: a sample's colour is shown with
/// the opacity 1 − exp(−σ·kLegendDepthVoxels) over black, the renderer's background, so transparent
/// values look dark as they do in the picture. (A slice's legend shows its colour map as the slice is
/// drawn: opaque.)
inline constexpr double kLegendDepthVoxels = 4;
/// Colours sampled along a bar (evenly over the window, both ends included).
inline constexpr int kLegendSamples = 32;

/// One colour bar (or, for an isosurface, one swatch) of a task.
struct LegendBar {
  std::string field;   ///< field name, e.g. "phi_p"
  std::string label;   ///< what the axis shows: "|phi_p|" when the transfer function colours |v|
  std::string units;   ///< the field's unit ("" = unknown)
  double lo = 0, hi = 1;  ///< window in physical values (an isosurface: lo == hi == the isovalue)
  /// False when the window is relative and the manifest does not record the reference (older
  /// databases): lo and hi are then fractions of that unknown reference.
  bool physical = true;
  bool isovalue = false;  ///< an isosurface: one value, one colour
  /// Colours (r, g, b in [0, 1]) as the task draws them (drawn_colours()) at kLegendSamples evenly
  /// spaced values from lo to hi; one entry for an isovalue; empty when the manifest does not record
  /// the transfer function (the bar then shows numbers only).
  std::vector<std::array<float, 3>> colours;
  /// What the reference follows (issue 41): "running" (the largest so far: a colour keeps its value
  /// along the movie), "snapshot" (each frame its own: brightness is not comparable across frames),
  /// "fixed" (a physical value); empty for absolute windows and where nothing is recorded.
  std::string scale;
  /// A two-field picture whose fields share one reference (the larger of the two).
  bool shared = false;
  /// This frame's reference over the previous frame's (1 = the scale did not change; 0 = unknown).
  double change = 1;
};

/// The colours the transfer function `tf_key` of `task` ("transfer_function" or "transfer_function2" of
/// its manifest parameters) puts on screen at `samples` (>= 2) evenly spaced window positions, both ends
/// included: a slice's colour map as the slice renderer writes it (opaque: render/march_plan.cpp's
/// slice_opacity, recorded as "slice_opacity" when not 1, over black), a MIP's ("mip") opaque as well
/// (the colour map at each ray's maximum), a volume's as a
/// kLegendDepthVoxels-thick layer over black. Empty when the manifest does not record them.
std::vector<std::array<float, 3>> drawn_colours(const store::TaskEntry& task, const char* tf_key, int samples);

/// The bars of `task` at `frame` (two for a two-field volume, none for tasks without a window, e.g.
/// synthetic ones). Never throws on a malformed or older manifest: what cannot be read is left out.
std::vector<LegendBar> task_legend(const store::Manifest& manifest, int task, int frame);

/// A value as the legend prints it: 3 significant digits, "0" for zero, e.g. "2.41e-03", "0.015", "120".
std::string legend_number(double value);
/// "0 .. 2.41e-03 1/s", "0.2 .. 1 x reference" (not physical), "iso 0.015 1/s".
std::string legend_range_text(const LegendBar& bar);
/// What the scale follows and whether it just changed, e.g. "running max", "per snapshot: x2.3 since
/// the previous frame", "fixed", "running max, shared with phi_s"; "" for an absolute window.
std::string legend_scale_text(const LegendBar& bar, const std::string& shared_with = "");
/// Its two parts, for front ends that draw them on two lines: the mode ("running max, shared with
/// phi_s") and the change ("x2.3 since the previous frame"; "" when the scale did not change).
std::string legend_scale_mode_text(const LegendBar& bar, const std::string& shared_with = "");
std::string legend_change_text(const LegendBar& bar);
/// "t = 4.2 s" (time and the manifest's time unit; no unit when it has none).
std::string time_text(const store::Manifest& manifest, double time);

}  // namespace panoptes::player
