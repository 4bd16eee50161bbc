#include "player/frame_cache.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace panoptes::player {
namespace {

std::shared_ptr<const video::YuvFrame> make_frame(int w, int h, int index) {
  auto f = std::make_shared<video::YuvFrame>();
  f->width = w, f->height = h, f->index = index;
  f->y.assign(std::size_t(w) * h, 16);
  f->u.assign(std::size_t((w + 1) / 2) * ((h + 1) / 2), 128);
  f->v = f->u;
  return f;
}

TEST(FrameCache, RespectsTheMemoryCapWithLruEviction) {
  const std::size_t one = frame_bytes(*make_frame(64, 64, 0));
  FrameCache cache(3 * one + one / 2);
  for (int i = 0; i < 10; ++i) {
    std::shared_ptr<const video::YuvFrame> out;
    ASSERT_EQ(cache.claim({0, i}, out), FrameCache::Claim::claimed);
    cache.finish({0, i}, make_frame(64, 64, i));
    EXPECT_LE(cache.bytes(), cache.capacity());
    if (i == 1) {  // touch frame 0 so it outlives frame 1
      ASSERT_EQ(cache.claim({0, 0}, out), FrameCache::Claim::cached);
    }
  }
  EXPECT_EQ(cache.size(), 3u);
  EXPECT_EQ(cache.evictions(), 7);
  EXPECT_TRUE(cache.contains({0, 9}));
  EXPECT_TRUE(cache.contains({0, 7}));
  EXPECT_FALSE(cache.contains({0, 1}));
}

TEST(FrameCache, FrameLargerThanTheCapIsNotCached) {
  FrameCache cache(100);
  std::shared_ptr<const video::YuvFrame> out;
  ASSERT_EQ(cache.claim({1, 1}, out), FrameCache::Claim::claimed);
  cache.finish({1, 1}, make_frame(64, 64, 1));
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_EQ(cache.bytes(), 0u);
}

TEST(FrameCache, SecondClaimWaitsForTheFirstDecode) {
  FrameCache cache(1 << 24);
  std::shared_ptr<const video::YuvFrame> out;
  ASSERT_EQ(cache.claim({2, 5}, out), FrameCache::Claim::claimed);
  EXPECT_EQ(cache.claim({2, 5}, out), FrameCache::Claim::in_flight);
  std::thread decoder([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    cache.finish({2, 5}, make_frame(32, 32, 5));
  });
  auto got = cache.wait({2, 5});
  decoder.join();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->index, 5);
  // A failed decode (null) wakes waiters with nothing cached.
  ASSERT_EQ(cache.claim({3, 0}, out), FrameCache::Claim::claimed);
  cache.finish({3, 0}, nullptr);
  EXPECT_EQ(cache.wait({3, 0}), nullptr);
}

}  // namespace
}  // namespace panoptes::player
