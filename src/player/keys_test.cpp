#include "player/keys.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

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

}  // namespace
}  // namespace panoptes::player
