#pragma once
// The value under the cursor of a slice task (issue 41), read back from the picture: a slice is drawn
// opaque with its colour map over the window [lo, hi] (the relative window × the frame's recorded
// reference, or an absolute window), so a pixel's colour names a value — the nearest colour along the
// map. Neither ParaView nor Ascent can do this from a movie: there the data is gone once rendered.
// UI-free: the window's HUD reads it directly, and the web player gets the same colour table and rule
// through database.json (slice_readout_json) and only searches it (web/player/readout.js).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vec3.hpp"
#include "store/manifest.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::player {

/// Bins of the slice renderer's colour table (render::TransferLut::kDefaultBins): the colour a value
/// gets is the map's colour at the centre of its bin.
inline constexpr int kReadoutBins = 1024;
/// A pixel farther than this (Euclidean, in 8-bit RGB levels) from every colour of the map is not a
/// reading (the background, the outline, a HUD colour, or damage). Measured on the test's H.264 slice
/// (value_readout_test.cpp, default CRF): interior slice pixels lie a median 1.4, p99 5.1, at most 10.8
/// levels from the nearest map colour; the outline's grey is about 25 from the diverging map.
inline constexpr double kReadoutMaxDistance = 20;
/// Colours within this many levels of the nearest one count as equally good matches; when their
/// window positions spread over more than kReadoutMaxSpread of the window the reading is ambiguous
/// (a map that comes back to a colour, or a flat stretch of it) and none is given.
inline constexpr double kReadoutMargin = 3;
inline constexpr double kReadoutMaxSpread = 0.05;
/// The value is the mean window position of the colours within this many levels of the nearest one
/// (H.264 moves a colour off the map's curve; several neighbours along it then match about equally):
/// on the test slice it lowered the worst error from 16.4 to 13.2 resolution steps (p95 3.99 -> 3.72).
inline constexpr double kReadoutCentroidBand = 1;
/// The readout's stated uncertainty, in resolution steps: the 95th percentile of |read - true| measured
/// on an H.264 slice (value_readout_test.cpp, docs/ui.md).
inline constexpr double kReadoutUncertaintySteps = 4;

/// The colour map of a slice task as the renderer puts it on screen, run-length coded: consecutive
/// renderer bins that write the same 8-bit colour form one entry, located at the mean window position
/// (0..1) of its bins. The number of entries is the map's count of distinguishable colours.
struct SliceColourTable {
  std::vector<std::array<std::uint8_t, 3>> colours;
  std::vector<double> u;
};

/// Everything needed to read a slice task's pixels at one frame.
struct SliceReadout {
  bool usable = false;  ///< false: not a slice, or the manifest lacks its colour map or window
  std::string field, label, units;  ///< label "|v|" when the map colours the absolute value
  double lo = 0, hi = 1;            ///< the window in physical values at this frame (see physical)
  bool physical = true;             ///< false: the reference is not recorded; lo/hi are fractions of it
  SliceColourTable table;
  int axis = 2;         ///< the slice plane: world coordinate `position` along axis 0/1/2
  double position = 0;
  bool have_box = false;  ///< the domain box is recorded: off-slice pixels can be told geometrically
  Vec3 box_lo, box_hi;
  /// Window width / number of distinguishable colours: the finest step a colour can name.
  double resolution() const;
};

/// The readout of `task` at `frame` (usable == false for tasks that are not slices). Never throws on
/// a malformed or older manifest.
SliceReadout slice_readout(const store::Manifest& manifest, int task, int frame);

/// What a pixel says.
struct ValueReading {
  enum class Kind {
    value,  ///< the value, within resolution()
    below,  ///< at or below the window's low end (the map's first colour): value is lo
    above,  ///< at or above the high end: value is hi
    none,   ///< no reading: `reason` says why
  };
  Kind kind = Kind::none;
  double value = 0;
  double resolution = 0;       ///< the colour map's step: window width / distinguishable colours
  double uncertainty = 0;      ///< what the text states: kReadoutUncertaintySteps x resolution
  double colour_distance = 0;  ///< RGB levels from the pixel to the matched colour
  std::string reason;          ///< for none: "off the slice", "not a colour of the map", "ambiguous colour"
};

/// The value a colour stands for (no geometry).
ValueReading read_colour(const SliceReadout& readout, std::array<int, 3> rgb);
/// True when the ray of pixel (x, y) of `camera`'s image meets the slice plane inside the domain box
/// (the renderer's Camera::ray through the pixel's centre); true when the box is not recorded.
bool pixel_on_slice(const store::Manifest& manifest, const SliceReadout& readout, int camera, int x, int y);
/// read_colour of the pixel, or none ("off the slice") when the pixel's ray misses the slice.
ValueReading read_pixel(const store::Manifest& manifest, const SliceReadout& readout, int camera, int x, int y,
                        std::array<int, 3> rgb);

/// "phi_p = 1.23e-05 1/s  (+-8.4e-07)" (the uncertainty), "phi_p <= -1.2e-04 1/s", "no reading: off the slice".
std::string reading_text(const SliceReadout& readout, const ValueReading& reading);

/// The RGB of pixel (x, y) of a decoded frame, converted as the players show it (BT.601, limited range,
/// the chroma sample covering the pixel). Throws panoptes::Error naming the pixel when it is outside.
std::array<int, 3> rgb_at(const video::YuvFrame& frame, int x, int y);

/// The table, plane and rule of a slice task as the web player reads them: {"colours": [[r, g, b], ...],
/// "u": [...] (to 1e-6), "axis", "position", "box_lo", "box_hi", "max_distance", "margin", "max_spread",
/// "centroid_band", "uncertainty_steps"}; null for tasks without a readout. Frame-independent: the
/// player scales u by the frame's window, as for the legend. (database.json moves colours and u into
/// a shared readout_tables entry that the task's "table" names.)
nlohmann::json slice_readout_json(const store::Manifest& manifest, int task);

}  // namespace panoptes::player
