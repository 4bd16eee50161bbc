#pragma once
// A machine-readable stamp of (camera, task, frame) drawn into a frame's top-left corner, so tests and
// benchmarks can verify which frame a decoder or player shows. It survives H.264 at CRF <= 30 with
// 4:2:0 chroma: pure black/white luma blocks, each several pixels wide, read by thresholding block
// centres, guarded by a sync nibble and a CRC-16 so anything else decodes as "no valid stamp".
#include <cstdint>
#include <optional>

#include "core/image.hpp"

namespace panoptes {

/// What a stamp encodes. Ranges: camera < 2^24, task < 2^16, frame < 2^20.
struct FrameStamp {
  std::uint32_t camera = 0;
  std::uint32_t task = 0;
  std::uint32_t frame = 0;
  bool operator==(const FrameStamp&) const = default;
};

inline constexpr std::uint32_t kStampMaxCamera = (1u << 24) - 1;
inline constexpr std::uint32_t kStampMaxTask = (1u << 16) - 1;
inline constexpr std::uint32_t kStampMaxFrame = (1u << 20) - 1;

/// Geometry of the stamp for an image size: a grid of kStampColumns x kStampRows square blocks of
/// `block` pixels at the top-left corner (block = max(4, min(width, height) / 64)).
struct StampGeometry {
  int block = 4;
  int width() const;   ///< pixels covered horizontally
  int height() const;  ///< pixels covered vertically
};
inline constexpr int kStampColumns = 10;
inline constexpr int kStampRows = 8;

/// The stamp geometry used for a width x height image. Throws Error if the image is smaller than the
/// smallest stamp (40 x 32 pixels).
StampGeometry stamp_geometry(int width, int height);

/// Draws the stamp into image (3 or 4 channels; alpha set to 255). Throws Error if a value is out of
/// range or the image is too small.
void draw_frame_stamp(Image& image, const FrameStamp& stamp);

/// Reads the stamp back; std::nullopt if there is no valid stamp (blocks not clearly black/white,
/// wrong sync or checksum, image too small).
std::optional<FrameStamp> read_frame_stamp(const Image& image);

}  // namespace panoptes
