#include "video/writer_memory.hpp"

#include <algorithm>

namespace panoptes::video {

namespace {
constexpr double kReferencePixels = 920.0 * 896.0;  // the frame size docs/formats.md measured
}

double open_writer_bytes(double pixels, int gop) {
  return gop > 1 ? 25e6 * std::max(pixels / kReferencePixels, 0.1) : 1.1e6;
}

double live_encoder_bytes(double pixels) { return 3.5e6 * std::max(pixels / kReferencePixels, 0.1); }

}  // namespace panoptes::video
