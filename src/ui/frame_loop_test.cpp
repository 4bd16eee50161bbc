#include "ui/frame_loop.hpp"

#include <gtest/gtest.h>

using namespace panoptes::ui;

// Nothing changes: no drawing, a long wait; a key draws at once and once more to settle ImGui; then
// quiet again until the slow refresh; playing looks at the clock every few milliseconds.
TEST(FrameLoop, DrawsOnlyWhenSomethingChanged) {
  FrameLoop loop;
  double t = 10;
  EXPECT_TRUE(loop.should_draw({}, t)) << "the first frame";
  loop.drawn(t);
  EXPECT_FALSE(loop.should_draw({}, t + 0.01));
  EXPECT_GE(loop.wait_ms(false, t + 0.01), 400);
  EXPECT_EQ(loop.wait_ms(true, t + 0.01), FrameLoop::kPlayingPoll);

  t += 0.1;
  EXPECT_TRUE(loop.should_draw({.input = true}, t));
  loop.drawn(t);
  EXPECT_EQ(loop.wait_ms(false, t), 0) << "the settling frame follows at once";
  EXPECT_TRUE(loop.should_draw({}, t + 0.01));
  loop.drawn(t + 0.01);
  EXPECT_FALSE(loop.should_draw({}, t + 0.02));
  EXPECT_TRUE(loop.should_draw({.new_frame = true}, t + 0.03));
  loop.drawn(t + 0.03);
  EXPECT_TRUE(loop.should_draw({}, t + 0.04));  // settle
  loop.drawn(t + 0.04);
  EXPECT_FALSE(loop.should_draw({}, t + 0.2));
  EXPECT_TRUE(loop.should_draw({}, t + 0.04 + FrameLoop::kIdleRefresh)) << "the slow refresh";
  EXPECT_TRUE(loop.should_draw({.every_frame = true}, t + 0.05)) << "virtual time draws every iteration";
}
