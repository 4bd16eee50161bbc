#pragma once
// Shared x264 encoders for intra-only movies (private to the video module).
//
// An intra-only (gop 1) frame depends on no other frame, so the encoder that made it carries no state
// into the next one: one encoder can encode frames for any number of movies of the same size and
// settings, which all get the same stream headers (SPS/PPS). Writers used to open a fresh x264 per
// frame (its set-up was ~15 % of the demo's time); now each writer borrows an idle encoder from the
// pool of its size and settings for one frame, so there are as many encoders as frames encoded at
// once (about one per thread), and an open writer still holds only its muxer.
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "video/h264_encoder.hpp"
#include "video/video_settings.hpp"

struct AVCodecParameters;

namespace panoptes::video {

/// The idle encoders of one (width, height, settings); thread-safe. Lives while a writer holds it.
class IntraEncoderPool {
 public:
  /// The pool for frames of width x height (even) and `settings` (gop 1), created on first use and
  /// shared by every writer that asks while one holds it. Throws Error naming `path` if no encoder opens.
  static std::shared_ptr<IntraEncoderPool> shared(int width, int height, const VideoSettings& settings,
                                                  const std::string& path);
  IntraEncoderPool(int width, int height, const VideoSettings& settings, const std::string& path);
  ~IntraEncoderPool();
  IntraEncoderPool(const IntraEncoderPool&) = delete;
  IntraEncoderPool& operator=(const IntraEncoderPool&) = delete;

  /// The stream parameters (codec, size, SPS/PPS extradata) every encoder of the pool writes.
  const AVCodecParameters* parameters() const { return parameters_; }

  /// An idle encoder, or a new one if all are busy. Give it back with release().
  std::unique_ptr<H264Encoder> acquire(const std::string& path);
  /// Returns an encoder to the idle list (one that is still usable: no flush was sent).
  void release(std::unique_ptr<H264Encoder> encoder);

  /// x264's version-and-options SEI NAL units (Annex B, with start codes), which x264 puts into the
  /// first packet of each encoder: remember_sei() keeps the first copy seen, sei() returns it so every
  /// movie carries it once, in its first packet, whichever encoder made that.
  void remember_sei(const std::vector<std::uint8_t>& sei);
  std::vector<std::uint8_t> sei() const;

  /// Encoders the pool has opened so far (tests, reports).
  int encoders_opened() const;

 private:
  std::unique_ptr<H264Encoder> open(const std::string& path);

  int width_, height_;
  VideoSettings settings_;
  AVCodecParameters* parameters_ = nullptr;
  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<H264Encoder>> idle_;
  std::vector<std::uint8_t> sei_;
  int opened_ = 0;
};

}  // namespace panoptes::video
