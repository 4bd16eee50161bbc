#pragma once
// JSON parsing for files that may come from anyone: nesting depth, string length and container
// sizes are bounded while parsing (before a DOM too deep to copy or destroy is built), and every
// error names the file and the key path where it happened, e.g.
// "DB/panoptes.json: tasks[2].parameters.iso: number overflow parsing '1e999'".
#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace panoptes::store {

/// Bounds of parse_bounded_json. The defaults are far above what any Panoptes writer produces.
struct JsonLimits {
  std::size_t max_depth = 64;               ///< nested objects/arrays
  std::size_t max_string = std::size_t(1) << 20;     ///< bytes of one string or key
  std::size_t max_elements = std::size_t(1) << 23;   ///< members of one object or array
};

/// Parses `text`; throws FileError(source, "malformed <kind> at <key path>: <what>") on malformed JSON
/// or a bound exceeded. `kind` names the document, e.g. "manifest".
nlohmann::json parse_bounded_json(std::string_view text, const std::string& source, const JsonLimits& limits = {},
                                  std::string_view kind = "JSON");

}  // namespace panoptes::store
