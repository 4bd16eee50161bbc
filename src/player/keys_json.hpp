#pragma once
// The key table as data for the browser (issue 30): the JSON document `panoptes serve` answers at
// /api/keys.json, `export-web` writes to api/keys.json and `panoptes play --keys-json` prints, generated
// from key_bindings(), the per-mode operations (controls.hpp), the walk and look rules (look.hpp) and
// the playback rules (playback_rule.hpp). Format: docs/web.md, "The key table as data".
#include <nlohmann/json.hpp>

#include "store/manifest.hpp"

namespace panoptes::player {

/// Version of the keys.json format (docs/web.md); raised when a field changes meaning. 2 (issue 43):
/// letters carry `shift` (Shift+A is not A), bindings carry ctrl, alt, repeat and refusal, and a key
/// pressed with Shift whose Shift form is not bound acts as the plain key (match_rule).
inline constexpr int kKeysJsonVersion = 2;

/// The keys.json document. With a manifest it also names the database's view mode ("mode").
nlohmann::json keys_json(const store::Manifest* manifest = nullptr);

}  // namespace panoptes::player
