#include "video/video_settings.hpp"

#include <array>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace panoptes::video {

namespace {
// x264's preset names (x264_preset_names); anything else makes avcodec_open2 fail with an unhelpful
// message, so it is refused up front with the list.
constexpr std::array<const char*, 10> kPresets = {"ultrafast", "superfast", "veryfast", "faster", "fast",
                                                  "medium",    "slow",      "slower",   "veryslow", "placebo"};
}  // namespace

void VideoSettings::validate() const {
  if (crf < 0 || crf > 51) throw Error("video settings: crf " + std::to_string(crf) + " is outside 0..51");
  bool known = false;
  std::string names;
  for (const char* p : kPresets) {
    known = known || preset == p;
    names += names.empty() ? p : std::string(", ") + p;
  }
  if (!known) throw Error("video settings: unknown x264 preset '" + preset + "' (expected one of " + names + ")");
  if (gop < 1 || gop > 100000)
    throw Error("video settings: gop " + std::to_string(gop) + " is outside 1..100000 frames");
  if (threads < 1 || threads > 64)
    throw Error("video settings: threads " + std::to_string(threads) + " is outside 1..64");
  if (!std::isfinite(fps) || fps <= 0 || fps > 1000)
    throw Error("video settings: fps " + std::to_string(fps) + " is outside (0, 1000]");
}

}  // namespace panoptes::video
