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

namespace {

// A 1x1 anti-aliased isosurface partial at depth d with its sliver state (PartialImage::slivers):
// colour `closed` if no sliver is open at its front, `open` if one is, and its end state.
PartialImage sliver_part(std::array<float, 4> closed, std::array<float, 4> open, SliverEnd end, float d) {
  PartialImage p;
  p.slivers = true;
  p.reset(1, 1, {0, 0, 1, 1});
  std::copy(closed.begin(), closed.end(), p.rgba_at(0, 0));
  std::copy(open.begin(), open.end(), p.rgba_open.begin());
  p.sliver_end[0] = end;
  p.depth[0] = d;
  return p;
}

}  // namespace

// A grazing sliver's entry in one brick and its exit in the brick behind: the exit adds nothing only
// because the front brick ends with the sliver open, so the join picks the back brick's colour for an
// open front; with the front ending closed the back brick's exit is a hit (its `rgba`). The join is
// the composition of functions of the state, so any grouping gives the same pixel.
TEST(PartialImage, SliverStateChainsFromBrickToBrick) {
  const PartialImage entry = sliver_part({0.3f, 0, 0, 0.3f}, {0.3f, 0, 0, 0.3f}, SliverEnd::open, 1);
  const PartialImage plain = sliver_part({0.2f, 0, 0, 0.2f}, {0.2f, 0, 0, 0.2f}, SliverEnd::closed, 1);
  const PartialImage pass = sliver_part({0.1f, 0.1f, 0, 0.1f}, {0.1f, 0.1f, 0, 0.1f}, SliverEnd::pass, 2);
  // Its first event an exit: a hit (opaque) with nothing open at its front, nothing added with.
  const PartialImage exit = sliver_part({0, 0, 1, 1}, {0, 0, 0, 0}, SliverEnd::closed, 3);
  const PartialImage back = sliver_part({0, 1, 0, 1}, {0, 1, 0, 1}, SliverEnd::closed, 4);
  auto join = [](std::vector<const PartialImage*> parts) { return composite(TaskKind::isosurface, parts); };
  // Open in front (through a brick that passes the state on): the exit adds nothing, the back shows.
  const PartialImage a = join({&entry, &pass, &exit, &back});
  EXPECT_NEAR(px(a, 0, 0)[1], 0.7f * 0.1f + 0.7f * 0.9f, 1e-6);
  EXPECT_NEAR(px(a, 0, 0)[2], 0.0f, 1e-6);
  EXPECT_NEAR(px(a, 0, 0)[3], 1.0f, 1e-6);
  // Closed in front: the exit is a hit, the back is hidden.
  const PartialImage b = join({&plain, &pass, &exit, &back});
  EXPECT_NEAR(px(b, 0, 0)[1], 0.8f * 0.1f, 1e-6);
  EXPECT_NEAR(px(b, 0, 0)[2], 0.8f * 0.9f, 1e-6);
  // Associative: joined in pairs first, and in either order of arrival.
  for (const PartialImage* front : {&entry, &plain}) {
    const PartialImage whole = join({front, &pass, &exit, &back});
    const PartialImage fp = join({&exit, front, &pass}), xb = join({&back, &exit});
    const PartialImage ppx = join({&pass, &exit});
    for (const PartialImage& c : {join({&fp, &back}), join({front, &pass, &xb}), join({front, &ppx, &back})})
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(px(c, 0, 0)[k], px(whole, 0, 0)[k], 1e-6) << "channel " << k;
    EXPECT_EQ(fp.sliver_end[0], SliverEnd::closed);
  }
  // A join that only passes the state on stays pass; one whose result depends on its front keeps both colours.
  EXPECT_EQ(join({&pass, &pass}).sliver_end[0], SliverEnd::pass);
  const PartialImage pe = join({&pass, &exit});
  EXPECT_EQ(pe.sliver_end[0], SliverEnd::closed);
  EXPECT_NE(px(pe, 0, 0)[3], pe.rgba_open[3]);
}
