// The partial-image room (partial_image.hpp): each kind's blend joins partial images (over in depth
// order, max by the maximum's key), associatively and whatever the order of arrival; the union of
// rects; the visibility order of bricks; refusals that name the sizes.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "render/partial_image.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

// A 4x3 image whose rect is `r`, every pixel of it the premultiplied colour `c` at depth `d`.
PartialImage flat(PixelRect r, std::array<float, 4> c, float d) {
  PartialImage p;
  p.reset(4, 3, r);
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      std::copy(c.begin(), c.end(), p.rgba_at(x, y));
      p.depth[std::size_t(y - r.y0) * std::size_t(r.width()) + std::size_t(x - r.x0)] = d;
    }
  return p;
}

std::array<float, 4> px(const PartialImage& p, int x, int y) {
  if (!p.rect.contains(x, y)) return {0, 0, 0, 0};
  const float* v = p.rgba_at(x, y);
  return {v[0], v[1], v[2], v[3]};
}

}  // namespace

TEST(PartialImage, OverJoinsFrontToBackByDepthWhateverTheOrderOfArrival) {
  const PixelRect all{0, 0, 4, 3};
  const PartialImage front = flat(all, {0.5f, 0, 0, 0.5f}, 1.0f), back = flat(all, {0, 0.8f, 0, 0.8f}, 2.0f);
  for (const auto& parts : {std::vector<const PartialImage*>{&front, &back}, std::vector<const PartialImage*>{&back, &front}}) {
    const PartialImage c = composite(TaskKind::volume, parts);
    // acc = front + (1 − 0.5)·back
    EXPECT_FLOAT_EQ(px(c, 2, 1)[0], 0.5f);
    EXPECT_FLOAT_EQ(px(c, 2, 1)[1], 0.4f);
    EXPECT_FLOAT_EQ(px(c, 2, 1)[3], 0.9f);
    EXPECT_FLOAT_EQ(c.depth_at(2, 1), 1.0f);  // the nearest
  }
}

TEST(PartialImage, MaxKeepsThePartialWithTheLargestMaximumWhole) {
  ASSERT_EQ(blend_of(TaskKind::mip), Blend::max);
  const PixelRect all{0, 0, 4, 3};
  // The front brick's maximum is smaller than the back brick's: over by entry depth would keep the
  // front's opaque colour; max keeps the back's.
  const PartialImage front = flat(all, {0.1f, 0.1f, 0.1f, 1}, max_key_depth(100)),
                     back = flat(all, {0.9f, 0.2f, 0.0f, 1}, max_key_depth(700));
  for (const auto& parts : {std::vector<const PartialImage*>{&front, &back}, std::vector<const PartialImage*>{&back, &front}}) {
    const PartialImage c = composite(TaskKind::mip, parts);
    EXPECT_EQ(px(c, 0, 0), (std::array<float, 4>{0.9f, 0.2f, 0.0f, 1}));
    EXPECT_EQ(c.depth_at(0, 0), max_key_depth(700));
    EXPECT_EQ(composite_ordered(TaskKind::mip, parts).rgba, c.rgba);  // a maximum has no order
  }
  // A max keeps one partial whole; over would blend translucent ones.
  const PartialImage a = flat(all, {0.2f, 0, 0, 0.5f}, max_key_depth(100)), b = flat(all, {0, 0.4f, 0, 0.5f}, max_key_depth(700));
  const std::vector<const PartialImage*> ab{&a, &b};
  EXPECT_EQ(px(composite(TaskKind::mip, ab), 0, 0), (std::array<float, 4>{0, 0.4f, 0, 0.5f}));
  EXPECT_EQ(px(composite(TaskKind::volume, ab), 0, 0), (std::array<float, 4>{0.1f, 0.4f, 0, 0.75f}));
  // No sample (+∞) loses to any sample, even a maximum at the window's low end (key 0).
  const PartialImage none = flat(all, {0, 0, 0, 0}, PartialImage::kNoDepth), low = flat(all, {0.2f, 0, 0, 1}, max_key_depth(0));
  const std::vector<const PartialImage*> nl{&none, &low};
  EXPECT_EQ(px(composite(TaskKind::mip, nl), 1, 1), (std::array<float, 4>{0.2f, 0, 0, 1}));
}

TEST(PartialImage, JoinsAreAssociative) {
  const PixelRect all{0, 0, 4, 3};
  const PartialImage a = flat(all, {0.3f, 0.1f, 0, 0.4f}, 1), b = flat(all, {0, 0.5f, 0.1f, 0.6f}, 2),
                     c = flat(all, {0.2f, 0, 0.7f, 0.9f}, 3);
  for (const TaskKind k : kTaskKinds) {
    const std::vector<const PartialImage*> ab{&a, &b};
    const PartialImage left = composite(k, ab);
    const std::vector<const PartialImage*> left_c{&left, &c}, bc{&b, &c};
    const PartialImage right = composite(k, bc);
    const std::vector<const PartialImage*> a_right{&a, &right}, abc{&a, &b, &c};
    const PartialImage all3 = composite(k, abc), l = composite(k, left_c), r = composite(k, a_right);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(px(l, 1, 1)[std::size_t(i)], px(all3, 1, 1)[std::size_t(i)], 1e-6) << to_string(k);
      EXPECT_NEAR(px(r, 1, 1)[std::size_t(i)], px(all3, 1, 1)[std::size_t(i)], 1e-6) << to_string(k);
    }
  }
}

TEST(PartialImage, TheJoinCoversTheUnionOfTheRectsAndRefusesOtherSizes) {
  const PartialImage left = flat({0, 0, 2, 2}, {1, 0, 0, 1}, 1), right = flat({3, 1, 4, 3}, {0, 0, 1, 1}, 1);
  const std::vector<const PartialImage*> parts{&left, &right};
  const PartialImage c = composite(TaskKind::slice, parts);
  EXPECT_EQ(c.rect, (PixelRect{0, 0, 4, 3}));
  EXPECT_EQ(px(c, 2, 0), (std::array<float, 4>{0, 0, 0, 0}));  // between the rects: transparent
  EXPECT_EQ(c.depth_at(2, 0), PartialImage::kNoDepth);
  EXPECT_EQ(px(c, 3, 2)[2], 1.0f);
  PartialImage other;
  other.reset(5, 3, {0, 0, 5, 3});
  const std::vector<const PartialImage*> mixed{&left, &other};
  try {
    (void)composite(TaskKind::volume, mixed);
    ADD_FAILURE() << "images of different sizes were joined";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("5x3 vs 4x3"), std::string::npos) << e.what();
  }
}

TEST(PartialImage, VisibilityOrderPutsTheBrickNearerTheCameraFirst) {
  const GridGeometry g{{9, 9, 9}, {0, 0, 0}, {1, 1, 1}};
  const std::vector<Brick> bricks = {Brick::slab(g, 2, 2, 0), Brick::slab(g, 2, 2, 1)};
  const camera::Camera above({4, 4, 30}, {4, 4, 4}, {0, 1, 0}, 40, 16, 16);
  const camera::Camera below({4, 4, -30}, {4, 4, 4}, {0, 1, 0}, 40, 16, 16);
  EXPECT_EQ(visibility_order(above, g, bricks), (std::vector<int>{1, 0}));
  EXPECT_EQ(visibility_order(below, g, bricks), (std::vector<int>{0, 1}));
}
