#include "player/keys_json.hpp"

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "player/controls.hpp"
#include "player/keys.hpp"
#include "player/playback_rule.hpp"

namespace panoptes::player {
namespace {

/// The browser's view of a desktop key name: KeyboardEvent.key values, KeyboardEvent.code values (US
/// layout) and the modifier state the event must have. Shift is published for keys whose `key` does not
/// say it (letters, Tab, PageUp, F1...); a character key (".", ">", "+", "[") carries Shift in the
/// character itself, which is what the layout produced, so there Shift is left to `key` (-1: any).
struct BrowserKey {
  std::vector<std::string> keys, codes;
  int shift = -1;  // -1: any, 0: without, 1: with
};

BrowserKey browser_key(const KeyBinding& b) {
  struct Named {
    std::string_view desktop, key, code;
  };
  static constexpr Named kNamed[] = {
      {"Space", " ", "Space"},          {"Left", "ArrowLeft", "ArrowLeft"}, {"Right", "ArrowRight", "ArrowRight"},
      {"Up", "ArrowUp", "ArrowUp"},     {"Down", "ArrowDown", "ArrowDown"}, {"Period", ".", "Period"},
      {"Comma", ",", "Comma"},          {"Shift+Period", ">", "Period"},    {"Shift+Comma", "<", "Comma"},
      {"+", "+", "Equal"},              {"=", "=", "Equal"},                {"-", "-", "Minus"},
      {"[", "[", "BracketLeft"},        {"]", "]", "BracketRight"},         {"/", "/", "Slash"},
  };
  BrowserKey k;
  for (const auto& n : kNamed)
    if (n.desktop == b.key) {
      k.keys = {std::string(n.key)};
      k.codes = {std::string(n.code)};
      return k;
    }
  const KeyChord chord = b.chord();
  const std::string_view name = chord.base;
  if (name.size() == 1 && std::isalpha(static_cast<unsigned char>(name[0]))) {
    const char lower = char(std::tolower(static_cast<unsigned char>(name[0])));
    const char upper = char(std::toupper(static_cast<unsigned char>(name[0])));
    k.keys = {std::string(1, lower), std::string(1, upper)};  // Caps Lock changes the case, not the key
    k.codes = {std::string("Key") + upper};
  } else if (name.size() == 1 && std::isdigit(static_cast<unsigned char>(name[0]))) {
    k.keys = {std::string(name)};
    k.codes = {std::string("Digit") + name[0]};
    return k;  // Shift+1 is "!" on the event: the character decides
  } else {
    k.keys = {std::string(name)};
    k.codes = {std::string(name)};
  }
  k.shift = (chord.modifiers & kShift) ? 1 : 0;  // A vs Shift+A, Tab vs Shift+Tab
  return k;
}

}  // namespace

nlohmann::json keys_json(const store::Manifest* manifest) {
  using nlohmann::json;
  json j;
  j["version"] = kKeysJsonVersion;
  if (manifest) j["mode"] = std::string(to_string(view_mode(*manifest)));
  j["modes"] = {
      {"sphere", "perspective frames (sphere, shells, Yin-Yang, ring, file rigs): the arrows and Z/X follow the "
                 "navigation graph, + / - / 0 magnify"},
      {"panorama", "360-degree frames without walking: the arrows and Z/X follow the navigation graph, a drag "
                   "looks around, + / - / 0 and the wheel change the field of view"},
      {"lattice", "360-degree frames of a lattice or path rig: the arrows and PageUp/PageDown walk relative to "
                  "the view, a drag looks around, + / - / 0 and the wheel change the field of view"},
  };
  j["mode_rule"] =
      "panorama when the rig's parameters record projection = \"equirectangular\"; lattice when they also record "
      "lattice = [nx, ny, nz] with nx*ny*nz = the camera count, or path = true; else sphere";

  json bindings = json::array();
  json actions = json::object();
  for (const KeyBinding& b : key_bindings()) {
    const BrowserKey k = browser_key(b);
    json row;
    row["desktop"] = std::string(b.key);
    row["keys"] = k.keys;
    row["codes"] = k.codes;
    if (k.shift >= 0) row["shift"] = k.shift == 1;
    // Ctrl and Alt are never in `key`: they must always match (absent and false alike).
    row["ctrl"] = (b.chord().modifiers & kCtrl) != 0;
    row["alt"] = (b.chord().modifiers & kAlt) != 0;
    row["repeat"] = b.repeats();
    row["action"] = std::string(to_string(b.action));
    row["front_end_only"] = !is_engine_action(b.action);
    json modes = json::array(), descriptions = json::object(), refusals = json::object();
    for (ViewMode m : kViewModes) {
      // What a refused press says, in every mode (also "does nothing here" where the key does nothing).
      if (const auto why = refusal(b.action, m, manifest); !why.empty()) refusals[std::string(to_string(m))] = std::string(why);
      if (operation(b.action, m) == Operation::none) continue;
      modes.push_back(std::string(to_string(m)));
      descriptions[std::string(to_string(m))] = std::string(description(b, m));
    }
    row["modes"] = std::move(modes);
    row["description"] = std::move(descriptions);
    row["refusal"] = std::move(refusals);
    bindings.push_back(std::move(row));
    json per_mode = json::object();
    for (ViewMode m : kViewModes) {
      const std::string_view op = operation_name(b.action, m);
      per_mode[std::string(to_string(m))] = op.empty() ? json(nullptr) : json(std::string(op));
    }
    actions[std::string(to_string(b.action))] = std::move(per_mode);
  }
  j["bindings"] = std::move(bindings);
  j["actions"] = std::move(actions);
  if (manifest) {
    // The actions that can change nothing in this database (usable()): the browser's help leaves them
    // out, as the window's does.
    const ViewMode mode = view_mode(*manifest);
    json unusable = json::array();
    for (const KeyBinding& b : key_bindings()) {
      const std::string name(to_string(b.action));
      if (!usable(b.action, mode, *manifest) && std::find(unusable.begin(), unusable.end(), name) == unusable.end())
        unusable.push_back(name);
    }
    j["unusable"] = std::move(unusable);
  }

  j["walk"] = {
      {"slots", {"left", "right", "up", "down", "in", "out"}},
      {"min_cos", kWalkMinCos},
      {"keep_view", true},
      {"directions",
       {{"walk_forward", "+view.forward"}, {"walk_back", "-view.forward"}, {"walk_right", "+view.right"},
        {"walk_left", "-view.right"}, {"walk_up", "+camera.up"}, {"walk_down", "-camera.up"}}},
  };
  j["look"] = {
      {"fov_deg", Look{}.fov_deg},         {"fov_min_deg", kFovMinDeg},       {"fov_max_deg", kFovMaxDeg},
      {"pitch_max_deg", kPitchMaxDeg},     {"key_fov_factor", kKeyFovFactor}, {"wheel_fov_factor", kWheelFovFactor},
  };
  j["playback"] = {
      {"speed_min", kSpeedMin},
      {"speed_max", kSpeedMax},
      {"faster_factor", kFasterFactor},
      {"fine_factor", kFineSpeedFactor},
      {"short_run", {{"shortest_run_s", kShortestRunSeconds}, {"speed_min", kShortRunSpeedMin}}},
  };
  j["numbering"] = {{"camera_first", 0}, {"frame_first", 0}, {"task_first", 1}};
  // How a key press finds its binding (player::binding_for_chord), for the browser to do the same.
  j["match_rule"] =
      "the binding whose keys hold event.key, whose shift (if given) equals event.shiftKey and whose ctrl and alt "
      "equal event.ctrlKey and event.altKey; failing that, with Shift alone held, the binding with shift false "
      "(Shift+L acts as L); Meta matches nothing; a held key (event.repeat) acts only if the binding's repeat";
  return j;
}

}  // namespace panoptes::player
