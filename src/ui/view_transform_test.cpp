#include "ui/view_transform.hpp"

#include <gtest/gtest.h>

namespace panoptes::ui {
namespace {

TEST(ViewTransform, ZoomOneFitsAndCentresTheFrame) {
  ViewTransform v;
  v.set_sizes(800, 600, 400, 400);  // limited by height: scale 1.5, pillar-boxed
  const Rect r = v.frame_rect();
  EXPECT_DOUBLE_EQ(v.scale(), 1.5);
  EXPECT_DOUBLE_EQ(r.w, 600);
  EXPECT_DOUBLE_EQ(r.h, 600);
  EXPECT_DOUBLE_EQ(r.x, 100);
  EXPECT_DOUBLE_EQ(r.y, 0);
}

TEST(ViewTransform, SameSizeIsOneToOne) {
  ViewTransform v;
  v.set_sizes(320, 240, 320, 240);
  const Rect r = v.frame_rect();
  EXPECT_DOUBLE_EQ(r.x, 0);
  EXPECT_DOUBLE_EQ(r.y, 0);
  EXPECT_DOUBLE_EQ(r.w, 320);
  EXPECT_DOUBLE_EQ(r.h, 240);
}

TEST(ViewTransform, ZoomKeepsThePointUnderTheCursor) {
  ViewTransform v;
  v.set_sizes(800, 600, 800, 600);
  double fx0, fy0;
  v.window_to_frame(200, 150, fx0, fy0);
  v.zoom_at(2.0, 200, 150);
  EXPECT_DOUBLE_EQ(v.zoom(), 2.0);
  double wx, wy;
  v.frame_to_window(fx0, fy0, wx, wy);
  EXPECT_NEAR(wx, 200, 1e-9);
  EXPECT_NEAR(wy, 150, 1e-9);
  // A second zoom at another point also keeps that point fixed.
  v.window_to_frame(500, 400, fx0, fy0);
  v.zoom_at(1.5, 500, 400);
  v.frame_to_window(fx0, fy0, wx, wy);
  EXPECT_NEAR(wx, 500, 1e-9);
  EXPECT_NEAR(wy, 400, 1e-9);
}

TEST(ViewTransform, ZoomIsClampedAndZoomingOutRecentres) {
  ViewTransform v;
  v.set_sizes(100, 100, 100, 100);
  for (int i = 0; i < 20; ++i) v.zoom_at(2.0, 10, 10);
  EXPECT_DOUBLE_EQ(v.zoom(), ViewTransform::kMaxZoom);
  for (int i = 0; i < 20; ++i) v.zoom_at(0.5, 90, 90);
  EXPECT_DOUBLE_EQ(v.zoom(), ViewTransform::kMinZoom);
  const Rect r = v.frame_rect();  // below zoom 1 the frame sits in the middle
  EXPECT_DOUBLE_EQ(r.x + r.w / 2, 50);
  EXPECT_DOUBLE_EQ(r.y + r.h / 2, 50);
}

TEST(ViewTransform, PanMovesThePictureAndStopsAtTheFrameEdge) {
  ViewTransform v;
  v.set_sizes(200, 200, 200, 200);
  v.pan(30, 0);  // at zoom 1 there is nothing to pan
  EXPECT_DOUBLE_EQ(v.frame_rect().x, 0);
  v.zoom_at(4.0, 100, 100);
  const double x0 = v.frame_rect().x;
  v.pan(30, -10);
  EXPECT_DOUBLE_EQ(v.frame_rect().x, x0 + 30);
  v.pan(1e6, 1e6);  // the viewport centre cannot leave the frame
  double fx, fy;
  v.window_to_frame(100, 100, fx, fy);
  EXPECT_DOUBLE_EQ(fx, 0);
  EXPECT_DOUBLE_EQ(fy, 0);
  v.reset();
  EXPECT_DOUBLE_EQ(v.zoom(), 1);
  EXPECT_DOUBLE_EQ(v.frame_rect().x, 0);
}

}  // namespace
}  // namespace panoptes::ui
