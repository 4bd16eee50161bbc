#pragma once
// The player's key bindings: one table shared by every front end (window, headless, Python, and the
// browser through keys.json), so a script line `key=Right` does exactly what pressing → does in the
// window. A row is everything a key is: its name with its modifiers, its action, whether holding it
// repeats, and what the player says when the key changes nothing.
#include <optional>
#include <utility>
#include <span>
#include <string>
#include <string_view>

namespace panoptes::player {

/// Everything a key can ask for. The engine executes the engine actions (Engine::apply); the
/// front-end-only actions (zoom, pan reset, full screen, screenshot, record, help) are executed by the
/// window and ignored by Engine::apply (it returns false for them).
enum class Action {
  none,
  // playback
  play_pause,      ///< Space
  frame_forward,   ///< Period ('.'): pause and step one frame forward
  frame_back,      ///< Comma (','): pause and step one frame back
  first_frame,     ///< Home
  last_frame,      ///< End
  toggle_loop,     ///< L
  faster,          ///< Shift+Period ('>'): double the speed (max ×8)
  slower,          ///< Shift+Comma ('<'): halve the speed (min ×¼)
  reverse,         ///< J: toggle playback direction (forward/backward)
  speed_up,        ///< ']': speed ×1.1 (as mpv)
  speed_down,      ///< '[': speed ÷1.1 (as mpv)
  speed_reset,     ///< Backspace: speed ×1 (as mpv)
  // cameras (the manifest's navigation graph)
  camera_left,     ///< Left
  camera_right,    ///< Right
  camera_up,       ///< Up
  camera_down,     ///< Down
  shell_in,        ///< Z: closer shell (graph edge `in`)
  shell_out,       ///< X: farther shell (graph edge `out`)
  // tasks and parameter axes
  next_task,       ///< Tab
  previous_task,   ///< Shift+Tab
  task_1, task_2, task_3, task_4, task_5, task_6, task_7, task_8, task_9,  ///< digit keys 1..9: task 0..8
  axis_up,         ///< PageUp: step the active parameter axis up, keeping the other axes
  axis_down,       ///< PageDown: step the active parameter axis down
  next_axis,       ///< A: make the next parameter axis the active one
  previous_axis,   ///< Shift+A: make the previous parameter axis the active one
  // front end only (Engine::apply ignores these)
  zoom_in,         ///< '+' / '=' (and the mouse wheel): magnify around the cursor
  zoom_out,        ///< '-'
  zoom_reset,      ///< 0: magnification 1, no pan
  fullscreen,      ///< F
  screenshot,      ///< S: save the shown frame as PNG
  record,          ///< R: start/stop recording what is shown to an MP4
  help,            ///< H or F1: help overlay
  toggle_hud,      ///< I: hide / show the HUD (status panel, mini-map, time slider)
  quit,            ///< Escape or Q
  // added by issue 32.2 (front end only)
  face_action,     ///< C: turn a 360° view toward the strongest signal in the shown frame
};

/// Modifier keys of a binding, as a bit set (spelled in the key's name: "Shift+Tab", "Ctrl+S").
enum Modifier : unsigned { kNoModifier = 0, kShift = 1, kCtrl = 2, kAlt = 4 };

/// A key name split into its modifiers and the key itself: "Shift+A" = {"A", kShift}. The name is the
/// only place the modifiers are written, so the script name, the window's match and keys.json agree.
struct KeyChord {
  std::string_view base;   ///< the key without modifiers: "A", "Tab", "Period", "+"
  unsigned modifiers = kNoModifier;
  bool operator==(const KeyChord&) const = default;
};
/// Splits the leading "Shift+", "Ctrl+" and "Alt+" prefixes (in any order) off a key name.
constexpr KeyChord parse_chord(std::string_view name) {
  KeyChord c{name, kNoModifier};
  for (bool more = true; more;) {
    more = false;
    for (auto [prefix, bit] : {std::pair<std::string_view, Modifier>{"Shift+", kShift}, {"Ctrl+", kCtrl}, {"Alt+", kAlt}})
      if (c.base.size() > prefix.size() && c.base.starts_with(prefix)) {
        c.base.remove_prefix(prefix.size());
        c.modifiers |= bit;
        more = true;
      }
  }
  return c;
}

/// Whether holding a key down repeats its action (navigation, frame steps, speed steps) or acts once
/// (toggles: a held Space must not flicker between play and pause).
enum class Repeat { yes, no };

/// One row of the key table.
struct KeyBinding {
  std::string_view key;          ///< canonical key name with its modifiers, as written in scripts: "Right", "Shift+Tab", "1"
  Action action;
  std::string_view description;  ///< one line for the help overlay and docs/ui.md
  Repeat repeat = Repeat::yes;   ///< whether a held key repeats (SDL's key.repeat, the browser's event.repeat)
  /// What every front end shows when the engine refuses the action (nothing that way, nothing changed);
  /// empty: a refusal needs no words (speed at its limit). Database-specific texts: refusal() in controls.hpp.
  std::string_view refusal = {};

  constexpr KeyChord chord() const { return parse_chord(key); }
  constexpr bool repeats() const { return repeat == Repeat::yes; }
};

/// The full key table, in the order the help overlay lists it. Several keys may map to one action.
std::span<const KeyBinding> key_bindings();

/// The binding of a key name (case-sensitive canonical names as in key_bindings(); single letters are
/// also accepted in lower case, e.g. "l", "Shift+a"). nullptr for an unknown name.
const KeyBinding* binding_for_key(std::string_view key);
/// The binding of a key pressed with `modifiers` (a Modifier bit set): the row of exactly that chord;
/// else, when only Shift is added to a key whose Shift form is not bound, the plain row (Shift+L is L,
/// as a desktop player does). nullptr if none. Every front end matches keys by this rule.
const KeyBinding* binding_for_chord(std::string_view base, unsigned modifiers);
/// binding_for_key(key)'s action; std::nullopt for an unknown name.
std::optional<Action> action_for_key(std::string_view key);
/// The first binding of an action in the table (its repeat and refusal are the action's), or nullptr.
const KeyBinding* binding_of(Action action);

/// Stable lower-case name of an action (e.g. "camera_left"), for statistics and logs.
std::string_view to_string(Action action);

/// True for actions the engine executes (false for front-end-only ones and none).
bool is_engine_action(Action action);

}  // namespace panoptes::player
