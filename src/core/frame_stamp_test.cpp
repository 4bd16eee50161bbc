#include "core/frame_stamp.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"

using namespace panoptes;

namespace {
Image gradient(int w, int h, int channels) {
  Image img(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      auto* p = img.at(x, y);
      p[0] = std::uint8_t(x * 255 / w);
      p[1] = std::uint8_t(y * 255 / h);
      p[2] = std::uint8_t((x + y) & 255);
      if (channels == 4) p[3] = 255;
    }
  return img;
}
}  // namespace

TEST(FrameStamp, RoundTripsAtTinyAndPaperSizes) {
  const FrameStamp values[] = {{0, 0, 0}, {1, 2, 3}, {kStampMaxCamera, kStampMaxTask, kStampMaxFrame},
                               {1u << 20, 1u << 12, 1u << 16}, {123456, 789, 54321}};
  for (auto [w, h] : {std::pair{64, 64}, std::pair{920, 896}, std::pair{41, 33}, std::pair{1920, 1080}})
    for (int channels : {3, 4})
      for (const auto& s : values) {
        Image img = gradient(w, h, channels);
        draw_frame_stamp(img, s);
        auto got = read_frame_stamp(img);
        ASSERT_TRUE(got.has_value()) << w << "x" << h;
        EXPECT_EQ(*got, s);
      }
}

TEST(FrameStamp, GeometryScalesWithImage) {
  EXPECT_EQ(stamp_geometry(64, 64).block, 4);
  EXPECT_EQ(stamp_geometry(920, 896).block, 14);
  EXPECT_LE(stamp_geometry(64, 64).width(), 64);
  EXPECT_THROW(stamp_geometry(39, 64), Error);
  EXPECT_THROW(stamp_geometry(64, 31), Error);
}

TEST(FrameStamp, SurvivesNoiseAndBlurOfBlockEdges) {
  Image img = gradient(64, 64, 4);
  const FrameStamp s{77777, 4000, 65536};
  draw_frame_stamp(img, s);
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> noise(-60, 60);
  for (auto& v : img.pixels) v = std::uint8_t(std::clamp(int(v) + noise(rng), 0, 255));
  // Smear every block edge the way a codec's deblocking would: average horizontally with the neighbour.
  Image blurred = img;
  for (int y = 0; y < 64; ++y)
    for (int x = 1; x < 63; ++x)
      for (int c = 0; c < 3; ++c)
        blurred.at(x, y)[c] = std::uint8_t((img.at(x - 1, y)[c] + 2 * img.at(x, y)[c] + img.at(x + 1, y)[c]) / 4);
  auto got = read_frame_stamp(blurred);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(*got, s);
}

TEST(FrameStamp, RejectsImagesWithoutAValidStamp) {
  EXPECT_FALSE(read_frame_stamp(gradient(64, 64, 4)).has_value());
  Image black(64, 64, 3);
  EXPECT_FALSE(read_frame_stamp(black).has_value());
  Image white(64, 64, 3);
  std::fill(white.pixels.begin(), white.pixels.end(), 255);
  EXPECT_FALSE(read_frame_stamp(white).has_value());
  EXPECT_FALSE(read_frame_stamp(Image(20, 20, 4)).has_value());

  // Random black/white blocks: the sync nibble and CRC reject them.
  std::mt19937 rng(7);
  int accepted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Image img(64, 64, 3);
    for (int b = 0; b < kStampColumns * kStampRows; ++b) {
      const std::uint8_t v = (rng() & 1) ? 255 : 0;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
          auto* p = img.at((b % kStampColumns) * 4 + x, (b / kStampColumns) * 4 + y);
          p[0] = p[1] = p[2] = v;
        }
    }
    accepted += read_frame_stamp(img).has_value();
  }
  EXPECT_EQ(accepted, 0);

  // Every single flipped block of a valid stamp is detected.
  Image img = gradient(64, 64, 3);
  draw_frame_stamp(img, {5, 6, 7});
  for (int b = 0; b < kStampColumns * kStampRows; ++b) {
    Image flipped = img;
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        auto* p = flipped.at((b % kStampColumns) * 4 + x, (b / kStampColumns) * 4 + y);
        p[0] = p[1] = p[2] = std::uint8_t(255 - p[0]);
      }
    EXPECT_FALSE(read_frame_stamp(flipped).has_value()) << "block " << b;
  }
}

TEST(FrameStamp, RefusesOutOfRangeValuesAndTinyImages) {
  Image img(64, 64, 4);
  EXPECT_THROW(draw_frame_stamp(img, {kStampMaxCamera + 1, 0, 0}), Error);
  EXPECT_THROW(draw_frame_stamp(img, {0, kStampMaxTask + 1, 0}), Error);
  EXPECT_THROW(draw_frame_stamp(img, {0, 0, kStampMaxFrame + 1}), Error);
  Image tiny(16, 16, 4);
  try {
    draw_frame_stamp(tiny, {1, 1, 1});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("16x16 is too small"), std::string::npos) << e.what();
  }
}
