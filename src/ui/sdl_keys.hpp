#pragma once
// Translation between SDL key events and the player's canonical key names (player/keys.hpp), so the
// window uses exactly the key table the headless mode and scripts use.
#include <optional>
#include <string>
#include <string_view>

#include <SDL.h>

#include "player/keys.hpp"

namespace panoptes::ui {

/// The binding of a key press: the key's plain name and its Shift / Ctrl / Alt state matched by
/// player::binding_for_chord (the rule every front end uses); nullptr if the key is unbound. GUI
/// (Windows/Command) combinations belong to the desktop and match nothing.
const player::KeyBinding* binding_for_event(const SDL_KeyboardEvent& event);
/// binding_for_event(event)'s action, or std::nullopt if the key is unbound.
std::optional<player::Action> action_for_event(const SDL_KeyboardEvent& event);

/// A synthetic SDL_KEYDOWN event for a canonical key name (scripts, the window test), so injected
/// keys take the same path as typed ones. std::nullopt for a name SDL has no key for.
std::optional<SDL_Event> key_event_for_name(std::string_view name);

}  // namespace panoptes::ui
