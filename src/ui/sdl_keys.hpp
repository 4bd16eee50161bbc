#pragma once
// Translation between SDL key events and the player's canonical key names (player/keys.hpp), so the
// window uses exactly the key table the headless mode and scripts use.
#include <optional>
#include <string>
#include <string_view>

#include <SDL.h>

#include "player/keys.hpp"

namespace panoptes::ui {

/// Canonical key name of a key press: "Right", "Tab", "A", "1", "Period"; with Shift held, the
/// "Shift+" form is returned when the key table has it (e.g. "Shift+Tab"), else the plain name.
/// Empty for keys Panoptes has no name for.
std::string key_name(SDL_Keycode key, Uint16 modifiers);

/// The action of a key press (via player::action_for_key), or std::nullopt if the key is unbound.
std::optional<player::Action> action_for_event(const SDL_KeyboardEvent& event);

/// A synthetic SDL_KEYDOWN event for a canonical key name (scripts, the window test), so injected
/// keys take the same path as typed ones. std::nullopt for a name SDL has no key for.
std::optional<SDL_Event> key_event_for_name(std::string_view name);

}  // namespace panoptes::ui
