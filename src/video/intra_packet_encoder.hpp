#pragma once
// Encodes frames of intra-only (gop 1) movies straight into MP4 samples, without a muxer: the packed
// store keeps no per-movie FFmpeg state between frames (see docs/formats.md, Packed layout).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "video/packet_checksum.hpp"
#include "video/video_settings.hpp"

namespace panoptes::video {

class IntraEncoderPool;

/// Shared by every movie of one frame size and settings (gop 1); thread-safe. A frame comes out as the
/// sample MovieWriter would have muxed for it: the same checksum message (version 2 with the movie's
/// identity and the frame's index, or version 1 without), x264's version SEI in each movie's first
/// frame, NAL units with 4-byte lengths.
class IntraPacketEncoder {
 public:
  /// Frames of width x height (odd sizes padded to even like MovieWriter). Throws Error on bad settings
  /// (gop must be 1) or when no encoder opens; `name` names the output in messages.
  IntraPacketEncoder(int width, int height, const VideoSettings& settings, const std::string& name);
  ~IntraPacketEncoder();
  IntraPacketEncoder(const IntraPacketEncoder&) = delete;
  IntraPacketEncoder& operator=(const IntraPacketEncoder&) = delete;

  int padded_width() const { return padded_width_; }
  int padded_height() const { return padded_height_; }
  /// The stream header every sample decodes with (Annex B SPS and PPS), for make_init_segment().
  const std::vector<std::uint8_t>& header() const { return header_; }

  /// Encodes `frame` (3 or 4 channels, the size given at construction) as frame `index` of the movie
  /// with `identity` (stamped into its checksum message; bound to the parameter sets when `bind`) and
  /// appends the sample to `out`. Returns the sample's size. Throws Error on a bad frame or an
  /// encoder failure.
  std::size_t encode(const Image& frame, std::uint32_t index, const std::optional<MovieIdentity>& identity, bool bind,
                     std::vector<std::uint8_t>& out);

 private:
  int width_, height_, padded_width_, padded_height_;
  std::string name_;
  std::shared_ptr<IntraEncoderPool> pool_;
  std::vector<std::uint8_t> header_;
  std::uint32_t header_crc_ = 0;
};

}  // namespace panoptes::video
