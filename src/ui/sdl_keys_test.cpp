#include "ui/sdl_keys.hpp"

#include <gtest/gtest.h>

namespace panoptes::ui {
namespace {

using player::Action;

std::optional<Action> press(SDL_Keycode key, Uint16 mod = KMOD_NONE) {
  SDL_KeyboardEvent e{};
  e.type = SDL_KEYDOWN;
  e.keysym.sym = key;
  e.keysym.mod = mod;
  return action_for_event(e);
}

TEST(SdlKeys, TypedKeysMapThroughThePlayersTable) {
  EXPECT_EQ(press(SDLK_SPACE), Action::play_pause);
  EXPECT_EQ(press(SDLK_RIGHT), Action::camera_right);
  EXPECT_EQ(press(SDLK_TAB), Action::next_task);
  EXPECT_EQ(press(SDLK_TAB, KMOD_LSHIFT), Action::previous_task);
  EXPECT_EQ(press(SDLK_PERIOD), Action::frame_forward);
  EXPECT_EQ(press(SDLK_PERIOD, KMOD_RSHIFT), Action::faster);  // '>' on US keyboards
  EXPECT_EQ(press(SDLK_EQUALS, KMOD_LSHIFT), Action::zoom_in);  // '+' on US keyboards
  EXPECT_EQ(press(SDLK_KP_PLUS), Action::zoom_in);
  EXPECT_EQ(press(SDLK_l), Action::toggle_loop);
  EXPECT_EQ(press(SDLK_l, KMOD_LSHIFT), Action::toggle_loop);  // no Shift+L binding: L
  EXPECT_EQ(press(SDLK_a), Action::next_axis);
  EXPECT_EQ(press(SDLK_a, KMOD_LSHIFT), Action::previous_axis);  // the table's Shift+A, not A
  EXPECT_FALSE(press(SDLK_a, KMOD_LCTRL));  // Ctrl+A is not bound: not A either
  EXPECT_EQ(press(SDLK_3), Action::task_3);
  EXPECT_EQ(press(SDLK_PAGEUP), Action::axis_up);
  EXPECT_EQ(press(SDLK_RIGHTBRACKET), Action::speed_up);  // as mpv
  EXPECT_EQ(press(SDLK_BACKSPACE), Action::speed_reset);
  EXPECT_EQ(press(SDLK_i), Action::toggle_hud);
  EXPECT_EQ(press(SDLK_F1), Action::help);
  EXPECT_EQ(press(SDLK_0), Action::zoom_reset);
  EXPECT_FALSE(press(SDLK_F7));
  EXPECT_FALSE(press(SDLK_TAB, KMOD_LALT));  // Alt+Tab belongs to the desktop
}

TEST(SdlKeys, EveryKeyOfTheTableCanBeInjected) {
  // Scripts name keys as the table does; each must become an SDL event mapping back to its action.
  for (const auto& b : player::key_bindings()) {
    const auto e = key_event_for_name(b.key);
    ASSERT_TRUE(e) << b.key;
    EXPECT_EQ(e->type, SDL_KEYDOWN);
    EXPECT_EQ(action_for_event(e->key), b.action) << b.key;
    EXPECT_EQ(binding_for_event(e->key), &b) << b.key << ": matched another row of the table";
  }
  EXPECT_FALSE(key_event_for_name("NoSuchKey"));
}

}  // namespace
}  // namespace panoptes::ui
