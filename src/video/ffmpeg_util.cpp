#include "video/ffmpeg_util.hpp"

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include <cstdlib>
#include <mutex>

namespace panoptes::video {

std::string av_error_string(int err) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(err, buf, sizeof buf);
  return buf;
}

void quiet_ffmpeg_logs() {
  static std::once_flag once;
  std::call_once(once, [] {
    const char* keep = std::getenv("PANOPTES_FFMPEG_LOG");
    if (!keep || std::string(keep) != "1") av_log_set_level(AV_LOG_FATAL);
  });
}

}  // namespace panoptes::video
