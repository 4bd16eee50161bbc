#include "player/keys.hpp"

#include <array>
#include <cctype>

namespace panoptes::player {
namespace {

// Refusal texts of the engine actions (front ends show them in their status line).
constexpr std::string_view kNoCameraThatWay = "no camera that way";
constexpr std::string_view kNoAxis = "this database has no parameter axis to step here";
constexpr std::string_view kOneTask = "this database has one task";
constexpr auto kOnce = Repeat::no;  // toggles and one-shot commands: a held key acts once

constexpr std::array kBindings{
    KeyBinding{"Space", Action::play_pause, "play / pause", kOnce},
    KeyBinding{"Left", Action::camera_left, "rotate: camera to the left (navigation graph)", Repeat::yes, kNoCameraThatWay},
    KeyBinding{"Right", Action::camera_right, "rotate: camera to the right", Repeat::yes, kNoCameraThatWay},
    KeyBinding{"Up", Action::camera_up, "rotate: camera above", Repeat::yes, "no camera above this one"},
    KeyBinding{"Down", Action::camera_down, "rotate: camera below", Repeat::yes, "no camera below this one"},
    KeyBinding{"Z", Action::shell_in, "zoom by moving to the inner (closer) camera shell", Repeat::yes,
               "no closer shell from this camera"},
    KeyBinding{"X", Action::shell_out, "zoom by moving to the outer (farther) camera shell", Repeat::yes,
               "no farther shell from this camera"},
    KeyBinding{"Tab", Action::next_task, "next visualization task", Repeat::yes, kOneTask},
    KeyBinding{"Shift+Tab", Action::previous_task, "previous visualization task", Repeat::yes, kOneTask},
    KeyBinding{"1", Action::task_1, "task 1 (digit keys 1..9 select tasks 1..9)"},
    KeyBinding{"2", Action::task_2, "task 2"},
    KeyBinding{"3", Action::task_3, "task 3"},
    KeyBinding{"4", Action::task_4, "task 4"},
    KeyBinding{"5", Action::task_5, "task 5"},
    KeyBinding{"6", Action::task_6, "task 6"},
    KeyBinding{"7", Action::task_7, "task 7"},
    KeyBinding{"8", Action::task_8, "task 8"},
    KeyBinding{"9", Action::task_9, "task 9"},
    KeyBinding{"PageUp", Action::axis_up, "active parameter axis: next value (other axes kept)", Repeat::yes,
               "no next value on the active parameter axis from this task"},
    KeyBinding{"PageDown", Action::axis_down, "active parameter axis: previous value", Repeat::yes,
               "no previous value on the active parameter axis from this task"},
    KeyBinding{"A", Action::next_axis, "make the next parameter axis the active one", Repeat::yes, kNoAxis},
    // Issue 43: the first binding with a letter and a modifier (keys.json once published it as plain A).
    KeyBinding{"Shift+A", Action::previous_axis, "make the previous parameter axis the active one", Repeat::yes, kNoAxis},
    KeyBinding{"Period", Action::frame_forward, "pause and step one frame forward ('.')"},
    KeyBinding{"Comma", Action::frame_back, "pause and step one frame back (',')"},
    KeyBinding{"Home", Action::first_frame, "first frame"},
    KeyBinding{"End", Action::last_frame, "last frame"},
    KeyBinding{"L", Action::toggle_loop, "loop on / off", kOnce},
    KeyBinding{"Shift+Period", Action::faster, "double the playback speed, up to x8 ('>')"},
    KeyBinding{"Shift+Comma", Action::slower, "halve the playback speed, down to x1/4 ('<')"},
    KeyBinding{"]", Action::speed_up, "speed x1.1 (as mpv)"},
    KeyBinding{"[", Action::speed_down, "speed /1.1 (as mpv)"},
    KeyBinding{"Backspace", Action::speed_reset, "speed x1: the database's playback rate (as mpv)"},
    KeyBinding{"J", Action::reverse, "reverse the playback direction", kOnce},
    KeyBinding{"+", Action::zoom_in, "magnify around the cursor (also '=' and the mouse wheel)"},
    KeyBinding{"=", Action::zoom_in, "same as +"},
    KeyBinding{"-", Action::zoom_out, "reduce the magnification"},
    KeyBinding{"0", Action::zoom_reset, "magnification 1, no pan"},
    KeyBinding{"F", Action::fullscreen, "full screen on / off", kOnce},
    KeyBinding{"S", Action::screenshot, "save the shown frame as a PNG screenshot", kOnce},
    KeyBinding{"R", Action::record, "start / stop recording what is shown to an MP4", kOnce},
    KeyBinding{"H", Action::help, "help overlay", kOnce},
    KeyBinding{"F1", Action::help, "help overlay", kOnce},
    KeyBinding{"I", Action::toggle_hud, "hide / show the HUD (status panel, mini-map, time slider)", kOnce},
    KeyBinding{"Escape", Action::quit, "quit", kOnce},
    KeyBinding{"Q", Action::quit, "quit", kOnce},
    // Issue 32.2: orientation aids of 360° databases.
    KeyBinding{"C", Action::face_action, "360° view: turn toward the strongest signal in the shown frame", kOnce,
               "C turns a 360-degree view toward the strongest signal; this database has fixed views"},
};

}  // namespace

std::span<const KeyBinding> key_bindings() { return kBindings; }

const KeyBinding* binding_for_chord(std::string_view base, unsigned modifiers) {
  // Single letters are named in upper case; scripts may write them in lower case.
  char upper[2] = {0, 0};
  if (base.size() == 1 && std::islower(static_cast<unsigned char>(base[0]))) {
    upper[0] = char(std::toupper(static_cast<unsigned char>(base[0])));
    base = std::string_view(upper, 1);
  }
  for (const auto& b : kBindings)
    if (b.chord() == KeyChord{base, modifiers}) return &b;
  // Shift on a key whose Shift form is not bound: the key itself (Shift+L loops, as L).
  if (modifiers == kShift) return binding_for_chord(base, kNoModifier);
  return nullptr;
}

const KeyBinding* binding_for_key(std::string_view key) {
  const KeyChord c = parse_chord(key);
  // A name is exact: "Shift+L" is not a name of the table even though pressing it acts as L.
  const KeyBinding* b = binding_for_chord(c.base, c.modifiers);
  return b && b->chord().modifiers == c.modifiers ? b : nullptr;
}

std::optional<Action> action_for_key(std::string_view key) {
  if (const KeyBinding* b = binding_for_key(key)) return b->action;
  return std::nullopt;
}

const KeyBinding* binding_of(Action action) {
  for (const auto& b : kBindings)
    if (b.action == action) return &b;
  return nullptr;
}

std::string_view to_string(Action action) {
  switch (action) {
    case Action::none: return "none";
    case Action::play_pause: return "play_pause";
    case Action::frame_forward: return "frame_forward";
    case Action::frame_back: return "frame_back";
    case Action::first_frame: return "first_frame";
    case Action::last_frame: return "last_frame";
    case Action::toggle_loop: return "toggle_loop";
    case Action::faster: return "faster";
    case Action::slower: return "slower";
    case Action::reverse: return "reverse";
    case Action::speed_up: return "speed_up";
    case Action::speed_down: return "speed_down";
    case Action::speed_reset: return "speed_reset";
    case Action::camera_left: return "camera_left";
    case Action::camera_right: return "camera_right";
    case Action::camera_up: return "camera_up";
    case Action::camera_down: return "camera_down";
    case Action::shell_in: return "shell_in";
    case Action::shell_out: return "shell_out";
    case Action::next_task: return "next_task";
    case Action::previous_task: return "previous_task";
    case Action::task_1: return "task_1";
    case Action::task_2: return "task_2";
    case Action::task_3: return "task_3";
    case Action::task_4: return "task_4";
    case Action::task_5: return "task_5";
    case Action::task_6: return "task_6";
    case Action::task_7: return "task_7";
    case Action::task_8: return "task_8";
    case Action::task_9: return "task_9";
    case Action::axis_up: return "axis_up";
    case Action::axis_down: return "axis_down";
    case Action::next_axis: return "next_axis";
    case Action::previous_axis: return "previous_axis";
    case Action::zoom_in: return "zoom_in";
    case Action::zoom_out: return "zoom_out";
    case Action::zoom_reset: return "zoom_reset";
    case Action::fullscreen: return "fullscreen";
    case Action::screenshot: return "screenshot";
    case Action::record: return "record";
    case Action::help: return "help";
    case Action::toggle_hud: return "toggle_hud";
    case Action::quit: return "quit";
    case Action::face_action: return "face_action";
  }
  return "unknown";
}

bool is_engine_action(Action action) {
  switch (action) {
    case Action::none:
    case Action::zoom_in:
    case Action::zoom_out:
    case Action::zoom_reset:
    case Action::fullscreen:
    case Action::screenshot:
    case Action::record:
    case Action::help:
    case Action::toggle_hud:
    case Action::quit:
    case Action::face_action:
      return false;
    default:
      return true;
  }
}

}  // namespace panoptes::player
