#pragma once
// One libx264 encoder with its YUV frame and RGB(A) -> YUV converters, as MovieWriter configures it
// (private to the video module). Used by one thread at a time.
#include <cstdint>
#include <string>
#include <vector>

#include "video/video_settings.hpp"

struct AVCodecContext;
struct AVFrame;
struct AVPacket;
struct SwsContext;

namespace panoptes::video {

/// An open x264 encoder for frames of width x height (both even) and the machinery that feeds it.
/// The settings are those of docs/formats.md: no B-frames, no look-ahead, slice threads, BT.601
/// limited range; for gop 1 the crf value is a constant quantizer.
struct H264Encoder {
  /// Opens the encoder. `global_header`: stream headers (SPS/PPS) go to extradata, as MP4 needs.
  /// Throws Error naming `path` (the movie it is opened for) if libx264 is missing or refuses.
  H264Encoder(int width, int height, const VideoSettings& settings, bool global_header, const std::string& path);
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  /// Converts a packed RGB (3 channels) or RGBA (4) picture of the encoder's size into `frame`.
  void convert(const std::uint8_t* pixels, int stride, int channels);

  AVCodecContext* context = nullptr;
  AVFrame* frame = nullptr;       ///< the YUV 4:2:0 picture convert() fills
  std::int64_t frames_sent = 0;   ///< frames sent to the encoder so far (its own pts counter)

 private:
  SwsContext* sws_rgb_ = nullptr;
  SwsContext* sws_rgba_ = nullptr;
  std::string path_;
};

/// Removes the SEI NAL units (type 6) from an Annex B packet, in place, and appends them (each with a
/// 4-byte start code) to `removed` if given. A packet that is not Annex B is left alone.
void remove_sei(AVPacket* pkt, std::vector<std::uint8_t>* removed = nullptr);

/// Puts `bytes` (Annex B NAL units) in front of the packet's data. Throws Error if memory runs out.
void prepend_nal_units(AVPacket* pkt, const std::vector<std::uint8_t>& bytes);

}  // namespace panoptes::video
