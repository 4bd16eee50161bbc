#pragma once
// Small helpers shared by the writer and the reader (private to the video module).
#include <string>

namespace panoptes::video {

/// FFmpeg's text for an AVERROR code.
std::string av_error_string(int err);

/// Lowers FFmpeg's log level to fatal once per process (x264 and the demuxer print a few lines per
/// movie otherwise; every failure reaches the caller as an exception). PANOPTES_FFMPEG_LOG=1 keeps
/// FFmpeg's own level for debugging.
void quiet_ffmpeg_logs();

}  // namespace panoptes::video
