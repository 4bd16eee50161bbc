#pragma once
// Encoder settings of a movie; stored in the manifest so a database says how it was made.
#include <string>

namespace panoptes::video {

/// H.264 (libx264) settings. Defaults are chosen by measurement: see docs/formats.md.
struct VideoSettings {
  /// Quality: x264 constant rate factor, 0 (lossless) .. 51. For intra-only movies (gop 1) it is
  /// applied as a constant quantizer (x264 --qp), since each frame is encoded by a fresh encoder.
  int crf = 20;
  std::string preset = "superfast";    ///< x264 preset name
  int gop = 1;                         ///< keyframe interval in frames (1 = all intra)
  int threads = 1;                     ///< encoder threads per movie (many movies encode in parallel)
  double fps = 30;                     ///< nominal playback frame rate

  /// Throws panoptes::Error naming the bad field if a value is out of range.
  void validate() const;
};

}  // namespace panoptes::video
