#include "player/keys.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <set>
#include <string>

#include "player/controls.hpp"
#include "player/keys_json.hpp"

namespace panoptes::player {
namespace {

TEST(Keys, PaperKeysMapToEngineActions) {
  EXPECT_EQ(action_for_key("Right"), Action::camera_right);
  EXPECT_EQ(action_for_key("Left"), Action::camera_left);
  EXPECT_EQ(action_for_key("Up"), Action::camera_up);
  EXPECT_EQ(action_for_key("Down"), Action::camera_down);
  EXPECT_EQ(action_for_key("Tab"), Action::next_task);
  EXPECT_EQ(action_for_key("Shift+Tab"), Action::previous_task);
  EXPECT_EQ(action_for_key("Space"), Action::play_pause);
  EXPECT_EQ(action_for_key("PageUp"), Action::axis_up);
  EXPECT_EQ(action_for_key("]"), Action::speed_up);  // as mpv
  EXPECT_EQ(action_for_key("["), Action::speed_down);
  EXPECT_EQ(action_for_key("Backspace"), Action::speed_reset);
  EXPECT_EQ(action_for_key("PageUp"), Action::axis_up);
  EXPECT_EQ(action_for_key("i"), Action::toggle_hud);
  EXPECT_EQ(action_for_key("PageDown"), Action::axis_down);
  EXPECT_EQ(action_for_key("Period"), Action::frame_forward);
  EXPECT_EQ(action_for_key("Comma"), Action::frame_back);
  EXPECT_EQ(action_for_key("Home"), Action::first_frame);
  EXPECT_EQ(action_for_key("End"), Action::last_frame);
  EXPECT_EQ(action_for_key("Z"), Action::shell_in);
  EXPECT_EQ(action_for_key("x"), Action::shell_out);
  EXPECT_EQ(action_for_key("L"), Action::toggle_loop);
  EXPECT_EQ(action_for_key("3"), Action::task_3);
  EXPECT_FALSE(action_for_key("NoSuchKey").has_value());
  EXPECT_FALSE(action_for_key("").has_value());
}

TEST(Keys, TableIsConsistent) {
  std::set<std::string> keys, names;
  for (const auto& b : key_bindings()) {
    EXPECT_TRUE(keys.insert(std::string(b.key)).second) << "duplicate key " << b.key;
    EXPECT_FALSE(b.description.empty()) << b.key;
    EXPECT_EQ(action_for_key(b.key), b.action) << b.key;
    names.insert(std::string(to_string(b.action)));
  }
  EXPECT_FALSE(names.count("unknown"));
  EXPECT_TRUE(is_engine_action(Action::camera_left));
  EXPECT_FALSE(is_engine_action(Action::zoom_in));
  EXPECT_FALSE(is_engine_action(Action::none));
}

// A key that can change nothing in the database at hand is not offered (help overlays, keys.json's
// "unusable"): PgUp / PgDn / A without parameter axes, Z / X on one camera shell, C on perspective frames.
TEST(Keys, UsableFollowsTheDatabase) {
  store::Manifest m;  // a perspective rig of one shell, no parameter axes (as the demo's Yin-Yang rig)
  m.graph.neighbours.assign(3, store::Neighbours{.left = 1, .right = 2, .up = 1, .down = 2});
  for (Action a : {Action::axis_up, Action::axis_down, Action::next_axis, Action::shell_in, Action::shell_out,
                   Action::face_action})
    EXPECT_FALSE(usable(a, ViewMode::sphere, m)) << to_string(a);
  for (Action a : {Action::camera_up, Action::next_task, Action::play_pause, Action::zoom_in, Action::help})
    EXPECT_TRUE(usable(a, ViewMode::sphere, m)) << to_string(a);
  EXPECT_TRUE(usable(Action::face_action, ViewMode::panorama, m));
  // Inside a lattice PgUp / PgDn walk, whatever the axes; A does nothing there.
  EXPECT_TRUE(usable(Action::axis_up, ViewMode::lattice, m));
  EXPECT_FALSE(usable(Action::next_axis, ViewMode::lattice, m));

  m.axes = {store::ParameterAxis{"isovalue", {0.1, 0.2}, ""}};
  m.graph.neighbours[1].in = 0;  // one camera with a closer shell: Z can move, X still cannot
  EXPECT_TRUE(usable(Action::axis_up, ViewMode::sphere, m));
  EXPECT_TRUE(usable(Action::next_axis, ViewMode::sphere, m));
  EXPECT_TRUE(usable(Action::shell_in, ViewMode::sphere, m));
  EXPECT_FALSE(usable(Action::shell_out, ViewMode::sphere, m));

  m.axes.clear();
  const auto j = keys_json(&m);
  ASSERT_TRUE(j.contains("unusable"));
  std::vector<std::string> unusable = j["unusable"];
  std::sort(unusable.begin(), unusable.end());
  EXPECT_EQ(unusable, (std::vector<std::string>{"axis_down", "axis_up", "face_action", "next_axis", "shell_out"}));
  EXPECT_FALSE(keys_json().contains("unusable")) << "without a database every key is listed";
}

}  // namespace
}  // namespace panoptes::player
