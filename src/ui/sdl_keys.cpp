#include "ui/sdl_keys.hpp"

#include <array>
#include <cctype>
#include <cstring>

namespace panoptes::ui {
namespace {

struct NamedKey {
  SDL_Keycode key;
  const char* name;
};

// Keys whose canonical name is not simply the upper-cased character (letters and digits are).
constexpr std::array kNamed{
    NamedKey{SDLK_SPACE, "Space"},       NamedKey{SDLK_LEFT, "Left"},
    NamedKey{SDLK_RIGHT, "Right"},       NamedKey{SDLK_UP, "Up"},
    NamedKey{SDLK_DOWN, "Down"},         NamedKey{SDLK_TAB, "Tab"},
    NamedKey{SDLK_PAGEUP, "PageUp"},     NamedKey{SDLK_PAGEDOWN, "PageDown"},
    NamedKey{SDLK_HOME, "Home"},         NamedKey{SDLK_END, "End"},
    NamedKey{SDLK_PERIOD, "Period"},     NamedKey{SDLK_COMMA, "Comma"},
    NamedKey{SDLK_ESCAPE, "Escape"},     NamedKey{SDLK_F1, "F1"},
    NamedKey{SDLK_LEFTBRACKET, "["},     NamedKey{SDLK_RIGHTBRACKET, "]"},
    NamedKey{SDLK_PLUS, "+"},            NamedKey{SDLK_KP_PLUS, "+"},
    NamedKey{SDLK_EQUALS, "="},          NamedKey{SDLK_MINUS, "-"},
    NamedKey{SDLK_KP_MINUS, "-"},        NamedKey{SDLK_KP_0, "0"},
    NamedKey{SDLK_KP_1, "1"},            NamedKey{SDLK_KP_2, "2"},
    NamedKey{SDLK_KP_3, "3"},            NamedKey{SDLK_KP_4, "4"},
    NamedKey{SDLK_KP_5, "5"},            NamedKey{SDLK_KP_6, "6"},
    NamedKey{SDLK_KP_7, "7"},            NamedKey{SDLK_KP_8, "8"},
    NamedKey{SDLK_KP_9, "9"},            NamedKey{SDLK_GREATER, "Shift+Period"},
    NamedKey{SDLK_LESS, "Shift+Comma"},  NamedKey{SDLK_BACKSPACE, "Backspace"},
};

std::string plain_name(SDL_Keycode key) {
  for (const auto& k : kNamed)
    if (k.key == key) return k.name;
  if (key >= SDLK_a && key <= SDLK_z) return std::string(1, char('A' + (key - SDLK_a)));
  if (key >= SDLK_0 && key <= SDLK_9) return std::string(1, char('0' + (key - SDLK_0)));
  return {};
}

}  // namespace

const player::KeyBinding* binding_for_event(const SDL_KeyboardEvent& event) {
  if (event.keysym.mod & KMOD_GUI) return nullptr;
  const std::string name = plain_name(event.keysym.sym);
  if (name.empty()) return nullptr;
  unsigned mods = player::kNoModifier;
  if (event.keysym.mod & KMOD_SHIFT) mods |= player::kShift;
  if (event.keysym.mod & KMOD_CTRL) mods |= player::kCtrl;
  if (event.keysym.mod & KMOD_ALT) mods |= player::kAlt;
  // '>' and '<' are SDL keys of their own whose name already says Shift ("Shift+Period").
  const player::KeyChord named = player::parse_chord(name);
  if (const auto* b = player::binding_for_chord(named.base, mods | named.modifiers)) return b;
  // Shift+'=' is '+' on US layouts.
  if (name == "=" && mods == player::kShift) return player::binding_for_key("+");
  return nullptr;
}

std::optional<player::Action> action_for_event(const SDL_KeyboardEvent& event) {
  if (const auto* b = binding_for_event(event)) return b->action;
  return std::nullopt;
}

std::optional<SDL_Event> key_event_for_name(std::string_view name) {
  const player::KeyChord chord = player::parse_chord(name);
  const std::string_view base = chord.base;
  Uint16 mod = KMOD_NONE;
  if (chord.modifiers & player::kShift) mod |= KMOD_LSHIFT;
  if (chord.modifiers & player::kCtrl) mod |= KMOD_LCTRL;
  if (chord.modifiers & player::kAlt) mod |= KMOD_LALT;
  SDL_Keycode key = SDLK_UNKNOWN;
  // Letters and digits first, so "1" is the main-row key rather than the keypad's.
  if (base.size() == 1) {
    const char c = char(std::tolower(static_cast<unsigned char>(base[0])));
    if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) key = SDL_Keycode(c);  // SDLK_a == 'a', SDLK_0 == '0'
  }
  for (const auto& k : kNamed)
    if (key == SDLK_UNKNOWN && base == k.name) key = k.key;
  if (key == SDLK_UNKNOWN) return std::nullopt;
  SDL_Event e{};
  e.type = SDL_KEYDOWN;
  e.key.type = SDL_KEYDOWN;
  e.key.state = SDL_PRESSED;
  e.key.keysym.sym = key;
  e.key.keysym.scancode = SDL_GetScancodeFromKey(key);
  e.key.keysym.mod = mod;
  return e;
}

}  // namespace panoptes::ui
