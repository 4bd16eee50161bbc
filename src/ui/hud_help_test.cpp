#include <gtest/gtest.h>

#include <algorithm>

#include "player/keys.hpp"
#include "store/manifest.hpp"
#include "ui/hud.hpp"

namespace panoptes::ui {
namespace {

// Issue 34: the help overlay must fit the default window of the demo (1052 x 1020 on a 1920 x 1200
// display) — it used to list 51 lines in one column, with a scroll bar and its last lines under the
// time slider.
TEST(HudHelp, DigitKeysAndSynonymsShareLines) {
  const auto rows = help_rows();
  EXPECT_LE(rows.size(), 42u) << "one line per action, not per key";
  const auto has = [&](const std::string& key) {
    return std::any_of(rows.begin(), rows.end(), [&](const HelpRow& r) { return r.key == key; });
  };
  EXPECT_TRUE(has("1 .. 9"));
  EXPECT_TRUE(has("H / F1"));
  EXPECT_TRUE(has("Escape / Q"));
  EXPECT_TRUE(has("+ / ="));
  EXPECT_FALSE(has("5"));
  // Every binding of the shared key table still appears.
  for (const auto& b : player::key_bindings()) {
    const std::string key(b.key);
    const bool found = std::any_of(rows.begin(), rows.end(), [&](const HelpRow& r) {
      return r.key == key || r.key.find(key + " /") == 0 || r.key.find("/ " + key) != std::string::npos ||
             (key.size() == 1 && key[0] >= '1' && key[0] <= '9' && r.key == "1 .. 9");
    });
    EXPECT_TRUE(found) << key;
  }
}

TEST(HudHelp, LayoutFitsByColumnsThenByTextSizeButNotBelowTheBitmapFont) {
  // Fits in one column: nothing changes.
  HelpLayout l = help_layout(40, 20, 500, 1000, 900, 1.3f);
  EXPECT_EQ(l.pairs, 1);
  EXPECT_FLOAT_EQ(l.scale, 1);
  EXPECT_TRUE(l.fits);
  // Too tall, two columns fit the width: two pairs.
  l = help_layout(40, 20, 450, 1000, 600, 1.3f);
  EXPECT_EQ(l.pairs, 2);
  EXPECT_FLOAT_EQ(l.scale, 1);
  // Too tall and only one column wide: the text shrinks to fit...
  l = help_layout(40, 20, 600, 1000, 700, 1.3f);
  EXPECT_EQ(l.pairs, 1);
  EXPECT_NEAR(l.scale, 700.f / 800.f, 1e-6);
  EXPECT_LE(40 * 20 * l.scale, 700.f + 1e-3f);
  // ... but never below the bitmap font's own size (then it scrolls).
  EXPECT_TRUE(l.fits);
  l = help_layout(40, 20, 600, 1000, 300, 1.3f);
  EXPECT_NEAR(l.scale, 1 / 1.3f, 1e-6);
  EXPECT_FALSE(l.fits);
  l = help_layout(40, 20, 600, 1000, 300, 1.0f);
  EXPECT_FLOAT_EQ(l.scale, 1);
}

// Issue 32.2: in a lattice 360° database the help says the arrows walk and + / - change the field of
// view, and no longer mentions rotating or magnifying; the rig help keeps its wording.
TEST(HudHelp, WordedForTheDatabaseAtHand) {
  const auto text = [](HelpMode mode) {
    std::string all;
    for (const auto& r : help_rows(mode)) all += r.key + ": " + r.what + "\n";
    return all;
  };
  const std::string walk = text(HelpMode::walk), rig = text(HelpMode::rig), look = text(HelpMode::look);
  EXPECT_NE(walk.find("Up: walk forward"), std::string::npos) << walk;
  EXPECT_NE(walk.find("PageUp: walk up"), std::string::npos) << walk;
  EXPECT_NE(walk.find("field of view"), std::string::npos);
  EXPECT_EQ(walk.find("rotate"), std::string::npos) << walk;
  EXPECT_EQ(walk.find("magnify around the cursor"), std::string::npos) << walk;
  EXPECT_EQ(walk.find("A: "), std::string::npos) << "A does nothing inside a lattice: no row";
  // Z / X step along the lattice's north axis (a path's order): inside, there are no camera shells.
  EXPECT_NE(walk.find("Z: step north"), std::string::npos) << walk;
  EXPECT_EQ(walk.find("camera shell"), std::string::npos) << walk;
  EXPECT_NE(look.find("look around"), std::string::npos);
  EXPECT_NE(look.find("rotate: camera"), std::string::npos) << "a 360° sphere rig still rotates with the arrows";
  EXPECT_NE(rig.find("Up: rotate"), std::string::npos);
  EXPECT_NE(rig.find("magnify"), std::string::npos);
  EXPECT_EQ(rig.find("walk"), std::string::npos);
}

// The demo's database (one Yin-Yang shell, no parameter axes) gets no PgUp / PgDn / A / Z / X / C rows:
// a first-time user pressing them would see nothing happen.
TEST(HudHelp, OnlyKeysTheDatabaseCanUse) {
  store::Manifest m;
  m.graph.neighbours.assign(2, store::Neighbours{.left = 1, .right = 1, .up = 1, .down = 1});
  const auto text = [&] {
    std::string all;
    for (const auto& r : help_rows(HelpMode::rig, &m)) all += r.key + ": " + r.what + "\n";
    return all;
  };
  std::string rig = text();
  for (const char* key : {"PageUp: ", "PageDown: ", "A: ", "Z: ", "X: ", "C: "})
    EXPECT_EQ(rig.find(std::string("\n") + key), std::string::npos) << key << " in\n" << rig;
  EXPECT_NE(rig.find("Up: rotate"), std::string::npos) << rig;
  m.axes = {store::ParameterAxis{"isovalue", {0.1, 0.2}, ""}};
  m.graph.neighbours[0].in = 1;
  m.graph.neighbours[1].out = 0;
  rig = text();
  for (const char* key : {"PageUp: ", "PageDown: ", "A: ", "Z: ", "X: "})
    EXPECT_NE(rig.find(std::string("\n") + key), std::string::npos) << key << " missing in\n" << rig;
}

}  // namespace
}  // namespace panoptes::ui
