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
  for (Action a : {Action::axis_up, Action::axis_down, Action::next_axis, Action::previous_axis, Action::shell_in,
                   Action::shell_out, Action::face_action})
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
  EXPECT_EQ(unusable, (std::vector<std::string>{"axis_down", "axis_up", "face_action", "next_axis", "previous_axis", "shell_out"}));
  EXPECT_FALSE(keys_json().contains("unusable")) << "without a database every key is listed";
}

// Issue 43: a modifier is part of the key. Shift+A is its own binding everywhere: by name (scripts),
// by chord (the window's and the browser's match) and in keys.json (the browser once ran A for it).
TEST(Keys, ShiftIsPartOfTheKey) {
  EXPECT_EQ(parse_chord("Shift+A"), (KeyChord{"A", kShift}));
  EXPECT_EQ(parse_chord("Ctrl+Shift+Tab"), (KeyChord{"Tab", kShift | kCtrl}));
  EXPECT_EQ(parse_chord("+"), (KeyChord{"+", kNoModifier}));
  EXPECT_EQ(action_for_key("A"), Action::next_axis);
  EXPECT_EQ(action_for_key("Shift+A"), Action::previous_axis);
  EXPECT_EQ(action_for_key("Shift+a"), Action::previous_axis);
  EXPECT_FALSE(action_for_key("Shift+L")) << "not a name of the table (pressing it acts as L)";
  ASSERT_TRUE(binding_for_chord("A", kShift));
  EXPECT_EQ(binding_for_chord("A", kShift)->action, Action::previous_axis);
  EXPECT_EQ(binding_for_chord("L", kShift)->action, Action::toggle_loop) << "unbound Shift form: the plain key";
  EXPECT_EQ(binding_for_chord("A", kCtrl), nullptr) << "Ctrl+A is not A";
  EXPECT_EQ(binding_for_chord("Tab", kShift | kAlt), nullptr);

  const auto j = keys_json();
  const auto row = [&](std::string_view desktop) {
    for (const auto& r : j["bindings"])
      if (r["desktop"] == desktop) return r;
    ADD_FAILURE() << desktop << " is not in keys.json";
    return nlohmann::json::object();
  };
  EXPECT_EQ(row("Shift+A")["action"], "previous_axis");
  EXPECT_EQ(row("Shift+A")["shift"], true);
  EXPECT_EQ(row("A")["shift"], false) << "else the browser runs A's action for Shift+A";
  EXPECT_EQ(row("Shift+Tab")["shift"], true);
  EXPECT_EQ(row("Tab")["shift"], false);
  EXPECT_FALSE(row("Shift+Period").contains("shift")) << "'>' carries its Shift in the character";
  for (const auto& r : j["bindings"]) {
    // Every chord of the table comes back from its published keys and modifiers.
    const KeyChord c = parse_chord(r["desktop"].get<std::string>());
    EXPECT_EQ(r["ctrl"], (c.modifiers & kCtrl) != 0) << r["desktop"];
    EXPECT_EQ(r["alt"], (c.modifiers & kAlt) != 0) << r["desktop"];
    if (r.contains("shift")) {
      EXPECT_EQ(r["shift"], (c.modifiers & kShift) != 0) << r["desktop"];
    }
  }
}

// The table, not a front end, says which keys repeat when held and what a refused key says.
TEST(Keys, RepeatAndRefusalAreTheTables) {
  for (Action a : {Action::play_pause, Action::toggle_loop, Action::reverse, Action::fullscreen, Action::screenshot,
                   Action::record, Action::help, Action::toggle_hud, Action::face_action})
    EXPECT_FALSE(binding_of(a)->repeats()) << to_string(a) << " is a toggle: a held key must act once";
  for (Action a : {Action::camera_left, Action::frame_forward, Action::next_task, Action::axis_up, Action::zoom_in})
    EXPECT_TRUE(binding_of(a)->repeats()) << to_string(a);
  for (const auto& b : key_bindings()) {
    // Several keys of one action (H and F1) are one action: the same repeat and refusal.
    EXPECT_EQ(b.repeat, binding_of(b.action)->repeat) << b.key;
    EXPECT_EQ(b.refusal, binding_of(b.action)->refusal) << b.key;
  }
  EXPECT_EQ(refusal(Action::camera_up, ViewMode::sphere), "no camera above this one");
  EXPECT_EQ(refusal(Action::camera_up, ViewMode::lattice), "no camera that way") << "a walk in a lattice";
  EXPECT_EQ(refusal(Action::previous_axis, ViewMode::lattice), "this key does nothing inside a lattice or along a path");
  EXPECT_EQ(refusal(Action::faster, ViewMode::sphere), "") << "a speed at its limit needs no words";

  // The database's reasons: one camera shell, no parameter axes.
  store::Manifest m;
  m.cameras.resize(2);
  m.graph.neighbours.resize(2);
  EXPECT_NE(refusal(Action::shell_in, ViewMode::sphere, &m).find("this rig has only one"), std::string_view::npos);
  EXPECT_EQ(refusal(Action::axis_up, ViewMode::sphere, &m), refusal(Action::next_axis, ViewMode::sphere));
  m.cameras[1].labels.shell = 1;
  m.axes = {store::ParameterAxis{"isovalue", {0.1, 0.2}, ""}};
  EXPECT_EQ(refusal(Action::shell_in, ViewMode::sphere, &m), "no closer shell from this camera");
  EXPECT_EQ(refusal(Action::axis_up, ViewMode::sphere, &m), binding_of(Action::axis_up)->refusal);

  // keys.json carries both, per binding and mode.
  const auto j = keys_json(&m);
  for (const auto& r : j["bindings"]) {
    const KeyBinding* b = binding_for_key(r["desktop"].get<std::string>());
    ASSERT_NE(b, nullptr) << r["desktop"];
    EXPECT_EQ(r["repeat"], b->repeats()) << b->key;
    for (ViewMode mode : kViewModes) {
      const std::string why(refusal(b->action, mode, &m)), name(to_string(mode));
      EXPECT_EQ(r["refusal"].value(name, std::string()), why) << b->key << " in " << name;
    }
  }
}

}  // namespace
}  // namespace panoptes::player
