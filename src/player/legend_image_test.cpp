#include "player/legend_image.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "player/legend.hpp"

using namespace panoptes;

namespace {

store::Manifest one_task() {
  store::Manifest m;
  m.fields = {{"phi_p", "1/s", {1e-5, 3e-5}, "running"}};
  const nlohmann::json tf = {{"colour", {{0, 1.0, 0.5, 0.0}, {1, 1.0, 0.5, 0.0}}}, {"extinction", {{0, 0}, {1, 2.0}}}};
  store::TaskEntry t;
  t.id = 0, t.name = "p", t.method = "volume", t.fields = {"phi_p"};
  t.parameters = {{"window", {0.0, 1.0}}, {"relative", true}, {"transfer_function", tf}};
  m.tasks = {t};
  return m;
}

}  // namespace

// The legend burnt into an exported frame (issue 41) shows the legend's colours and leaves the rest
// of the picture alone.
TEST(LegendImage, BarColoursAreTheLegendsAndTheRestIsUntouched) {
  const store::Manifest m = one_task();
  Image im(400, 390, 4);
  const int h = player::draw_legend(im, m, 0, 1);
  ASSERT_GT(h, 20);
  ASSERT_LT(h, 390 / 3) << "the panel must leave the picture visible";
  EXPECT_EQ(im.at(399, 0)[0], 0);  // far from the panel: untouched
  EXPECT_EQ(im.at(200, 390 - h - 1)[1], 0);
  // Find the bar: the row whose right end of the bar is orange at the legend's top colour.
  const auto bars = player::task_legend(m, 0, 1);
  const auto top = bars[0].colours.back();
  bool found = false;
  for (int y = 390 - h; y < 390 && !found; ++y)
    for (int x = 0; x < 130 && !found; ++x) {
      const std::uint8_t* p = im.at(x, y);
      found = std::abs(p[0] - int(std::lround(top[0] * 255))) <= 2 && std::abs(p[1] - int(std::lround(top[1] * 255))) <= 2 &&
              std::abs(p[2] - int(std::lround(top[2] * 255))) <= 2 && p[0] > 100;
    }
  EXPECT_TRUE(found) << "no pixel of the bar has the legend's top colour";
  // The scale changed (1e-5 -> 3e-5): its amber line is drawn.
  int amber = 0;
  for (int y = 390 - h; y < 390; ++y)
    for (int x = 0; x < 200; ++x) amber += im.at(x, y)[0] == 255 && im.at(x, y)[1] == 199 && im.at(x, y)[2] == 77;
  EXPECT_GT(amber, 10);
  // Frame 0: no change, no amber.
  Image first(400, 390, 4);
  player::draw_legend(first, m, 0, 0);
  int amber0 = 0;
  for (int y = 0; y < 390; ++y)
    for (int x = 0; x < 200; ++x) amber0 += first.at(x, y)[0] == 255 && first.at(x, y)[1] == 199;
  EXPECT_EQ(amber0, 0);
  // A task without a legend draws nothing.
  store::Manifest none = m;
  none.tasks[0].parameters = nlohmann::json::object();
  Image blank(64, 64, 3);
  EXPECT_EQ(player::draw_legend(blank, none, 0, 0), 0);
}
