#include "video/video_settings.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace panoptes::video {
namespace {

std::string message_of(const VideoSettings& s) {
  try {
    s.validate();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(VideoSettings, DefaultsAreValid) { EXPECT_NO_THROW(VideoSettings{}.validate()); }

TEST(VideoSettings, BadValuesNameTheField) {
  VideoSettings s;
  s.crf = 52;
  EXPECT_NE(message_of(s).find("crf 52"), std::string::npos);
  s = {};
  s.preset = "turbo";
  EXPECT_NE(message_of(s).find("unknown x264 preset 'turbo'"), std::string::npos);
  EXPECT_NE(message_of(s).find("veryfast"), std::string::npos);
  s = {};
  s.gop = 0;
  EXPECT_NE(message_of(s).find("gop 0"), std::string::npos);
  s = {};
  s.threads = 0;
  EXPECT_NE(message_of(s).find("threads 0"), std::string::npos);
  s = {};
  s.fps = -1;
  EXPECT_NE(message_of(s).find("fps"), std::string::npos);
}

}  // namespace
}  // namespace panoptes::video
